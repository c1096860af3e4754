//! The crate's one seeded generator, SplitMix64 (Steele, Lea and Flood 2014): small, fast and
//! fixed, so a seed gives the same stream on every platform and in every release (no library
//! whose stream may change). Synthetic records draw from it here; the plans' samples
//! (`plan::sample`) and the fragility bootstrap above.

/// SplitMix64's state: the seed, advanced by the golden-ratio step at each draw.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`: the top 53 bits as a fraction (the synthetic records' noise).
    pub fn uniform_from_zero(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in the open interval (0, 1): the top 53 bits, offset half a step, so an inverse
    /// CDF of the draw stays finite.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Uniform integer in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n.max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stream_is_splitmix64s() {
        // The reference outputs of SplitMix64 seeded with 1234567 (Vigna's splitmix64.c).
        let mut r = SplitMix64::new(1_234_567);
        let got: Vec<u64> = (0..3).map(|_| r.next_u64()).collect();
        assert_eq!(
            got,
            [
                6_457_827_717_110_365_317,
                3_203_168_211_198_807_973,
                9_817_491_932_198_370_423
            ]
        );
    }

    #[test]
    fn uniforms_stay_in_their_intervals() {
        let mut r = SplitMix64::new(7);
        for _ in 0..1000 {
            let (a, b) = (r.uniform_from_zero(), r.uniform());
            assert!((0.0..1.0).contains(&a));
            assert!(b > 0.0 && b < 1.0);
            assert!(r.below(3) < 3);
        }
    }
}
