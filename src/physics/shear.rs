//! Multi-storey shear buildings and their modes.
//!
//! A shear building has `N` lumped floor masses `m_j` joined by storey springs `k_j` (storey `j`
//! joins floor `j - 1` and floor `j`; floor 0 is the ground), so `K` is tridiagonal. Its damping
//! is classical (Rayleigh `C = a0 M + a1 K`, or the same ratio on every mode), so the motion
//! splits into `N` independent modal oscillators. With mass-normalised mode shapes `Phi`
//! (`Phi^T M Phi = I`) and `u = Phi q`:
//!
//! ```text
//! q_i'' + 2 xi_i w_i q_i' + w_i^2 q_i = -L_i ag + phi_i^T F,   L_i = phi_i^T M 1
//! ```
//!
//! so the exact propagator of [`crate::physics::propagator`] steps each mode with no
//! truncation error (a unit-mass oscillator under ground motion `L_i ag`).

use crate::physics::model::Oscillator;

/// Most storeys a building may have: the modal transforms cost `N^2` per step and the
/// eigenvectors are found in `O(N^3)`; taller shear models are not what this tool is for.
pub const MAX_STOREYS: usize = 60;

/// How a building's damping is specified (both are classical).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damping {
    /// Rayleigh `C = a0 M + a1 K` with this ratio on modes 1 and 2 (on mode 1 alone for a
    /// single storey).
    Rayleigh(f64),
    /// This ratio on every mode.
    Modal(f64),
}

impl Damping {
    pub fn ratio(self) -> f64 {
        match self {
            Damping::Rayleigh(x) | Damping::Modal(x) => x,
        }
    }

    pub fn key(self) -> &'static str {
        match self {
            Damping::Rayleigh(_) => "rayleigh",
            Damping::Modal(_) => "modal",
        }
    }
}

/// A shear building: floor 1 is the lowest floor above the ground.
#[derive(Debug, Clone, PartialEq)]
pub struct ShearBuilding {
    /// Floor masses, kg, bottom to top.
    pub masses: Vec<f64>,
    /// Storey stiffnesses, N/m: `stiffness[j]` joins floor `j` (0 = ground) and floor `j + 1`.
    pub stiffness: Vec<f64>,
    /// Storey heights, m.
    pub heights: Vec<f64>,
    pub damping: Damping,
    /// Yielding storey springs, bilinear or deteriorating (None: every storey linear elastic).
    pub yielding: Option<Yielding>,
    /// P-Delta: each storey's geometric stiffness `P_j / h_j`, N/m, `P_j` the gravity load it
    /// carries (None: no P-Delta; [`ShearBuilding::with_p_delta`]).
    pub geometric: Option<Vec<f64>>,
    /// The share `alpha` of each storey's stiffness that the columns a neighbour's slab strikes
    /// carry: their local stiffness at the struck point, `alpha k_j / (4 xi^3 (1 - xi)^3)`, is
    /// in series with the contact (physics.md section 11; [`crate::physics::row::Row`]). None:
    /// the struck point is rigid.
    pub struck_column_share: Option<f64>,
}

/// Storeys that yield: storey `j` is a bilinear spring with kinematic hardening (physics.md
/// section 8; OpenSees `Steel01` without isotropic hardening): initial stiffness `k_j`, yield
/// force `force[j]`, post-yield stiffness `post_yield[j] k_j`.
#[derive(Debug, Clone, PartialEq)]
pub struct Yielding {
    /// Yield force per storey, N (> 0).
    pub force: Vec<f64>,
    /// Post-yield stiffness ratio `b` per storey, `0 <= b < 1` (0: elastic-perfectly-plastic).
    pub post_yield: Vec<f64>,
    /// Capped, deteriorating storeys (IMK, physics.md section 13); None: bilinear.
    pub deterioration: Option<Deterioration>,
}

/// Which IMK hysteresis rule a deteriorating storey follows (OpenSees' material of that name).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImkRule {
    /// `IMKBilin`: unloading and reloading along the deteriorated bounding lines.
    Bilinear,
    /// `IMKPeakOriented`: reloading aims at the largest earlier excursion on that side.
    PeakOriented,
}

