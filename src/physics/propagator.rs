//! Exact one-step propagator of a linear oscillator under piecewise-linear ground acceleration
//! (the Nigam-Jennings idea): over a step `h` with `ag` linear from `a0` to `a1`,
//! `u1 = uu u0 + uv v0 + ua0 a0 + ua1 a1` and likewise for `v1`, with no truncation error.
//!
//! The coefficients come from `exp(M h)` of the augmented system `[u, v, f, g]`
//! (`u' = v`, `v' = -(k/m) u - (c/m) v - f`, `f' = g`, `g' = 0`) by scaling and squaring, so
//! they hold for any damping (also >= critical) and for a free mass (`k = 0`). They need
//! transcendentals once per (oscillator, h): the GPU path takes them precomputed from here.

use crate::physics::model::Oscillator;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Propagator {
    pub uu: f64,
    pub uv: f64,
    pub ua0: f64,
    pub ua1: f64,
    pub vu: f64,
    pub vv: f64,
    pub va0: f64,
    pub va1: f64,
}

type M4 = [[f64; 4]; 4];

fn mul<const N: usize>(a: &[[f64; N]; N], b: &[[f64; N]; N]) -> [[f64; N]; N] {
    let mut r = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            r[i][j] = (0..N).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

/// Halvings that bring the row-sum norm of `a` to at most `limit` (scaling and squaring).
fn halvings<const N: usize>(a: &[[f64; N]; N], limit: f64) -> i32 {
    halvings_of(a.iter().map(|r| &r[..]), limit)
}

/// [`halvings`] of a matrix given by its rows.
fn halvings_of<'a>(rows: impl Iterator<Item = &'a [f64]>, limit: f64) -> i32 {
    let norm = rows
        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if norm > limit {
        (norm / limit).log2().ceil() as i32
    } else {
        0
    }
}

