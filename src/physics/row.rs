//! A row of multi-storey buildings, left to right, that may pound: the scene of a multi-storey
//! run, and what such a run reports.
//!
//! Adjacent buildings `a` and `a + 1` stand `gaps[a]` apart. They touch at contact levels:
//! floor against floor where both have a floor at the same elevation (within
//! [`LevelRule::same_level_m`]), and floor against column where a floor faces the neighbour's
//! storey between its floors (physics.md section 11; [`LevelRule::floor_column`] turns these
//! off). A storey's columns deflect as fixed-fixed members, `u(xi) = u_(j-1) + (u_j - u_(j-1))
//! s(xi)` with `s = 3 xi^2 - 2 xi^3`, and the force reaches the storey's two floors as
//! `(1 - s) F` and `s F` ([`LevelSide`]). Each level has its own contact element: the run's law,
//! stiffness and damping ratio, with the effective mass of the two colliding points,
//! `m_eff = m_A m_B / (m_A + m_B)`, a column's point mass being `1 / ((1 - s)^2 / m_(j-1) + s^2
//! / m_j)` (the ground's term 0).

use crate::physics::contact::{Contact, LawKind};
use crate::physics::model::{EnergyBalance, RunOutput, Status};
use crate::physics::shear::ShearBuilding;

/// Two floors of neighbouring buildings are at the same level, by default, when their
/// elevations differ by at most this, m.
pub const LEVEL_TOLERANCE_M: f64 = 0.01;

/// Which contact levels a row has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelRule {
    /// Floors whose elevations differ by at most this are one floor/floor level, m.
    pub same_level_m: f64,
    /// A floor that faces the neighbour's storey between its floors strikes its columns.
    pub floor_column: bool,
}

impl Default for LevelRule {
    fn default() -> LevelRule {
        LevelRule {
            same_level_m: LEVEL_TOLERANCE_M,
            floor_column: true,
        }
    }
}

/// Where a level meets one of its buildings: a floor, or the columns of a storey at a height
/// between its floors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelSide {
    /// The floor (from 1); on a column, the floor at the top of the struck storey (the
    /// storey's number).
    pub floor: usize,
    /// The share of the point's motion and force on `floor`: 1 on a floor; on a column
    /// `s = 3 xi^2 - 2 xi^3` at `xi` up the storey, the rest `1 - s` on the floor below (none on
    /// the ground).
    pub weight: f64,
    /// The height fraction `xi` up the struck storey (1 on a floor).
    pub xi: f64,
}

impl LevelSide {
    pub fn floor(floor: usize) -> LevelSide {
        LevelSide {
            floor,
            weight: 1.0,
            xi: 1.0,
        }
    }

    /// The column of storey `storey` (from 1) at `xi` up it (`0 < xi < 1`).
    pub fn column(storey: usize, xi: f64) -> LevelSide {
        LevelSide {
            floor: storey,
            weight: xi * xi * (3.0 - 2.0 * xi),
            xi,
        }
    }

    pub fn on_column(&self) -> bool {
        self.weight != 1.0
    }

    /// The point's value (displacement, velocity, acceleration) from its building's floors'
    /// `x` (the lowest floor first). On a floor exactly `x[floor - 1]`.
    #[inline]
    pub fn at(&self, x: &[f64]) -> f64 {
        let top = x[self.floor - 1];
        if self.weight == 1.0 {
            return top;
        }
        let below = if self.floor >= 2 {
            x[self.floor - 2]
        } else {
            0.0
        };
        self.weight * top + (1.0 - self.weight) * below
    }

    /// Each floor (from 0) the point moves with, and its share: the transpose of
    /// [`LevelSide::at`], so a force `F` at the point does the work `F u(xi)`.
    pub fn shares(&self) -> impl Iterator<Item = (usize, f64)> {
        let f = self.floor - 1;
        let below = (self.weight != 1.0 && f >= 1).then(|| (f - 1, 1.0 - self.weight));
        below.into_iter().chain(std::iter::once((f, self.weight)))
    }