impl ImkRule {
    /// The config's word for the rule (`hysteresis = "..."`).
    pub fn key(self) -> &'static str {
        match self {
            ImkRule::Bilinear => "imk_bilinear",
            ImkRule::PeakOriented => "imk_peak_oriented",
        }
    }
}

/// The IMK backbone beyond yield and its cyclic deterioration, per storey, in drift ratios
/// (physics.md section 13): the yield drift and hardening ratio are [`Yielding`]'s.
#[derive(Debug, Clone, PartialEq)]
pub struct Deterioration {
    pub rule: ImkRule,
    /// `theta_p`: yield to capping (> 0).
    pub plastic: Vec<f64>,
    /// `theta_pc`: capping to zero strength (> 0).
    pub post_capping: Vec<f64>,
    /// `kappa`: residual strength over the initial yield strength, in `[0, 1)`.
    pub residual: Vec<f64>,
    /// `theta_u`: no strength beyond this drift ratio, from the origin (infinite: none).
    pub ultimate: Vec<f64>,
    /// `gamma`: the energy capacity `E_t = gamma F_y theta_y h` (None: no cyclic
    /// deterioration).
    pub energy: Option<Vec<f64>>,
}

impl Yielding {
    /// Yield forces `F_y,j = k_j theta_y,j h_j` from yield drift ratios `theta_y` (per storey).
    pub fn from_drift_ratio(
        stiffness: &[f64],
        heights: &[f64],
        theta_y: &[f64],
        post_yield: Vec<f64>,
    ) -> Yielding {
        Yielding {
            force: stiffness
                .iter()
                .zip(heights)
                .zip(theta_y)
                .map(|((k, h), t)| k * t * h)
                .collect(),
            post_yield,
            deterioration: None,
        }
    }
}

impl ShearBuilding {
    /// A building whose storey stiffnesses follow `profile` (relative values, bottom to top),
    /// scaled so its fundamental period is `period` s.
    pub fn from_period(
        masses: Vec<f64>,
        profile: &[f64],
        heights: Vec<f64>,
        period: f64,
        damping: Damping,
    ) -> ShearBuilding {
        let mut b = ShearBuilding {
            masses,
            stiffness: profile.to_vec(),
            heights,
            damping,
            yielding: None,
            geometric: None,
            struck_column_share: None,
        };
        let w1 = b.eigen().0[0].sqrt();
        let target = 2.0 * std::f64::consts::PI / period;
        let s = (target / w1) * (target / w1);
        for k in &mut b.stiffness {
            *k *= s;
        }
        b
    }

    /// The single-storey building equivalent to an oscillator (storey height `height`).
    pub fn single(o: &Oscillator, xi: f64, height: f64) -> ShearBuilding {
        ShearBuilding {
            masses: vec![o.m],
            stiffness: vec![o.k],
            heights: vec![height],
            damping: Damping::Modal(xi),
            yielding: None,
            geometric: None,
            struck_column_share: None,
        }
    }

    /// This building with P-Delta (physics.md section 10): floor `j` carries the gravity load
    /// `g m_j ratio` (`ratio`: the gravity mass ratio, 1 where the frame carries its floors'
    /// own weight, more where a leaning column adds gravity the frame does not resist), storey
    /// `j` the loads at and above it, and its lateral force gains `-P_j d_j / h_j`.
    pub fn with_p_delta(mut self, ratio: f64) -> ShearBuilding {
        // No gravity load, no geometric term: the building without P-Delta, bit for bit.
        if ratio == 0.0 {
            self.geometric = None;
            return self;
        }
        let mut above = 0.0;
        let mut g = vec![0.0; self.storeys()];
        for j in (0..self.storeys()).rev() {
            above += crate::physics::model::G * self.masses[j] * ratio;
            g[j] = above / self.heights[j];
        }
        self.geometric = Some(g);
        self
    }