fn expm<const N: usize>(a: &[[f64; N]; N]) -> [[f64; N]; N] {
    let s = halvings(a, 0.5);
    let f = 0.5f64.powi(s);
    let a = a.map(|r| r.map(|x| x * f));
    let mut result = [[0.0; N]; N];
    let mut term = [[0.0; N]; N];
    for i in 0..N {
        result[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for k in 1..=24 {
        term = mul(&term, &a).map(|r| r.map(|x| x / k as f64));
        for i in 0..N {
            for j in 0..N {
                result[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..s {
        result = mul(&result, &result);
    }
    result
}

/// `A h` of the augmented system `[u, v, f, g]` (see the module docs).
fn augmented(o: &Oscillator, h: f64) -> M4 {
    [
        [0.0, h, 0.0, 0.0],
        [-o.k / o.m * h, -o.c / o.m * h, -h, 0.0],
        [0.0, 0.0, 0.0, h],
        [0.0; 4],
    ]
}

impl Propagator {
    pub fn new(o: &Oscillator, h: f64) -> Propagator {
        let e = expm(&augmented(o, h));
        // Forcing enters as f = a0, g = (a1 - a0) / h.
        Propagator {
            uu: e[0][0],
            uv: e[0][1],
            ua0: e[0][2] - e[0][3] / h,
            ua1: e[0][3] / h,
            vu: e[1][0],
            vv: e[1][1],
            va0: e[1][2] - e[1][3] / h,
            va1: e[1][3] / h,
        }
    }

    #[inline]
    pub fn step(&self, u: f64, v: f64, a0: f64, a1: f64) -> (f64, f64) {
        (
            self.uu * u + self.uv * v + self.ua0 * a0 + self.ua1 * a1,
            self.vu * u + self.vv * v + self.va0 * a0 + self.va1 * a1,
        )
    }
}

/// `n x n` matrices, row-major, for the coupled modes' propagator.
fn mul_dyn(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut r = vec![0.0; n * n];
    for i in 0..n {
        for k in 0..n {
            let x = a[i * n + k];
            if x == 0.0 {
                continue;
            }
            for j in 0..n {
                r[i * n + j] += x * b[k * n + j];
            }
        }
    }
    r
}

/// `exp(a)` of an `n x n` matrix by scaling and squaring with the `[6/6]` Padé approximant
/// (error below `1e-16` at the scaled norm `1/2`): four products and a solve where
/// [`expm_dyn`]'s Taylor series takes 24 products. For the propagators built while a run goes
/// (a building's tangent stiffness at each change of its storeys' pieces).
fn expm_pade(a: &[f64], n: usize) -> Vec<f64> {
    // The sizes of buildings of 1 to 7 storeys on the stack, so that the products unroll: the
    // same operations in the same order as the general one, so the same bits.
    match n {
        4 => expm_pade_fixed::<4>(a),
        6 => expm_pade_fixed::<6>(a),
        8 => expm_pade_fixed::<8>(a),
        10 => expm_pade_fixed::<10>(a),
        12 => expm_pade_fixed::<12>(a),
        14 => expm_pade_fixed::<14>(a),
        16 => expm_pade_fixed::<16>(a),
        _ => expm_pade_dyn(a, n),
    }
}

/// The `[6/6]` Padé approximant's coefficients.
const PADE6: [f64; 7] = [
    1.0,
    0.5,
    5.0 / 44.0,
    1.0 / 66.0,
    1.0 / 792.0,
    1.0 / 15_840.0,
    1.0 / 665_280.0,
];

/// [`expm_pade`] of an `N x N` matrix (row-major in `a`), on the stack.
fn expm_pade_fixed<const N: usize>(a: &[f64]) -> Vec<f64> {
    type M<const N: usize> = [[f64; N]; N];
    fn product<const N: usize>(a: &M<N>, b: &M<N>) -> M<N> {
        let mut r = [[0.0; N]; N];
        for (ri, ai) in r.iter_mut().zip(a) {
            for (&x, bk) in ai.iter().zip(b) {
                if x == 0.0 {
                    continue;
                }
                for (r, b) in ri.iter_mut().zip(bk) {
                    *r += x * b;
                }
            }
        }
        r
    }
    let c = PADE6;
    let d = balance(a, N);
    let mut x: M<N> = std::array::from_fn(|i| std::array::from_fn(|j| a[i * N + j] * d[j] / d[i]));
    let s = halvings_of(x.iter().map(|r| &r[..]), 0.5);
    let f = 0.5f64.powi(s);
    for v in x.iter_mut().flatten() {
        *v *= f;
    }
    let x2 = product(&x, &x);
    let x4 = product(&x2, &x2);
    let x6 = product(&x4, &x2);
    let eye = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
    let odd: M<N> = std::array::from_fn(|i| {
        std::array::from_fn(|j| c[1] * eye(i, j) + c[3] * x2[i][j] + c[5] * x4[i][j])
    });
    let u = product(&x, &odd);
    let v: M<N> = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            c[0] * eye(i, j) + c[2] * x2[i][j] + c[4] * x4[i][j] + c[6] * x6[i][j]
        })
    });
    // (V - U) R = V + U, by solve_dyn's elimination.
    let mut l: M<N> = std::array::from_fn(|i| std::array::from_fn(|j| v[i][j] - u[i][j]));
    let mut r: M<N> = std::array::from_fn(|i| std::array::from_fn(|j| v[i][j] + u[i][j]));
    for col in 0..N {
        let p = (col..N)
            .max_by(|&x, &y| l[x][col].abs().total_cmp(&l[y][col].abs()))
            .expect("a column");
        assert!(l[p][col].abs() > 0.0, "the Padé denominator is regular");
        if p != col {
            l.swap(col, p);
            r.swap(col, p);
        }
        let (lp, lb) = l.split_at_mut(col + 1);
        let (rp, rb) = r.split_at_mut(col + 1);
        let (lp, rp) = (&lp[col], &rp[col]);
        for (lr, rr) in lb.iter_mut().zip(rb.iter_mut()) {
            let x = lr[col] / lp[col];
            if x == 0.0 {
                continue;
            }
            for (a, b) in lr[col..].iter_mut().zip(&lp[col..]) {
                *a -= x * b;
            }
            for (a, b) in rr.iter_mut().zip(rp) {
                *a -= x * b;
            }
        }
    }
    for col in (0..N).rev() {
        let (top, below) = r.split_at_mut(col + 1);
        let lc = &l[col];
        for (j, rc) in top[col].iter_mut().enumerate() {
            let x = (below.iter().zip(&lc[col + 1..])).fold(*rc, |x, (rk, lk)| x - lk * rk[j]);
            *rc = x / lc[col];
        }
    }
    for _ in 0..s {
        r = product(&r, &r);
    }
    // exp(A) = D exp(D^-1 A D) D^-1.
    (0..N * N)
        .map(|i| r[i / N][i % N] * d[i / N] / d[i % N])
        .collect()
}

/// [`expm_pade`] of any size.
fn expm_pade_dyn(a: &[f64], n: usize) -> Vec<f64> {
    const C: [f64; 7] = PADE6;
    // Balanced first (`D^-1 A D`, `D` powers of 2, exact): a mode's `w^2 h` and `h` become
    // about `w h` each, so far fewer squarings are needed.
    let scale = balance(a, n);
    let a: Vec<f64> = (0..n * n)
        .map(|i| a[i] * scale[i % n] / scale[i / n])
        .collect();
    let s = halvings_of(a.chunks(n), 0.5);
    let f = 0.5f64.powi(s);
    let a: Vec<f64> = a.iter().map(|x| x * f).collect();
    let a2 = mul_dyn(&a, &a, n);
    let a4 = mul_dyn(&a2, &a2, n);
    let a6 = mul_dyn(&a4, &a2, n);
    let eye = |i: usize| if i.is_multiple_of(n + 1) { 1.0 } else { 0.0 };
    let odd: Vec<f64> = (0..n * n)
        .map(|i| C[1] * eye(i) + C[3] * a2[i] + C[5] * a4[i])
        .collect();
    let u = mul_dyn(&a, &odd, n);
    let v: Vec<f64> = (0..n * n)
        .map(|i| C[0] * eye(i) + C[2] * a2[i] + C[4] * a4[i] + C[6] * a6[i])
        .collect();
    // (V - U) R = V + U.
    let d: Vec<f64> = v.iter().zip(&u).map(|(v, u)| v - u).collect();
    let r: Vec<f64> = v.iter().zip(&u).map(|(v, u)| v + u).collect();
    let mut r = solve_dyn(d, r, n, 0.0).expect("the Padé denominator is regular");
    for _ in 0..s {
        r = mul_dyn(&r, &r, n);
    }
    // exp(A) = D exp(D^-1 A D) D^-1.
    (0..n * n)
        .map(|i| r[i] * scale[i / n] / scale[i % n])
        .collect()
}

/// `X` with `A X = B` (`A` `n x n`, `B` `n x m`, both row-major, `m` from `b`'s length), by
/// Gauss elimination with partial pivoting; None where a pivot is at or below `tiny` in size
/// (singular to that).
pub(crate) fn solve_dyn(mut a: Vec<f64>, mut b: Vec<f64>, n: usize, tiny: f64) -> Option<Vec<f64>> {
    let m = b.len() / n;
    for c in 0..n {
        let p = (c..n).max_by(|&x, &y| a[x * n + c].abs().total_cmp(&a[y * n + c].abs()))?;
        if a[p * n + c].abs() <= tiny {
            return None;
        }
        if p != c {
            for j in 0..n {
                a.swap(c * n + j, p * n + j);
            }
            for j in 0..m {
                b.swap(c * m + j, p * m + j);
            }
        }
        let pivot = a[c * n + c];
        for row in c + 1..n {
            let x = a[row * n + c] / pivot;
            if x == 0.0 {
                continue;
            }
            for j in c..n {
                a[row * n + j] -= x * a[c * n + j];
            }
            for j in 0..m {
                b[row * m + j] -= x * b[c * m + j];
            }
        }
    }
    for c in (0..n).rev() {
        for j in 0..m {
            let mut x = b[c * m + j];
            for k in c + 1..n {
                x -= a[c * n + k] * b[k * m + j];
            }
            b[c * m + j] = x / a[c * n + c];
        }
    }
    Some(b)
}

/// Powers of 2 `d` for which `D^-1 A D` has each row's and column's off-diagonal norms alike
/// (Parlett and Reinsch's balancing, a few sweeps).
fn balance(a: &[f64], n: usize) -> Vec<f64> {
    // `d` and its reciprocals are powers of 2, so a product with one is a division by the
    // other, exactly.
    let (mut d, mut inv) = (vec![1.0; n], vec![1.0; n]);
    for _ in 0..4 {
        for i in 0..n {
            let (mut row, mut col) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                row += (a[i * n + j] * d[j] * inv[i]).abs();
                col += (a[j * n + i] * d[i] * inv[j]).abs();
            }
            if row == 0.0 || col == 0.0 {
                continue;
            }
            // Scaling d_i by 2^e scales the row by 2^-e and the column by 2^e.
            let e = (0.5 * (row / col).log2()).round();
            d[i] *= e.exp2();
            inv[i] = 1.0 / d[i];
        }
    }
    d
}

/// `exp(a)` of an `n x n` matrix by scaling and squaring (as [`expm`]).
fn expm_dyn(a: &[f64], n: usize) -> Vec<f64> {
    let s = halvings_of(a.chunks(n), 0.5);
    let f = 0.5f64.powi(s);
    let a: Vec<f64> = a.iter().map(|x| x * f).collect();
    let mut result = vec![0.0; n * n];
    let mut term = vec![0.0; n * n];
    for i in 0..n {
        result[i * n + i] = 1.0;
        term[i * n + i] = 1.0;
    }
    for k in 1..=24 {
        term = mul_dyn(&term, &a, n);
        for (t, r) in term.iter_mut().zip(result.iter_mut()) {
            *t /= k as f64;
            *r += *t;
        }
    }
    for _ in 0..s {
        result = mul_dyn(&result, &result, n);
    }
    result
}

/// The exact step of `N` modes whose damping couples them (`q'' + c q' + E q' + w^2 q =
/// -L ag`, `c` and `w^2` per mode, `E` the coupling) over `h` under `ag` linear from `a0` to
/// `a1`: `x1 = P x0 + f0 a0 + f1 a1` for `x = [q, q']`, from `exp` of the augmented system
/// `[x, f, g]` as [`Propagator`]. Exact like it; `O(N^2)` per step where uncoupled modes cost
/// `O(N)`.
#[derive(Debug, Clone, PartialEq)]
pub struct CoupledPropagator {
    n: usize,
    /// `2N x 2N`, row-major.
    p: Vec<f64>,
    f0: Vec<f64>,
    f1: Vec<f64>,
}

impl CoupledPropagator {
    pub fn new(w2: &[f64], c: &[f64], coupling: &[Vec<f64>], part: &[f64], h: f64) -> Self {
        Self::with_stiffness(w2, None, c, coupling, part, h)
    }

    /// As [`CoupledPropagator::new`] with the modes' stiffness coupled too, `q'' + c q' + E q' +
    /// (w^2 + S) q = -L ag` (`S` row by row): a building whose storeys stand on pieces off
    /// their initial stiffness.
    pub fn with_stiffness(
        w2: &[f64],
        stiffness: Option<&[Vec<f64>]>,
        c: &[f64],
        coupling: &[Vec<f64>],
        part: &[f64],
        h: f64,
    ) -> Self {
        let n = w2.len();
        let m = 2 * n + 2;
        let a = Self::augmented(w2, stiffness, c, coupling, part, h);
        // The modal propagators of a run's start as before; a tangent's, built as the run goes,
        // by the cheaper approximant.
        let e = if stiffness.is_some() {
            expm_pade(&a, m)
        } else {
            expm_dyn(&a, m)
        };
        let n2 = 2 * n;
        let mut p = vec![0.0; n2 * n2];
        let (mut f0, mut f1) = (vec![0.0; n2], vec![0.0; n2]);
        for i in 0..n2 {
            p[i * n2..(i + 1) * n2].copy_from_slice(&e[i * m..i * m + n2]);
            // Forcing enters as f = a0, g = (a1 - a0) / h.
            let (ef, eg) = (e[i * m + n2], e[i * m + n2 + 1]);
            f0[i] = ef - eg / h;
            f1[i] = eg / h;
        }
        CoupledPropagator { n, p, f0, f1 }
    }

    /// `A h` of the augmented system `[q, q', f, g]` (`2N + 2` square, row-major) of the modes'
    /// `w^2`, their stiffness coupling, `c`, damping coupling and participations.
    fn augmented(
        w2: &[f64],
        stiffness: Option<&[Vec<f64>]>,
        c: &[f64],
        coupling: &[Vec<f64>],
        part: &[f64],
        h: f64,
    ) -> Vec<f64> {
        let n = w2.len();
        let m = 2 * n + 2;
        let mut a = vec![0.0; m * m];
        for i in 0..n {
            a[i * m + n + i] = h;
            let r = (n + i) * m;
            a[r + i] = -w2[i] * h;
            for k in 0..n {
                a[r + n + k] = -coupling[i][k] * h;
            }
            a[r + n + i] -= c[i] * h;
            if let Some(s) = stiffness {
                for k in 0..n {
                    a[r + k] -= s[i][k] * h;
                }
            }
            a[r + 2 * n] = -part[i] * h;
        }
        a[2 * n * m + 2 * n + 1] = h;
        a
    }

    /// Its coefficients: the step `P` (`2N x 2N`, row-major) and the ground's `f0`, `f1`.
    pub fn coefficients(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.p, &self.f0, &self.f1)
    }

    /// The state `[q, q']` after the step, into `out`.
    pub fn step(&self, x0: &[f64], a0: f64, a1: f64, out: &mut [f64]) {
        let n2 = 2 * self.n;
        for (i, o) in out.iter_mut().enumerate().take(n2) {
            let row = &self.p[i * n2..(i + 1) * n2];
            *o = row.iter().zip(x0).map(|(p, x)| p * x).sum::<f64>()
                + self.f0[i] * a0
                + self.f1[i] * a1;
        }
    }
}