    /// The point's row of mode shapes, `u = row . q`, from its building's (`shape[f]`: floor
    /// `f`'s, from 0): its floors' rows by their shares (a floor's own row on a floor).
    pub fn mode_row(&self, shape: &[Vec<f64>]) -> Vec<f64> {
        let f = self.floor - 1;
        if self.weight == 1.0 {
            return shape[f].clone();
        }
        let mut row = vec![0.0; shape[f].len()];
        for (f, w) in self.shares() {
            for (r, p) in row.iter_mut().zip(&shape[f]) {
                *r += w * p;
            }
        }
        row
    }

    /// The point's mass under a force there: `1 / sum share^2 / m` over its floors (the
    /// ground takes no share of the motion).
    pub fn point_mass(&self, masses: &[f64]) -> f64 {
        if self.weight == 1.0 {
            return masses[self.floor - 1];
        }
        1.0 / self.shares().map(|(f, w)| w * w / masses[f]).sum::<f64>()
    }

    /// Its name in a level's column prefix: `f3` for floor 3, `c3` for storey 3's column.
    pub fn name(&self) -> String {
        let kind = if self.on_column() { 'c' } else { 'f' };
        format!("{kind}{}", self.floor)
    }
}

/// A contact level: a point of building `left` against a point of building `left + 1`, at
/// least one of them a floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    pub left: usize,
    pub sides: [LevelSide; 2],
    /// Elevation of the level (the striking floor's), m.
    pub elevation: f64,
    pub contact: Contact,
}

impl Level {
    /// Does a floor strike a column here?
    pub fn floor_column(&self) -> bool {
        struck_side(&self.sides).is_some()
    }
}

/// Which side of a level (0 left, 1 right) is a struck column, if one is.
pub fn struck_side(sides: &[LevelSide; 2]) -> Option<usize> {
    (0..2).find(|&k| sides[k].on_column())
}

/// Buildings left to right, the gap between each adjacent two, and the contact levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub buildings: Vec<ShearBuilding>,
    /// m, `gaps[a]` between building `a` and `a + 1`.
    pub gaps: Vec<f64>,
    /// Ordered by adjacent pair, then by elevation.
    pub levels: Vec<Level>,
    /// A run collapses when any storey's drift ratio reaches this (infinite: never;
    /// [`Row::with_collapse`]).
    pub collapse_drift_ratio: f64,
}

impl Row {
    /// A row whose contact levels ([`LevelRule::default`]) all use `law` with `stiffness` and
    /// dimensionless damping `damping_ratio` (see [`Contact::new`]). Panics unless there is
    /// one gap per adjacent pair.
    pub fn new(
        buildings: Vec<ShearBuilding>,
        gaps: Vec<f64>,
        law: LawKind,
        stiffness: f64,
        damping_ratio: f64,
    ) -> Row {
        let rule = LevelRule::default();
        Row::with_levels(buildings, gaps, law, stiffness, damping_ratio, rule)
    }

    /// [`Row::new`] with the levels `rule` gives.
    pub fn with_levels(
        buildings: Vec<ShearBuilding>,
        gaps: Vec<f64>,
        law: LawKind,
        stiffness: f64,
        damping_ratio: f64,
        rule: LevelRule,
    ) -> Row {
        assert_eq!(gaps.len() + 1, buildings.len(), "one gap per adjacent pair");
        let mut levels = Vec::new();
        for (a, pair) in buildings.windows(2).enumerate() {
            for point in contact_points(&pair[0], &pair[1], rule) {
                let [ma, mb] = [0, 1].map(|k| point.sides[k].point_mass(&pair[k].masses));
                let (k, m_eff) = (point.share * stiffness, point.share * ma * mb / (ma + mb));
                let k = match struck_side(&point.sides) {
                    Some(side) if law == LawKind::Linear => {
                        let struck = &pair[side];
                        let j = point.sides[side].floor - 1;
                        struck.struck_column_share.map_or(k, |alpha| {
                            let k_loc =
                                local_stiffness(alpha * struck.stiffness[j], point.sides[side].xi);
                            k * k_loc / (k + k_loc)
                        })
                    }
                    _ => k,
                };
                levels.push(Level {
                    left: a,
                    sides: point.sides,
                    elevation: point.elevation,
                    contact: Contact::new(law, k, damping_ratio, m_eff),
                });
            }
        }
        Row {
            buildings,
            gaps,
            levels,
            collapse_drift_ratio: f64::INFINITY,
        }
    }