    /// Each storey's stability coefficient `theta_j = P_j / (k_j h_j)` (all 0 without
    /// P-Delta); a storey with `theta_j >= 1` is unstable under gravity alone.
    pub fn stability_coefficients(&self) -> Vec<f64> {
        match &self.geometric {
            Some(g) => g.iter().zip(&self.stiffness).map(|(g, k)| g / k).collect(),
            None => vec![0.0; self.storeys()],
        }
    }

    /// The storey stiffnesses the motion sees: `k_j - P_j / h_j` with P-Delta, else `k_j`.
    pub fn effective_stiffness(&self) -> Vec<f64> {
        match &self.geometric {
            Some(g) => self.stiffness.iter().zip(g).map(|(k, g)| k - g).collect(),
            None => self.stiffness.clone(),
        }
    }

    pub fn storeys(&self) -> usize {
        self.masses.len()
    }

    /// Floor elevations above the ground, m, floor 1 first.
    pub fn elevations(&self) -> Vec<f64> {
        self.heights
            .iter()
            .scan(0.0, |z, h| {
                *z += h;
                Some(*z)
            })
            .collect()
    }

    /// `(K u)_j`: the storey forces on floor `j` (tridiagonal).
    pub fn stiffness_force(&self, u: &[f64]) -> Vec<f64> {
        let n = self.storeys();
        (0..n)
            .map(|j| {
                let below = if j == 0 { u[0] } else { u[j] - u[j - 1] };
                let above = if j + 1 < n { u[j + 1] - u[j] } else { 0.0 };
                self.stiffness[j] * below
                    - if j + 1 < n {
                        self.stiffness[j + 1] * above
                    } else {
                        0.0
                    }
            })
            .collect()
    }

    /// Eigenvalues `w^2` (ascending) and `M^(1/2)`-scaled eigenvectors of
    /// `M^(-1/2) K M^(-1/2)` (columns, `v[j][i]` = component `j` of mode `i`), by cyclic Jacobi:
    /// slow (`O(N^3)` per sweep) but accurate to rounding for any spread of stiffnesses.
    #[allow(clippy::needless_range_loop)] // rotations index rows and columns alike
    fn eigen(&self) -> (Vec<f64>, Vec<Vec<f64>>) {
        self.eigen_of(&self.stiffness)
    }

    /// [`ShearBuilding::eigen`] with storey stiffnesses `stiffness`.
    #[allow(clippy::needless_range_loop)] // rotations index rows and columns alike
    fn eigen_of(&self, stiffness: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
        let n = self.storeys();
        let s: Vec<f64> = self.masses.iter().map(|m| 1.0 / m.sqrt()).collect();
        let mut a = vec![vec![0.0; n]; n];
        for j in 0..n {
            let kj = stiffness[j] + stiffness.get(j + 1).copied().unwrap_or(0.0);
            a[j][j] = kj * s[j] * s[j];
            if j + 1 < n {
                let off = -stiffness[j + 1] * s[j] * s[j + 1];
                a[j][j + 1] = off;
                a[j + 1][j] = off;
            }
        }
        let mut v = vec![vec![0.0; n]; n];
        for (j, row) in v.iter_mut().enumerate() {
            row[j] = 1.0;
        }
        for _sweep in 0..100 {
            let off: f64 = (0..n)
                .flat_map(|p| (p + 1..n).map(move |q| (p, q)))
                .map(|(p, q)| a[p][q] * a[p][q])
                .sum();
            let diag: f64 = (0..n).map(|p| a[p][p] * a[p][p]).sum();
            if off <= 1e-32 * diag {
                break;
            }
            for p in 0..n {
                for q in p + 1..n {
                    if a[p][q] == 0.0 {
                        continue;
                    }
                    // The rotation that zeroes a[p][q] (Golub & Van Loan 8.5.2).
                    let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                    let sign = if theta >= 0.0 { 1.0 } else { -1.0 };
                    let t = sign / (theta.abs() + (theta * theta + 1.0).sqrt());
                    let c = 1.0 / (t * t + 1.0).sqrt();
                    let sn = t * c;
                    for k in 0..n {
                        let (akp, akq) = (a[k][p], a[k][q]);
                        a[k][p] = c * akp - sn * akq;
                        a[k][q] = sn * akp + c * akq;
                    }
                    for k in 0..n {
                        let (apk, aqk) = (a[p][k], a[q][k]);
                        a[p][k] = c * apk - sn * aqk;
                        a[q][k] = sn * apk + c * aqk;
                    }
                    for row in v.iter_mut() {
                        let (vp, vq) = (row[p], row[q]);
                        row[p] = c * vp - sn * vq;
                        row[q] = sn * vp + c * vq;
                    }
                }
            }
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&x, &y| a[x][x].total_cmp(&a[y][y]));
        let w2 = order.iter().map(|&i| a[i][i].max(0.0)).collect();
        let vecs = (0..n)
            .map(|j| order.iter().map(|&i| v[j][i]).collect())
            .collect();
        (w2, vecs)
    }