/// Gauss-Legendre nodes and weights on [-1, 1], 5 points (polynomials of degree 9 exactly).
pub const GAUSS5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Coefficients of a quadratic form in `y = [u0, v0, a0, a1]`: `sum_{i<=j} c_ij y_i y_j`, upper
/// triangle row by row.
pub type Form = [f64; 10];

/// `y^T form y` for `y = [u, v, a0, a1]`.
#[inline]
pub fn quadratic(c: &Form, u: f64, v: f64, a0: f64, a1: f64) -> f64 {
    u * (c[0] * u + c[1] * v + c[2] * a0 + c[3] * a1)
        + v * (c[4] * v + c[5] * a0 + c[6] * a1)
        + a0 * (c[7] * a0 + c[8] * a1)
        + a1 * c[9] * a1
}

/// Exact energy integrals of one oscillator over a free step `h` under piecewise-linear `ag`,
/// as quadratic forms of the step's start state and ground samples: `int v^2 dt` (times `c`,
/// the structural damping work) and `int ag v dt` (times `-m`, the input work). Exact like the
/// propagator, so the energy balance of a run measures only the contact integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyForms {
    /// `int_0^h v^2 dt`
    pub vv: Form,
    /// `int_0^h ag v dt`
    pub agv: Form,
}

