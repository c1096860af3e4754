//! Quantiles of sorted values, the crate's one definition: the engine's aggregate sketch reads
//! its quantiles at a rank of this module, and the studies above (accuracy, fragility, IDA, the
//! gap study) read theirs here. In the engine, the lowest layer that needs it, so the sketch
//! and the studies share it without a study reaching down for engine internals or the engine
//! up into the studies.

/// How a quantile `q` is read from `n` sorted values, at the rank `q (n - 1)` between the first
/// (0) and the last (`n - 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// The value at the nearest rank ([`nearest_rank`]): always a value of the data (the
    /// accuracy study's medians and 99th percentiles, the aggregate's sketch).
    Nearest,
    /// Linear between the two values around the rank (Hyndman and Fan's type 7, R's and
    /// NumPy's default): the fragility bootstrap's band, the IDA fractiles, the gap study's
    /// ratios. An infinite value taken with a weight above 0 gives that infinity (an IDA's
    /// collapses), never the NaN of `inf - inf`.
    Linear,
}

/// The rank nearest `q (n - 1)`, halves rounded up (`f64::round`), for `n > 0` values.
pub fn nearest_rank(n: usize, q: f64) -> usize {
    (q * (n - 1) as f64).round() as usize
}

/// Quantile `q` (0 to 1) of `sorted` (ascending, no NaN), read as `how` says; NaN when there
/// are no values (a statistic over nothing is not a zero).
pub fn quantile(sorted: &[f64], q: f64, how: Interpolation) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    match how {
        Interpolation::Nearest => sorted[nearest_rank(n, q)],
        Interpolation::Linear => {
            let x = q * (n - 1) as f64;
            let (i, f) = (x.floor() as usize, x - x.floor());
            let (here, next) = (sorted[i], sorted[(i + 1).min(n - 1)]);
            if f == 0.0 || here.is_infinite() {
                here
            } else if next.is_infinite() {
                next
            } else {
                here + f * (next - here)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Interpolation::{Linear, Nearest};

    #[test]
    fn nearest_reads_a_value_of_the_data() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5, Nearest), 3.0);
        assert_eq!(quantile(&v, 0.99, Nearest), 5.0);
        // Rank 0.5 * 3 = 1.5 rounds up to 2.
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.5, Nearest), 3.0);
        assert_eq!(nearest_rank(1, 0.7), 0);
        assert!(quantile(&[], 0.5, Nearest).is_nan());
    }

    #[test]
    fn linear_interpolates_between_order_statistics() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5, Linear), 3.0);
        assert_eq!(quantile(&v, 0.1, Linear), 1.4);
        assert_eq!(quantile(&v, 1.0, Linear), 5.0);
        assert!(quantile(&[], 0.5, Linear).is_nan());
    }

    /// Type-7 quantiles with collapses (infinities) at the end (an IDA's): infinite where the position
    /// falls on one, or between a finite value and one; the finite ones as before.
    #[test]
    fn quantiles_reach_infinity_where_the_collapses_are() {
        let inf = f64::INFINITY;
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0, inf], 0.5, Linear), 3.0);
        assert!((quantile(&[1.0, 2.0, 3.0, 4.0, inf], 0.16, Linear) - 1.64).abs() < 1e-12);
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0, inf], 0.84, Linear), inf);
        // Exactly on the last finite value: finite (no weight on the collapse).
        assert_eq!(quantile(&[1.0, 2.0, inf], 0.5, Linear), 2.0);
        assert_eq!(quantile(&[1.0, inf, inf], 0.5, Linear), inf);
        assert_eq!(quantile(&[inf], 0.16, Linear), inf);
        assert!(quantile(&[], 0.5, Linear).is_nan());
        // Nine finite of ten: the 84 % stays finite (position 7.56, between the 8th and 9th).
        let mut v: Vec<f64> = (1..=9).map(f64::from).collect();
        v.push(inf);
        assert!((quantile(&v, 0.84, Linear) - 8.56).abs() < 1e-12);
        v[8] = inf;
        assert_eq!(quantile(&v, 0.84, Linear), inf);
    }
}