    /// Rayleigh's `(a0, a1)` of `C = a0 M + a1 K` for the circular frequencies `omega`
    /// (ascending): the ratio on modes 1 and 2, or `(2 xi w1, 0)` for one storey; None for
    /// modal damping.
    pub fn rayleigh(&self, omega: &[f64]) -> Option<(f64, f64)> {
        match self.damping {
            Damping::Modal(_) => None,
            Damping::Rayleigh(x) if omega.len() == 1 => Some((2.0 * x * omega[0], 0.0)),
            Damping::Rayleigh(x) => {
                let (w1, w2) = (omega[0], omega[1]);
                Some((2.0 * x * w1 * w2 / (w1 + w2), 2.0 * x / (w1 + w2)))
            }
        }
    }

    /// The building's modes (see the module docs). With P-Delta, the modes of
    /// `(K0 - K_G, M)` ([`ShearBuilding::p_delta_modes`]).
    pub fn modes(&self) -> Modes {
        if self.geometric.is_some() {
            return self.p_delta_modes();
        }
        let n = self.storeys();
        let (w2, v) = self.eigen();
        let omega: Vec<f64> = w2.iter().map(|x| x.sqrt()).collect();
        let (shape, participation) = self.shapes(&v);
        let rayleigh = self.rayleigh(&omega);
        let xi = match (self.damping, rayleigh) {
            (Damping::Rayleigh(x), _) if n == 1 => vec![x],
            (_, Some((a0, a1))) => omega.iter().map(|w| 0.5 * (a0 / w + a1 * w)).collect(),
            (Damping::Modal(x), _) | (Damping::Rayleigh(x), None) => vec![x; n],
        };
        Modes {
            omega,
            xi,
            shape,
            participation,
            coupling: None,
            rayleigh,
        }
    }
}

impl ShearBuilding {
    /// Mass-normalised shapes from the eigenvectors of `eigen_of`, each column signed so its
    /// roof component is >= 0, and the participations `phi_i^T M 1`.
    fn shapes(&self, v: &[Vec<f64>]) -> (Vec<Vec<f64>>, Vec<f64>) {
        let n = self.storeys();
        let mut shape = vec![vec![0.0; n]; n];
        for i in 0..n {
            let sign = if v[n - 1][i] < 0.0 { -1.0 } else { 1.0 };
            for j in 0..n {
                shape[j][i] = sign * v[j][i] / self.masses[j].sqrt();
            }
        }
        let participation = (0..n)
            .map(|i| (0..n).map(|j| self.masses[j] * shape[j][i]).sum())
            .collect();
        (shape, participation)
    }

