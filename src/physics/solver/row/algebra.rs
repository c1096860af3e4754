//! The row's one inner product: a row of an operator (a storey's drift, a level's closing, a
//! mode's share of a load) against a slice of the state.

#[inline]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
