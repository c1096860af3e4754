//! A row of multi-storey buildings, left to right, that may pound floor against floor: the
//! scene of a multi-storey run, and what such a run reports.
//!
//! Adjacent buildings `a` and `a + 1` stand `gaps[a]` apart. They can touch at every floor level
//! both have at the same elevation (within [`LEVEL_TOLERANCE_M`]); floors at different heights
//! never touch floor to floor (mid-column pounding is not modelled). Each such contact level
//! has its own contact element: the run's law, stiffness and damping ratio, with the effective
//! mass of the two colliding floors, `m_eff = m_A m_B / (m_A + m_B)`.

use crate::physics::contact::{Contact, LawKind};
use crate::physics::model::{EnergyBalance, RunOutput, Status};
use crate::physics::shear::ShearBuilding;

/// Two floors of neighbouring buildings are at the same level when their elevations differ by
/// at most this, m.
pub const LEVEL_TOLERANCE_M: f64 = 0.01;

/// A contact level: floor `floor_left` of building `left` against floor `floor_right` of
/// building `left + 1` (floors counted from 1, the lowest above the ground).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    pub left: usize,
    pub floor_left: usize,
    pub floor_right: usize,
    /// Elevation of the level (the left floor's), m.
    pub elevation: f64,
    pub contact: Contact,
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
    /// A row whose contact levels all use `law` with `stiffness` and dimensionless damping
    /// `damping_ratio` (see [`Contact::new`]). Panics unless there is one gap per adjacent pair.
    pub fn new(
        buildings: Vec<ShearBuilding>,
        gaps: Vec<f64>,
        law: LawKind,
        stiffness: f64,
        damping_ratio: f64,
    ) -> Row {
        assert_eq!(gaps.len() + 1, buildings.len(), "one gap per adjacent pair");
        let mut levels = Vec::new();
        for (a, pair) in buildings.windows(2).enumerate() {
            for (fa, fb, elevation) in common_levels(&pair[0], &pair[1]) {
                let (ma, mb) = (pair[0].masses[fa - 1], pair[1].masses[fb - 1]);
                levels.push(Level {
                    left: a,
                    floor_left: fa,
                    floor_right: fb,
                    elevation,
                    contact: Contact::new(law, stiffness, damping_ratio, ma * mb / (ma + mb)),
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

/// The floors of `left` and `right` at the same elevation (within [`LEVEL_TOLERANCE_M`]),
/// lowest first: `(floor of left, floor of right, elevation)`, floors counted from 1.
pub fn common_levels(left: &ShearBuilding, right: &ShearBuilding) -> Vec<(usize, usize, f64)> {
    let (za, zb) = (left.elevations(), right.elevations());
    za.iter()
        .enumerate()
        .filter_map(|(fa, &ea)| {
            zb.iter()
                .position(|&eb| (ea - eb).abs() <= LEVEL_TOLERANCE_M)
                .map(|fb| (fa + 1, fb + 1, ea))
        })
        .collect()
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
}

impl InelasticOutput {
    /// Gather a building's storeys (bottom to top): the largest `|residual|` and ductility with
    /// their storeys, the hysteretic energies summed, the storeys that yielded.
    pub fn gather(storeys: &[StoreyOutput]) -> InelasticOutput {
        let mut out = InelasticOutput::default();
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
    /// Where the run collapsed (status `collapsed`).
    pub collapse: Option<Collapse>,
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
        };
        let building = |u: f64, a: f64, h: f64| BuildingOutput {
            peak_roof: u,
            peak_drift_ratio: u / h,
            drift_storey: (u > 0.0) as u32,
            peak_accel: a,
            accel_floor: (a > 0.0) as u32,
            inelastic: None,
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
        settled: bool,
    ) {
        for (b, span) in self.buildings.iter_mut().zip(spans) {
            b.inelastic = span.clone().map(|r| {
                let mut ie = InelasticOutput::gather(&self.storeys[r]);
                if !settled {
                    ie.residual_drift_ratio = f64::NAN;
                }
                ie
            });
        }
        if !settled {
            for st in self.storeys.iter_mut() {
                st.residual_drift_ratio = f64::NAN;
            }
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
            .map(|l| (l.left, l.floor_left, l.floor_right))
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
    fn floors_at_different_heights_never_touch() {
        let row = Row::new(
            vec![building(3, 3.0, 2e5), building(3, 3.2, 2e5)],
            vec![0.02],
            LawKind::Linear,
            1e9,
            0.0,
        );
        assert!(row.levels.is_empty());
    }
}