    /// The modes of a P-Delta building: shapes and frequencies of `(K0 - K_G, M)`. Damping
    /// stays the elastic building's (physics.md section 10): modal damping puts its ratio on
    /// every mode; Rayleigh's `C = a0 M + a1 K0` (coefficients from modes 1 and 2 of
    /// `(K0, M)`) is `phi_i^T C phi_k = a0 delta_ik + a1 phi_i^T K0 phi_k` in these modes: its
    /// diagonal gives each mode's ratio, and where it is not classical in them (storeys that
    /// lean unequally) the rest is the coupling `E` (`a1 phi_i^T K0 phi_k`, i != k), which the
    /// schemes carry exactly (docs/collapse.md).
    fn p_delta_modes(&self) -> Modes {
        let n = self.storeys();
        let (w2, v) = self.eigen_of(&self.effective_stiffness());
        let omega: Vec<f64> = w2.iter().map(|x| x.sqrt()).collect();
        let (shape, participation) = self.shapes(&v);
        let rayleigh = match self.damping {
            Damping::Modal(_) => None,
            Damping::Rayleigh(_) => {
                let omega0: Vec<f64> = self.eigen().0.iter().map(|x| x.sqrt()).collect();
                self.rayleigh(&omega0)
            }
        };
        let (xi, coupling) = match (self.damping, rayleigh) {
            (Damping::Modal(x), _) | (Damping::Rayleigh(x), None) => (vec![x; n], None),
            (Damping::Rayleigh(_), Some((a0, a1))) => {
                // phi_i^T K0 phi_k, storey by storey.
                let drifts: Vec<Vec<f64>> = (0..n).map(|j| storey_drift_row(&shape, j)).collect();
                let k0 = |i: usize, k: usize| -> f64 {
                    (0..n)
                        .map(|j| self.stiffness[j] * drifts[j][i] * drifts[j][k])
                        .sum()
                };
                let xi: Vec<f64> = (0..n)
                    .map(|i| (a0 + a1 * k0(i, i)) / (2.0 * omega[i]))
                    .collect();
                // The coupling between modes, where it is more than rounding (it is exactly 0
                // where every storey leans alike).
                let scale = (0..n).map(|i| 2.0 * xi[i] * omega[i]).fold(0.0, f64::max);
                let e: Vec<Vec<f64>> = (0..n)
                    .map(|i| {
                        (0..n)
                            .map(|k| if i == k { 0.0 } else { a1 * k0(i, k) })
                            .collect()
                    })
                    .collect();
                let coupled = e.iter().flatten().any(|x| x.abs() > 1e-9 * scale);
                (xi, coupled.then_some(e))
            }
        };
        Modes {
            omega,
            xi,
            shape,
            participation,
            coupling,
            rayleigh,
        }
    }
}

/// Storey `j`'s drift in modes of shapes `shape` (`shape[j][i]`: floor `j + 1` in mode `i`):
/// `d_j = u_j - u_(j-1) = row . q`, the ground below storey 0.
pub fn storey_drift_row(shape: &[Vec<f64>], j: usize) -> Vec<f64> {
    (0..shape[j].len())
        .map(|i| shape[j][i] - if j == 0 { 0.0 } else { shape[j - 1][i] })
        .collect()
}

/// A building's modes: mass-normalised shapes, frequencies, damping ratios, participation.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// rad/s, ascending.
    pub omega: Vec<f64>,
    pub xi: Vec<f64>,
    /// `shape[j][i]`: floor `j + 1` in mode `i`, with `Phi^T M Phi = I` (units kg^-1/2).
    pub shape: Vec<Vec<f64>>,
    /// `L_i = phi_i^T M 1`, kg^1/2.
    pub participation: Vec<f64>,
    /// Damping that couples the modes, `E` (`q'' + 2 xi w q' + E q' + w^2 q = ...`, zero
    /// diagonal), where the damping is not classical in them: Rayleigh on `K0` in the modes of
    /// a P-Delta building whose storeys lean unequally. None where it is classical.
    pub coupling: Option<Vec<Vec<f64>>>,
    /// Rayleigh's `(a0, a1)` of `C = a0 M + a1 K0`, from the elastic building's modes 1 and 2
    /// (with P-Delta too: its damping is the elastic building's); None for modal damping.
    pub rayleigh: Option<(f64, f64)>,
}

impl Modes {
    pub fn count(&self) -> usize {
        self.omega.len()
    }