    /// This row with runs that collapse when any storey's drift ratio reaches `drift_ratio`.
    pub fn with_collapse(mut self, drift_ratio: f64) -> Row {
        self.collapse_drift_ratio = drift_ratio;
        self
    }

    /// Total storeys (degrees of freedom) of the row.
    pub fn storeys(&self) -> usize {
        self.buildings.iter().map(|b| b.storeys()).sum()
    }
}

/// The local stiffness of fixed-fixed columns of lateral stiffness `k_col = 12 EI / h^3`
/// under a point load at `xi` up them, `3 EI h^3 / (a^3 b^3) = k_col / (4 xi^3 (1 - xi)^3)`
/// (physics.md section 11).
pub fn local_stiffness(k_col: f64, xi: f64) -> f64 {
    let c = xi * (1.0 - xi);
    k_col / (4.0 * c * c * c)
}

/// A contact point of two neighbours ([`contact_points`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    pub sides: [LevelSide; 2],
    /// m
    pub elevation: f64,
    /// The share of the contact's stiffness and mass the point takes: 1, but from 1/2 to 1
    /// over `same_level_m` to `2 same_level_m` where its partner lies as close ([`contact_points`]).
    pub share: f64,
}

/// The contact points of `left` and `right`, lowest first: every two floors at the same
/// elevation (within `rule.same_level_m`), and with `rule.floor_column` every other floor of
/// either against the neighbour's storey at its height (none above the neighbour's roof).
///
/// Two floors `d` apart just beyond the tolerance give two floor/column points that both move
/// almost as the one floor/floor level they become within it: each takes a share of the
/// contact that rises smoothly from 1/2 at `d = same_level_m` to 1 at twice that, so the
/// motion does not jump where two points become one.
pub fn contact_points(
    left: &ShearBuilding,
    right: &ShearBuilding,
    rule: LevelRule,
) -> Vec<ContactPoint> {
    let tol = rule.same_level_m;
    let z = [left.elevations(), right.elevations()];
    let mut points: Vec<ContactPoint> = Vec::new();
    // Per point on a column: the striking side, and the struck storey's nearer floor.
    let mut struck: Vec<Option<(usize, usize, f64)>> = Vec::new();
    // Each floor's nearest floor of the other building within the tolerance; two floors are
    // one level where each is the other's nearest (so the pairs do not depend on which
    // building is on the left).
    let nearest = |k: usize, e: f64| -> Option<usize> {
        (z[1 - k].iter().enumerate())
            .filter(|(_, &o)| (e - o).abs() <= tol)
            .min_by(|a, b| (e - a.1).abs().total_cmp(&(e - b.1).abs()))
            .map(|(f, _)| f)
    };
    let paired = |k: usize, f: usize| -> bool {
        nearest(k, z[k][f]).is_some_and(|g| nearest(1 - k, z[1 - k][g]) == Some(f))
    };
    for (fa, &ea) in z[0].iter().enumerate() {
        if !paired(0, fa) {
            continue;
        }
        let fb = nearest(0, ea).expect("a paired floor");
        points.push(ContactPoint {
            sides: [LevelSide::floor(fa + 1), LevelSide::floor(fb + 1)],
            elevation: ea,
            share: 1.0,
        });
        struck.push(None);
    }
    if rule.floor_column {
        for k in 0..2 {
            let other = 1 - k;
            for (f, &e) in z[k].iter().enumerate() {
                if paired(k, f) {
                    continue;
                }
                // The neighbour's storey at `e`: the first floor above it.
                let Some(j) = z[other].iter().position(|&o| o > e) else {
                    continue;
                };
                let bottom = if j == 0 { 0.0 } else { z[other][j - 1] };
                let xi = (e - bottom) / (z[other][j] - bottom);
                let mut sides = [LevelSide::floor(f + 1); 2];
                sides[other] = LevelSide::column(j + 1, xi);
                points.push(ContactPoint {
                    sides,
                    elevation: e,
                    share: 1.0,
                });
                // The nearer of the struck storey's floors (the ground has no partner).
                let near = if xi >= 0.5 {
                    Some((j, z[other][j]))
                } else {
                    j.checked_sub(1).map(|b| (b, bottom))
                };
                struck.push(near.map(|(floor, zn)| (k, floor, (e - zn).abs())));
            }
        }
        // Partners: the point where the struck storey's nearer floor strikes this floor's
        // storey, as close to this one.
        let shares: Vec<f64> = (0..points.len())
            .map(|i| {
                let Some((k, near, d)) = struck[i] else {
                    return 1.0;
                };
                let striking = points[i].sides[k].floor - 1;
                let partner = (0..points.len()).any(|p| match struck[p] {
                    Some((kp, near_p, _)) => {
                        kp != k && points[p].sides[kp].floor - 1 == near && near_p == striking
                    }
                    None => false,
                });
                if partner {
                    let r = ((d - tol) / tol).clamp(0.0, 1.0);
                    0.5 + 0.5 * r * r * (3.0 - 2.0 * r)
                } else {
                    1.0
                }
            })
            .collect();
        for (p, s) in points.iter_mut().zip(shares) {
            p.share = s;
        }
    }
    points.sort_by(|a, b| a.elevation.total_cmp(&b.elevation));
    points
}