impl EnergyForms {
    /// By Van Loan's block exponential: for `x' = A x` and `C = [[-A^T, Q], [0, A]] h`,
    /// `W(h) = int_0^h e^(A^T t) Q e^(A t) dt = F22^T F12` with `expm(C) = [[F11, F12], [0, F22]]`.
    /// `F11 = e^(-A^T h)` grows where the oscillator decays fast, and `F12` then loses digits to
    /// cancellation (1e-9 at `zeta` = 2.5, `omega h` = 3), so Van Loan runs on `h / 2^s` small
    /// enough for no growth and the doubling `W(2h) = W(h) + E(h)^T W(h) E(h)` does the rest.
    pub fn new(o: &Oscillator, h: f64) -> EnergyForms {
        let a = augmented(o, h);
        let s = halvings(&a, 0.25);
        let a = a.map(|r| r.map(|x| x * 0.5f64.powi(s)));
        let hs = h * 0.5f64.powi(s);
        // x = [u, v, f, g] with f = ag, g = (a1 - a0) / h: x0 = T y.
        let t: M4 = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0 / h, 1.0 / h],
        ];
        let form = |q: M4| -> Form {
            let mut c = [[0.0; 8]; 8];
            for i in 0..4 {
                for j in 0..4 {
                    c[i][j] = -a[j][i];
                    c[i][4 + j] = q[i][j] * hs;
                    c[4 + i][4 + j] = a[i][j];
                }
            }
            let f = expm(&c);
            let mut e = [[0.0; 4]; 4];
            let mut w = [[0.0; 4]; 4];
            for i in 0..4 {
                for j in 0..4 {
                    e[i][j] = f[4 + i][4 + j];
                    w[i][j] = (0..4).map(|k| f[4 + k][4 + i] * f[k][4 + j]).sum();
                }
            }
            for _ in 0..s {
                let we = mul(&w, &e);
                for i in 0..4 {
                    for j in 0..4 {
                        w[i][j] += (0..4).map(|k| e[k][i] * we[k][j]).sum::<f64>();
                    }
                }
                e = mul(&e, &e);
            }
            // W_y = T^T W T, as upper-triangle coefficients.
            let wt = mul(&w, &t);
            let mut wy = [[0.0; 4]; 4];
            for i in 0..4 {
                for j in 0..4 {
                    wy[i][j] = (0..4).map(|k| t[k][i] * wt[k][j]).sum();
                }
            }
            let pairs = (0..4).flat_map(|i| (i..4).map(move |j| (i, j)));
            let mut out = [0.0; 10];
            for (c, (i, j)) in out.iter_mut().zip(pairs) {
                *c = if i == j {
                    wy[i][i]
                } else {
                    wy[i][j] + wy[j][i]
                };
            }
            out
        };
        let mut qv = [[0.0; 4]; 4];
        qv[1][1] = 1.0;
        let mut qa = [[0.0; 4]; 4];
        qa[1][2] = 0.5;
        qa[2][1] = 0.5;
        EnergyForms {
            vv: form(qv),
            agv: form(qa),
        }
    }

    /// `(int v^2 dt, int ag v dt)` over the step from `(u, v)` with `ag` from `a0` to `a1`.
    #[inline]
    pub fn integrals(&self, u: f64, v: f64, a0: f64, a1: f64) -> (f64, f64) {
        (
            quadratic(&self.vv, u, v, a0, a1),
            quadratic(&self.agv, u, v, a0, a1),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_mass_under_linear_ramp() {
        // v' = -ag, ag from a0 to a1: v1 = v0 - h (a0 + a1)/2, u1 = u0 + v0 h - h^2 (a0/3 + a1/6).
        let p = Propagator::new(&Oscillator::free(3.0), 0.1);
        let (u, v) = p.step(0.2, 1.0, 2.0, 5.0);
        assert!((v - (1.0 - 0.1 * 3.5)).abs() < 1e-14);
        assert!((u - (0.2 + 0.1 - 0.01 * (2.0 / 3.0 + 5.0 / 6.0))).abs() < 1e-14);
    }

    /// Against composite Simpson quadrature of the exact propagator's velocity, for a light, a
    /// heavy (overdamped) and an undamped oscillator over steps short and long against `T`.
    #[test]
    fn energy_forms_match_quadrature_of_the_exact_solution() {
        for (o, h) in [
            (Oscillator::from_period(2e5, 0.5, 0.05), 0.02),
            (Oscillator::from_period(3.0, 0.1, 2.5), 0.05),
            (Oscillator::from_period(1.0, 1.3, 0.0), 0.4),
            (Oscillator::free(5.0), 0.1),
        ] {
            let (u0, v0, a0, a1) = (0.013, -0.21, 1.7, -2.9);
            let f = EnergyForms::new(&o, h);
            let (vv, agv) = f.integrals(u0, v0, a0, a1);
            let n = 2000;
            let (mut svv, mut sagv) = (0.0, 0.0);
            for i in 0..=n {
                let s = h * i as f64 / n as f64;
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let ag = a0 + (a1 - a0) * s / h;
                let v = if i == 0 {
                    v0
                } else {
                    Propagator::new(&o, s).step(u0, v0, a0, ag).1
                };
                svv += w * v * v;
                sagv += w * ag * v;
            }
            let (svv, sagv) = (svv * h / (3.0 * n as f64), sagv * h / (3.0 * n as f64));
            assert!(
                (vv - svv).abs() <= 1e-10 * svv.abs(),
                "{o:?}: {vv} vs {svv}"
            );
            assert!(
                (agv - sagv).abs() <= 1e-10 * sagv.abs().max(svv.abs()),
                "{o:?}: {agv} vs {sagv}"
            );
        }
    }

    /// Without coupling the coupled propagator is each mode's own.
    #[test]
    fn uncoupled_modes_step_as_their_own_propagators() {
        let (w2, c, part) = ([4.0, 30.0], [0.2, 0.5], [1.3, -0.4]);
        let zero = vec![vec![0.0; 2]; 2];
        let h = 0.02;
        let cp = CoupledPropagator::new(&w2, &c, &zero, &part, h);
        let x0 = [0.01, -0.02, 0.3, 0.1];
        let mut x1 = [0.0; 4];
        cp.step(&x0, 0.7, -0.2, &mut x1);
        for i in 0..2 {
            let o = Oscillator {
                m: 1.0,
                k: w2[i],
                c: c[i],
            };
            let (u, v) =
                Propagator::new(&o, h).step(x0[i], x0[2 + i], part[i] * 0.7, part[i] * -0.2);
            assert!(
                (u - x1[i]).abs() < 1e-14 && (v - x1[2 + i]).abs() < 1e-13,
                "{i}"
            );
        }
    }

    /// The Padé approximant of the tangent propagators gives the Taylor series' exponential to
    /// rounding, on matrices of a stiff, a soft and a negative (hyperbolic) tangent.
    #[test]
    fn pade_and_taylor_exponentials_agree() {
        for (w2, ds) in [
            ([4.0, 900.0], [[0.0, 0.0], [0.0, 0.0]]),
            ([4.0, 900.0], [[-3.0, 1.5], [1.5, -200.0]]),
            ([40.0, 2500.0], [[-45.0, 8.0], [8.0, -100.0]]),
        ] {
            let stiffness: Vec<Vec<f64>> = ds.iter().map(|r| r.to_vec()).collect();
            let e = vec![vec![0.0, 0.07], vec![0.07, 0.0]];
            for h in [0.005, 0.02, 0.3] {
                let pade = CoupledPropagator::with_stiffness(
                    &w2,
                    Some(&stiffness),
                    &[0.2, 0.5],
                    &e,
                    &[1.3, -0.4],
                    h,
                );
                // The same matrix through the Taylor series.
                let n = 6;
                let mut a = vec![0.0; n * n];
                for i in 0..2 {
                    a[i * n + 2 + i] = h;
                    let r = (2 + i) * n;
                    a[r + i] = -w2[i] * h;
                    for k in 0..2 {
                        a[r + 2 + k] = -e[i][k] * h;
                        a[r + k] -= ds[i][k] * h;
                    }
                    a[r + 2 + i] -= [0.2, 0.5][i] * h;
                    a[r + 4] = -[1.3, -0.4][i] * h;
                }
                a[4 * n + 5] = h;
                let (t, p) = (expm_dyn(&a, n), expm_pade(&a, n));
                let scale = t.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
                for (x, y) in t.iter().zip(&p) {
                    // A long step's squarings carry either's rounding up to 1.2e-13 of it.
                    assert!((x - y).abs() <= 1e-12 * scale, "{h}: {x} vs {y}");
                }
                let (pp, _, _) = pade.coefficients();
                assert!((pp[0] - p[0]).abs() <= 1e-13 * scale);
            }
        }
    }

    /// The stack exponentials of small matrices are the general one's, bit for bit (the same
    /// operations in the same order), on augmented systems of 1 to 7 modes and on a dense one.
    #[test]
    fn stack_pade_exponentials_are_the_general_ones() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut draw = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for modes in 1..=7 {
            let w2: Vec<f64> = (0..modes)
                .map(|i| 40.0 * (1 + i * i) as f64 * (1.0 + draw()))
                .collect();
            let c: Vec<f64> = (0..modes).map(|_| 0.5 + draw()).collect();
            let part: Vec<f64> = (0..modes).map(|_| draw()).collect();
            let coupling: Vec<Vec<f64>> = (0..modes)
                .map(|_| (0..modes).map(|_| 0.1 * draw()).collect())
                .collect();
            let stiffness: Vec<Vec<f64>> = (0..modes)
                .map(|_| (0..modes).map(|_| 300.0 * draw()).collect())
                .collect();
            for h in [0.005, 0.02, 0.3] {
                let m = 2 * modes + 2;
                let a =
                    CoupledPropagator::augmented(&w2, Some(&stiffness), &c, &coupling, &part, h);
                let dense: Vec<f64> = (0..m * m).map(|_| 3.0 * draw()).collect();
                for a in [a, dense] {
                    let (fixed, general) = (expm_pade(&a, m), expm_pade_dyn(&a, m));
                    assert!(
                        fixed
                            .iter()
                            .zip(&general)
                            .all(|(x, y)| x.to_bits() == y.to_bits()),
                        "{modes} modes, h {h}"
                    );
                }
            }
        }
    }

    /// Coupled modes: the step equals a fine RK4 integration of the coupled equations.
    #[test]
    fn coupled_modes_step_as_a_fine_integration() {
        let (w2, c, part) = ([4.0, 30.0], [0.2, 0.5], [1.3, -0.4]);
        let e = vec![vec![0.0, 0.07], vec![0.07, 0.0]];
        let (h, a0, a1) = (0.05, 0.7, -0.2);
        let cp = CoupledPropagator::new(&w2, &c, &e, &part, h);
        let x0 = [0.01, -0.02, 0.3, 0.1];
        let mut x1 = [0.0; 4];
        cp.step(&x0, a0, a1, &mut x1);
        let f = |t: f64, x: &[f64; 4]| -> [f64; 4] {
            let ag = a0 + (a1 - a0) * t / h;
            let mut d = [x[2], x[3], 0.0, 0.0];
            for i in 0..2 {
                d[2 + i] = -w2[i] * x[i]
                    - c[i] * x[2 + i]
                    - part[i] * ag
                    - (0..2).map(|k| e[i][k] * x[2 + k]).sum::<f64>();
            }
            d
        };
        let steps = 2000;
        let dt = h / steps as f64;
        let mut x = x0;
        for s in 0..steps {
            let t = s as f64 * dt;
            let add = |x: &[f64; 4], k: &[f64; 4], a: f64| std::array::from_fn(|i| x[i] + a * k[i]);
            let k1 = f(t, &x);
            let k2 = f(t + dt / 2.0, &add(&x, &k1, dt / 2.0));
            let k3 = f(t + dt / 2.0, &add(&x, &k2, dt / 2.0));
            let k4 = f(t + dt, &add(&x, &k3, dt));
            x = std::array::from_fn(|i| {
                x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        for i in 0..4 {
            assert!((x[i] - x1[i]).abs() < 1e-12, "{i}: {} vs {}", x[i], x1[i]);
        }
    }
}