    /// Mode `i` as a unit-mass oscillator (its propagator steps `q_i` under `L_i ag`).
    pub fn oscillator(&self, i: usize) -> Oscillator {
        let w = self.omega[i];
        Oscillator {
            m: 1.0,
            k: w * w,
            c: 2.0 * self.xi[i] * w,
        }
    }

    /// Floor displacements `u = Phi q`.
    pub fn to_floors(&self, q: &[f64]) -> Vec<f64> {
        self.shape
            .iter()
            .map(|row| row.iter().zip(q).map(|(p, x)| p * x).sum())
            .collect()
    }

    /// Modal coordinates `q = Phi^T M u` of floor displacements `u`.
    pub fn to_modes(&self, masses: &[f64], u: &[f64]) -> Vec<f64> {
        (0..self.count())
            .map(|i| {
                (0..u.len())
                    .map(|j| self.shape[j][i] * masses[j] * u[j])
                    .sum()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(n: usize, m: f64, k: f64, damping: Damping) -> ShearBuilding {
        ShearBuilding {
            masses: vec![m; n],
            stiffness: vec![k; n],
            heights: vec![3.0; n],
            damping,
            yielding: None,
            geometric: None,
            struck_column_share: None,
        }
    }

    /// A uniform shear building's frequencies in closed form:
    /// `w_i = 2 sqrt(k/m) sin((2i - 1) pi / (2 (2N + 1)))`.
    #[test]
    fn uniform_building_frequencies_are_the_closed_form() {
        for n in [1, 2, 5, 20, 60] {
            let (m, k) = (2.5e5, 4e8);
            let modes = uniform(n, m, k, Damping::Modal(0.05)).modes();
            for (i, w) in modes.omega.iter().enumerate() {
                let exact = 2.0
                    * (k / m).sqrt()
                    * ((2 * i + 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64))
                        .sin();
                assert!(
                    (w - exact).abs() <= 1e-12 * exact,
                    "N {n} mode {i}: {w} vs {exact}"
                );
            }
        }
    }

    /// `Phi^T M Phi = I`, `Phi^T K Phi = diag(w^2)`, and `sum L_i phi_i = 1` (the modes span the
    /// rigid-body shape), on a building with a soft storey and uneven masses.
    #[test]
    fn modes_diagonalise_mass_and_stiffness() {
        let b = ShearBuilding {
            masses: vec![3e5, 2.8e5, 2.8e5, 2.2e5, 1.5e5],
            stiffness: vec![9e7, 6e8, 5.5e8, 4e8, 3e8],
            heights: vec![4.0, 3.0, 3.0, 3.0, 3.0],
            damping: Damping::Rayleigh(0.05),
            yielding: None,
            geometric: None,
            struck_column_share: None,
        };
        let md = b.modes();
        let n = b.storeys();
        for i in 0..n {
            let phi_i: Vec<f64> = (0..n).map(|j| md.shape[j][i]).collect();
            let kphi = b.stiffness_force(&phi_i);
            for l in 0..n {
                let mm: f64 = (0..n)
                    .map(|j| md.shape[j][l] * b.masses[j] * phi_i[j])
                    .sum();
                let kk: f64 = (0..n).map(|j| md.shape[j][l] * kphi[j]).sum();
                let want_m = if i == l { 1.0 } else { 0.0 };
                let want_k = if i == l { md.omega[i].powi(2) } else { 0.0 };
                assert!((mm - want_m).abs() < 1e-12, "M {i} {l}: {mm}");
                assert!(
                    (kk - want_k).abs() < 1e-11 * md.omega[n - 1].powi(2),
                    "K {i} {l}: {kk}"
                );
            }
        }
        for j in 0..n {
            let s: f64 = (0..n).map(|i| md.participation[i] * md.shape[j][i]).sum();
            assert!((s - 1.0).abs() < 1e-12, "floor {j}: {s}");
        }
    }

    /// Rayleigh damping gives the stated ratio on modes 1 and 2 and `a0 / (2 w) + a1 w / 2` on
    /// the others; the fundamental period is the one asked for.
    #[test]
    fn period_scaling_and_rayleigh_ratios() {
        let b = ShearBuilding::from_period(
            vec![2e5; 6],
            &[3.0, 2.5, 2.0, 1.5, 1.0, 0.5],
            vec![3.2; 6],
            0.8,
            Damping::Rayleigh(0.04),
        );
        let md = b.modes();
        let t1 = 2.0 * std::f64::consts::PI / md.omega[0];
        assert!((t1 - 0.8).abs() < 1e-12, "{t1}");
        assert!((md.xi[0] - 0.04).abs() < 1e-14 && (md.xi[1] - 0.04).abs() < 1e-14);
        // Rayleigh ratios dip between modes 1 and 2 and grow beyond mode 2.
        assert!(md.xi[5] > md.xi[4] && md.xi[4] > 0.04);
        assert_eq!(
            uniform(1, 1.0, 1.0, Damping::Rayleigh(0.03)).modes().xi,
            vec![0.03]
        );
    }

    #[test]
    fn floor_and_modal_coordinates_round_trip() {
        let b = uniform(7, 1.3e5, 2e8, Damping::Modal(0.02));
        let md = b.modes();
        let u: Vec<f64> = (0..7).map(|j| 0.01 * (j as f64 - 2.5)).collect();
        let back = md.to_floors(&md.to_modes(&b.masses, &u));
        for (a, b) in u.iter().zip(&back) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
    }

    /// A one-storey building whose storey carries `P` with `P / (k h) = theta`.
    fn leaning_sdof(theta: f64, damping: Damping) -> ShearBuilding {
        let (m, h, t0) = (2e5, 3.5, 0.6);
        let b = ShearBuilding::from_period(vec![m], &[1.0], vec![h], t0, damping);
        // P = g m r, so r = theta k h / (g m).
        let r = theta * b.stiffness[0] * h / (crate::physics::model::G * m);
        b.with_p_delta(r)
    }

    /// physics.md section 10: an elastic SDOF with P-Delta has the period `T0 / sqrt(1 -
    /// theta)`; its damping is the elastic building's (`c = 2 xi m w0` for Rayleigh on one
    /// storey; the ratio on the mode for modal damping).
    #[test]
    fn p_delta_lengthens_the_period_by_one_over_root_one_minus_theta() {
        let w0 = 2.0 * std::f64::consts::PI / 0.6;
        for theta in [0.02, 0.1, 0.3, 0.9] {
            let rayleigh = leaning_sdof(theta, Damping::Rayleigh(0.05));
            assert!((rayleigh.stability_coefficients()[0] - theta).abs() < 1e-12);
            let md = rayleigh.modes();
            let w = w0 * (1.0 - theta).sqrt();
            assert!(
                (md.omega[0] - w).abs() < 1e-12 * w,
                "{theta}: {}",
                md.omega[0]
            );
            // c / m = 2 xi w0, whatever the geometric stiffness.
            let c_over_m = 2.0 * md.xi[0] * md.omega[0];
            assert!((c_over_m - 2.0 * 0.05 * w0).abs() < 1e-12 * w0, "{theta}");
            let modal = leaning_sdof(theta, Damping::Modal(0.05)).modes();
            assert_eq!(modal.xi, vec![0.05]);
        }
    }

    /// Where every storey has the same stability coefficient, `K_G = theta K0` and Rayleigh's
    /// `C = a0 M + a1 K0` is classical in the P-Delta modes: the modes' damping is exactly
    /// `Phi^T C Phi`, with zeros off the diagonal.
    #[test]
    #[allow(clippy::needless_range_loop)] // floors j of the shapes and forces alike
    fn rayleigh_on_k0_is_exact_where_every_storey_leans_alike() {
        let n = 5;
        let (m, h) = (3e5, 3.2);
        // k_j proportional to the floors above it: P_j / (k_j h) is the same in every storey.
        let profile: Vec<f64> = (0..n).map(|j| (n - j) as f64).collect();
        let b = ShearBuilding::from_period(
            vec![m; n],
            &profile,
            vec![h; n],
            1.2,
            Damping::Rayleigh(0.05),
        )
        .with_p_delta(2.0);
        let theta = b.stability_coefficients();
        for t in &theta {
            assert!((t - theta[0]).abs() < 1e-12 * theta[0], "{theta:?}");
        }
        let elastic = ShearBuilding {
            geometric: None,
            struck_column_share: None,
            ..b.clone()
        };
        let w0 = elastic.modes().omega;
        let (a0, a1) = elastic.rayleigh(&w0).unwrap();
        let md = b.modes();
        assert_eq!(md.coupling, None);
        // Frequencies: w0 sqrt(1 - theta).
        for (w, w_0) in md.omega.iter().zip(&w0) {
            assert!((w - w_0 * (1.0 - theta[0]).sqrt()).abs() < 1e-9 * w_0);
        }
        for i in 0..n {
            for k in 0..n {
                let mut c = 0.0;
                for j in 0..n {
                    c += a0 * m * md.shape[j][i] * md.shape[j][k];
                }
                let kx =
                    elastic.stiffness_force(&(0..n).map(|j| md.shape[j][k]).collect::<Vec<_>>());
                for (j, kx_j) in kx.iter().enumerate().take(n) {
                    c += a1 * md.shape[j][i] * kx_j;
                }
                let want = if i == k {
                    2.0 * md.xi[i] * md.omega[i]
                } else {
                    0.0
                };
                assert!(
                    (c - want).abs() < 1e-9 * md.omega[n - 1],
                    "({i}, {k}): {c} vs {want}"
                );
            }
        }
    }

    /// Where the storeys lean unequally, the modes' damping is all of `C = a0 M + a1 K0` in
    /// them: `2 xi w` on the diagonal, the coupling `E` off it.
    #[test]
    #[allow(clippy::needless_range_loop)] // floors j of the shapes and forces alike
    fn rayleigh_on_k0_couples_the_modes_where_storeys_lean_unequally() {
        let n = 4;
        let b = ShearBuilding::from_period(
            vec![3e5, 3e5, 2.5e5, 2e5],
            &[1.0, 0.9, 0.8, 0.6],
            vec![4.0, 3.5, 3.5, 3.5],
            1.0,
            Damping::Rayleigh(0.05),
        )
        .with_p_delta(2.0);
        let elastic = ShearBuilding {
            geometric: None,
            struck_column_share: None,
            ..b.clone()
        };
        let (a0, a1) = elastic.rayleigh(&elastic.modes().omega).unwrap();
        let md = b.modes();
        let e = md
            .coupling
            .clone()
            .expect("unequal storeys couple the modes");
        for i in 0..n {
            for k in 0..n {
                let mut c = 0.0;
                for j in 0..n {
                    c += a0 * b.masses[j] * md.shape[j][i] * md.shape[j][k];
                }
                let kx =
                    elastic.stiffness_force(&(0..n).map(|j| md.shape[j][k]).collect::<Vec<_>>());
                for j in 0..n {
                    c += a1 * md.shape[j][i] * kx[j];
                }
                let want = if i == k {
                    2.0 * md.xi[i] * md.omega[i]
                } else {
                    e[i][k]
                };
                assert!(
                    (c - want).abs() < 1e-9 * md.omega[n - 1],
                    "({i}, {k}): {c} vs {want}"
                );
            }
        }
        assert!(e[0][1].abs() > 1e-6 * md.omega[n - 1]);
    }

    /// A gravity mass ratio of 0 carries no load: the building without P-Delta, bit for bit.
    #[test]
    fn no_gravity_load_is_no_p_delta() {
        let b = ShearBuilding::from_period(
            vec![2e5, 2e5, 1e5],
            &[1.0, 0.8, 0.6],
            vec![4.0, 3.0, 3.0],
            0.5,
            Damping::Rayleigh(0.05),
        );
        let zero = b.clone().with_p_delta(0.0);
        assert_eq!(zero, b);
        assert_eq!(zero.modes(), b.modes());
        assert_eq!(zero.stability_coefficients(), vec![0.0; 3]);
    }
}