/// What one contact level reports. Peaks are over the whole simulated time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LevelOutput {
    pub impacts: u32,
    /// N
    pub peak_force: f64,
    /// m
    pub peak_penetration: f64,
    /// Approach speed of the impact with the largest peak force, m/s (0 if none).
    pub impact_velocity: f64,
    /// s
    pub first_impact: Option<f64>,
    /// s
    pub contact_time: f64,
    /// Net work of the contact force on the relative motion, J.
    pub dissipated_energy: f64,
    /// Where a floor strikes a column: the struck storey's largest column shear while in
    /// contact, N (the storey's spring force with the share of the contact force each
    /// segment of the column carries: `max(|V - s F|, |V + (1 - s) F|)`; with
    /// `struck_column_share` `alpha`, the struck columns' `alpha V` in place of `V`); 0
    /// elsewhere.
    pub column_shear: f64,
    /// That shear over the storey's yield force (`alpha` of it with the key), where it yields
    /// (0 elsewhere).
    pub column_shear_ratio: f64,
}

/// What one building reports. Peaks are over the whole simulated time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BuildingOutput {
    /// max |u| of the top floor relative to the ground, m.
    pub peak_roof: f64,
    /// max over storeys of `|u_j - u_(j-1)| / h_j`.
    pub peak_drift_ratio: f64,
    /// The storey of that drift (from 1; 0 while the building has not moved).
    pub drift_storey: u32,
    /// max |absolute floor acceleration| (relative acceleration plus the ground's), m/s^2.
    pub peak_accel: f64,
    /// The floor of that acceleration (from 1; 0 while the building has not moved).
    pub accel_floor: u32,
    /// Residual drift, ductility and hysteretic energy, where its storeys yield.
    pub inelastic: Option<InelasticOutput>,
    /// Where and when this building collapsed (physics.md section 12): it left the scene
    /// there, its peaks are over `[0, t_c]`; None where it stood to the end.
    pub collapse: Option<Collapse>,
}

/// What a yielding building reports besides the elastic peaks.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InelasticOutput {
    /// Largest `|p_j| / h_j` over the storeys at rest after the motion; NaN where the run did
    /// not settle (`solver::row::yielding::SETTLE_PERIODS`) or failed.
    pub residual_drift_ratio: f64,
    /// Its storey (from 1; 0 when no storey yielded).
    pub residual_storey: u32,
    /// Largest `max_t |d_j| / d_y,j` over the storeys.
    pub peak_ductility: f64,
    /// Its storey (from 1).
    pub ductility_storey: u32,
    /// `sum_j int f_j dp_j`: the springs' work less the elastic energy they hold at the end, J.
    pub hysteretic_energy: f64,
    /// Storeys that yielded at least once.
    pub yielded_storeys: u32,
    /// The smallest IMK strength ratio over the storeys ([`StoreyOutput::strength_ratio`]);
    /// NaN where no storey is IMK.
    pub strength_ratio: f64,
    /// IMK storeys that passed their capping point.
    pub capped_storeys: u32,
}

/// What one yielding storey reports (with `--columns` asking for it).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StoreyOutput {
    /// `p_j / h_j` at rest after the motion, signed (positive: the floor above to the right);
    /// NaN where the run did not settle.
    pub residual_drift_ratio: f64,
    /// `max_t |d_j| / d_y,j`.
    pub peak_ductility: f64,
    /// `int f_j dp_j`, J.
    pub hysteretic_energy: f64,
    /// It yielded at least once.
    pub yielded: bool,
    /// An IMK storey's capping strength left over its initial one, the weaker side's (0: no
    /// strength left); NaN for a bilinear storey.
    pub strength_ratio: f64,
    /// An IMK storey passed its capping point.
    pub capped: bool,
}

impl InelasticOutput {
    /// Gather a building's storeys (bottom to top): the largest `|residual|` and ductility with
    /// their storeys, the hysteretic energies summed, the storeys that yielded, the weakest
    /// IMK storey's strength ratio and the storeys that passed capping.
    pub fn gather(storeys: &[StoreyOutput]) -> InelasticOutput {
        let mut out = InelasticOutput {
            strength_ratio: f64::NAN,
            ..InelasticOutput::default()
        };
        let mut residual: f64 = 0.0;
        for (j, st) in storeys.iter().enumerate() {
            if st.residual_drift_ratio.abs() > residual {
                residual = st.residual_drift_ratio.abs();
                out.residual_storey = j as u32 + 1;
            }
            if st.peak_ductility > out.peak_ductility {
                out.peak_ductility = st.peak_ductility;
                out.ductility_storey = j as u32 + 1;
            }
            out.hysteretic_energy += st.hysteretic_energy;
            out.yielded_storeys += st.yielded as u32;
            // `min` takes the other where one is NaN: a bilinear storey's NaN is skipped.
            out.strength_ratio = out.strength_ratio.min(st.strength_ratio);
            out.capped_storeys += st.capped as u32;
        }
        out.residual_drift_ratio = residual;
        out
    }
}

/// Per-run results of a row. The totals gather the levels: impacts summed, the largest peak
/// force (with its impact velocity), the earliest first impact, contact time and dissipated
/// energy summed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RowOutput {
    pub status: Status,
    pub impacts: u32,
    pub peak_force: f64,
    pub impact_velocity: f64,
    pub first_impact: Option<f64>,
    pub contact_time: f64,
    pub dissipated_energy: f64,
    pub levels: Vec<LevelOutput>,
    pub buildings: Vec<BuildingOutput>,
    /// Integration work beyond the exact free steps (as [`crate::physics::model::RunOutput`]).
    pub substeps: u64,
    /// Record steps taken whole by the exact modal propagators.
    pub free_steps: u64,
    /// Record steps settled by a shared free response instead (a row that runs on the pair's
    /// kernels, [`RowOutput::of_pair`]).
    pub shared_steps: u64,
    pub energy: Option<EnergyBalance>,
    /// Every yielding storey, building by building, bottom to top (none in an elastic row).
    pub storeys: Vec<StoreyOutput>,
    /// Per contact level, its floors' closing and peaks, where the run was asked to track them
    /// (the separation of uncoupled buildings); empty otherwise.
    pub closings: Vec<LevelClosing>,
    /// The run's first collapse (status `collapsed`): the earliest of the buildings'
    /// ([`BuildingOutput::collapse`]).
    pub collapse: Option<Collapse>,
    /// Per building, each storey's and floor's peaks, where the run was asked to track them
    /// (`RowModel::track_demands`); empty otherwise.
    pub demands: Vec<BuildingDemands>,
}

/// A building's demands storey by storey and floor by floor (bottom to top), over the whole
/// simulated time (up to its collapse, where it collapsed: its collapsed storey at the limit).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BuildingDemands {
    /// Each storey's `max |u_j - u_(j-1)| / h_j`.
    pub peak_drift_ratio: Vec<f64>,
    /// Each floor's (from floor 1) max |absolute acceleration|, m/s^2.
    pub peak_accel: Vec<f64>,
}

impl BuildingDemands {
    /// A one-storey building's, from its peaks (a row that runs on the pair's kernels).
    pub fn of_one_storey(b: &BuildingOutput) -> BuildingDemands {
        BuildingDemands {
            peak_drift_ratio: vec![b.peak_drift_ratio],
            peak_accel: vec![b.peak_accel],
        }
    }
}

/// Where and when a run collapsed: the first storey whose drift ratio reached the limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collapse {
    /// s
    pub time: f64,
    /// Building and storey, from 1.
    pub building: u32,
    pub storey: u32,
}

/// What a contact level's two floors do over a run: the largest closing
/// `max_t (u_left - u_right)` (from 0 at rest) and when it is reached (None while it stays at
/// or below 0), and each floor's peak `max_t |u|`, m.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LevelClosing {
    pub closing: f64,
    pub time: Option<f64>,
    pub peak_left: f64,
    pub peak_right: f64,
}

impl RowOutput {
    /// What a row of two one-storey buildings of storey heights `heights` reports, from the run
    /// of the same pair of oscillators (tracking their accelerations,
    /// [`crate::physics::solver::simulate_tracking_accel`]): its one level is the pair's contact;
    /// a storey's drift is its floor's displacement.
    pub fn of_pair(out: &RunOutput, heights: [f64; 2]) -> RowOutput {
        let level = LevelOutput {
            impacts: out.impacts,
            peak_force: out.peak_force,
            peak_penetration: out.peak_penetration,
            impact_velocity: out.impact_velocity,
            first_impact: out.first_impact,
            contact_time: out.contact_time,
            dissipated_energy: out.dissipated_energy,
            ..LevelOutput::default()
        };
        let building = |u: f64, a: f64, h: f64| BuildingOutput {
            peak_roof: u,
            peak_drift_ratio: u / h,
            drift_storey: (u > 0.0) as u32,
            peak_accel: a,
            accel_floor: (a > 0.0) as u32,
            inelastic: None,
            collapse: None,
        };
        let mut row = RowOutput {
            status: out.status,
            levels: vec![level],
            buildings: vec![
                building(out.peak_u1, out.peak_accel[0], heights[0]),
                building(out.peak_u2, out.peak_accel[1], heights[1]),
            ],
            substeps: out.substeps,
            free_steps: out.free_steps,
            shared_steps: out.shared_steps,
            energy: out.energy,
            ..RowOutput::default()
        };
        row.gather();
        row
    }

    /// Each yielding building's outputs from its storeys in `self.storeys` (`spans`: each
    /// building's storeys there, None where it is elastic); the residual drifts are known only
    /// where the run `settled` (else NaN, not a guess). The CPU schemes and the GPU row
    /// kernel's readback both end with this.
    pub(crate) fn gather_storeys(
        &mut self,
        spans: &[Option<std::ops::Range<usize>>],
        settled: &[bool],
    ) {
        for ((b, span), &settled) in self.buildings.iter_mut().zip(spans).zip(settled) {
            b.inelastic = span.clone().map(|r| {
                let mut ie = InelasticOutput::gather(&self.storeys[r.clone()]);
                if !settled {
                    ie.residual_drift_ratio = f64::NAN;
                    for st in self.storeys[r].iter_mut() {
                        st.residual_drift_ratio = f64::NAN;
                    }
                }
                ie
            });
        }
    }

    /// Fill the totals from the levels.
    pub(crate) fn gather(&mut self) {
        self.impacts = self.levels.iter().map(|l| l.impacts).sum();
        // From +0 (a float sum starts at -0): a building alone has no level.
        self.contact_time = self.levels.iter().fold(0.0, |a, l| a + l.contact_time);
        self.dissipated_energy = (self.levels.iter()).fold(0.0, |a, l| a + l.dissipated_energy);
        self.first_impact = self
            .levels
            .iter()
            .filter_map(|l| l.first_impact)
            .min_by(f64::total_cmp);
        (self.peak_force, self.impact_velocity) = (0.0, 0.0);
        for l in &self.levels {
            if l.peak_force > self.peak_force {
                (self.peak_force, self.impact_velocity) = (l.peak_force, l.impact_velocity);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shear::Damping;

    fn building(n: usize, h: f64, m: f64) -> ShearBuilding {
        ShearBuilding::from_period(
            vec![m; n],
            &vec![1.0; n],
            vec![h; n],
            0.1 * n as f64,
            Damping::Modal(0.05),
        )
    }

    #[test]
    fn levels_are_the_floors_at_equal_elevations() {
        // 3 storeys of 3 m against 6 of 3 m: levels at 3, 6, 9 m. Then 4 of 4.5 m: the 6-storey
        // building's floors at 9 and 18 m meet floors 2 and 4 of the third.
        let row = Row::new(
            vec![
                building(3, 3.0, 2e5),
                building(6, 3.0, 4e5),
                building(4, 4.5, 3e5),
            ],
            vec![0.02, 0.03],
            LawKind::Hertz,
            2.75e9,
            0.0,
        );
        let got: Vec<(usize, usize, usize)> = row
            .levels
            .iter()
            .filter(|l| !l.floor_column())
            .map(|l| (l.left, l.sides[0].floor, l.sides[1].floor))
            .collect();
        assert_eq!(
            got,
            vec![(0, 1, 1), (0, 2, 2), (0, 3, 3), (1, 3, 2), (1, 6, 4)]
        );
        let m = 2e5 * 4e5 / 6e5;
        assert!((row.levels[0].contact.m_eff - m).abs() < 1e-9 * m);
        assert_eq!(row.storeys(), 13);
    }

    #[test]
    fn floors_at_different_heights_strike_columns() {
        // 3 storeys of 3.5 m against 4 of 3 m: floors at 3.5, 7, 10.5 against 3, 6, 9, 12.
        let (a, b) = (building(3, 3.5, 2e5), building(4, 3.0, 3e5));
        let row = Row::new(vec![a, b], vec![0.02], LawKind::Linear, 1e9, 0.0);
        let got: Vec<(String, String, f64)> = (row.levels.iter())
            .map(|l| (l.sides[0].name(), l.sides[1].name(), l.elevation))
            .collect();
        let want = [
            ("c1", "f1", 3.0),
            ("f1", "c2", 3.5),
            ("c2", "f2", 6.0),
            ("f2", "c3", 7.0),
            ("c3", "f3", 9.0),
            ("f3", "c4", 10.5),
        ];
        assert_eq!(got.len(), want.len(), "{got:?}");
        for ((l, r, z), (wl, wr, wz)) in got.iter().zip(want) {
            assert_eq!((l.as_str(), r.as_str()), (wl, wr));
            assert!((z - wz).abs() < 1e-12);
        }
        // Floor 1 of the left building (3.5 m) is a sixth of the way up the right's storey 2
        // (3-6 m): s = 3 / 36 - 2 / 216.
        let side = row.levels[1].sides[1];
        let s = 3.0 / 36.0 - 2.0 / 216.0;
        assert!((side.weight - s).abs() < 1e-15);
        assert!((side.at(&[2.0, 4.0, 0.0, 0.0]) - (2.0 + 2.0 * s)).abs() < 1e-12);
        // Storey 1's column shares its point with the ground: only floor 1 moves it.
        let low = row.levels[0].sides[0];
        let xi: f64 = 3.0 / 3.5;
        assert!((low.weight - xi * xi * (3.0 - 2.0 * xi)).abs() < 1e-15);
        assert_eq!(low.shares().collect::<Vec<_>>(), vec![(0, low.weight)]);
        assert!((low.point_mass(&[2e5; 3]) - 2e5 / (low.weight * low.weight)).abs() < 1e-6);
        // The point's mass: 1 / ((1 - s)^2 / m_1 + s^2 / m_2), and the effective mass with it.
        let mp = 1.0 / ((1.0 - s) * (1.0 - s) / 3e5 + s * s / 3e5);
        let want = 2e5 * mp / (2e5 + mp);
        assert!((row.levels[1].contact.m_eff - want).abs() < 1e-9 * want);
        // Turned off: only common floors (none here).
        let rule = LevelRule {
            floor_column: false,
            ..LevelRule::default()
        };
        let (a, b) = (building(3, 3.5, 2e5), building(4, 3.0, 3e5));
        let off = Row::with_levels(vec![a, b], vec![0.02], LawKind::Linear, 1e9, 0.0, rule);
        assert!(off.levels.is_empty());
    }

    /// A force at a column's point does the work of its shares on the floors: the split is the
    /// transpose of how the point moves, so any floor motion gives `F u(xi)` both ways.
    #[test]
    fn a_column_point_splits_its_force_by_virtual_work() {
        for (storey, xi) in [(1, 0.3), (2, 0.3), (3, 0.77)] {
            let side = LevelSide::column(storey, xi);
            let u = [0.013, -0.007, 0.021];
            let f = 2.5e5;
            let work: f64 = side.shares().map(|(k, w)| w * f * u[k]).sum();
            assert!((work - f * side.at(&u)).abs() < 1e-12 * f);
            // Statically the shares carry the whole force, except what the ground takes.
            let carried: f64 = side.shares().map(|(_, w)| w).sum();
            let want = if storey == 1 { side.weight } else { 1.0 };
            assert!((carried - want).abs() < 1e-15);
        }
    }

    /// Two floors just beyond the tolerance apart give two floor/column points that each take a
    /// half share, rising to whole ones at twice the tolerance: where they become one level,
    /// the contact's stiffness does not jump.
    #[test]
    fn points_that_become_one_level_share_the_contact() {
        let shares = |h: f64| -> Vec<f64> {
            let (a, b) = (building(3, 3.0, 2e5), building(3, h, 2e5));
            contact_points(&a, &b, LevelRule::default())
                .iter()
                .map(|p| p.share)
                .collect()
        };
        assert_eq!(shares(3.0), vec![1.0; 3]);
        // Floor 1 at 3.0 against 3.005: one level.
        assert_eq!(shares(3.005).len(), 3);
        // Just past 0.01 m: floor 1's two points take half shares (the higher floors are
        // farther apart; the right's roof is above the left's).
        let near = shares(3.0101);
        assert_eq!(near.len(), 5);
        assert!(
            near.iter().take(2).all(|&s| (s - 0.5).abs() < 1e-3),
            "{near:?}"
        );
        let far = shares(3.3);
        assert!(far.iter().all(|&s| s == 1.0), "{far:?}");
    }

    /// Floors pair by mutual nearness: with a wide tolerance, A's floors at 3.4 and 6.4 m
    /// against B's at 3.0, 3.7 and 6.7 m give the same points whichever is on the left (before,
    /// a floor paired with the first within the tolerance, and one within it of a paired floor
    /// was left out).
    #[test]
    fn the_points_do_not_depend_on_which_building_is_left() {
        let a = ShearBuilding::from_period(
            vec![2e5; 2],
            &[1.0; 2],
            vec![3.4, 3.0],
            0.3,
            Damping::Modal(0.05),
        );
        let b = ShearBuilding::from_period(
            vec![2e5; 3],
            &[1.0; 3],
            vec![3.0, 0.7, 3.0],
            0.3,
            Damping::Modal(0.05),
        );
        let rule = LevelRule {
            same_level_m: 0.5,
            floor_column: true,
        };
        let key = |p: &ContactPoint, flip: bool| {
            let [l, r] = p.sides;
            let (l, r) = if flip { (r, l) } else { (l, r) };
            (l.name(), r.name())
        };
        let ab: Vec<_> = (contact_points(&a, &b, rule).iter())
            .map(|p| key(p, false))
            .collect();
        let mut ba: Vec<_> = (contact_points(&b, &a, rule).iter())
            .map(|p| key(p, true))
            .collect();
        let mut sorted = ab.clone();
        sorted.sort();
        ba.sort();
        assert_eq!(sorted, ba);
        // 3.4 pairs with 3.7 (each the other's nearest), 6.4 with 6.7; B's 3.0 m floor, whose
        // nearest (3.4) is paired, strikes A's first storey.
        let want: Vec<(String, String)> = [("c1", "f1"), ("f1", "f2"), ("f2", "f3")]
            .iter()
            .map(|(l, r)| (l.to_string(), r.to_string()))
            .collect();
        assert_eq!(ab, want);
    }

    #[test]
    fn floors_at_different_heights_never_touch_without_columns() {
        let rule = LevelRule {
            floor_column: false,
            ..LevelRule::default()
        };
        let row = Row::with_levels(
            vec![building(3, 3.0, 2e5), building(3, 3.2, 2e5)],
            vec![0.02],
            LawKind::Linear,
            1e9,
            0.0,
            rule,
        );
        assert!(row.levels.is_empty());
    }
}
