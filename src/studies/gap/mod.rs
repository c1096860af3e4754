//! The separation-gap study (`pound gap`): for every run of a sweep without its contact and gap
//! axes (buildings x records x intensities x samples), the gap each adjacent pair needs, exactly
//! from the time histories ([`crate::physics::solver::separation`]), against what the code rules
//! say from the same peak displacements ([`crate::physics::separation`]); a summary per rule;
//! and the probability of pounding against the gap, with a lognormal fitted by maximum likelihood
//! to the runs' required gaps themselves (each is known exactly; the gaps it is counted at are
//! for display and do not move the fit).
//!
//! Elastic responses are linear in the record's scale, so one response per record and building
//! values serves every intensity. Where storeys yield they are not: every run is its own
//! response, the row scheme's run of the uncoupled buildings under the config's collapse limit
//! ([`uncoupled`]). There a building may collapse: each pair's gaps are then taken up to the
//! earlier collapse of its two buildings, a lower bound on what the pair needs (censored,
//! [`PairGap::censored`]); a run that ends early for another reason has no gaps and is left
//! out of every statistic ([`RunEnd::Failed`]).

mod curves;
mod fit;
mod scenes;
mod study;
mod table;

pub use curves::PoundingCurve;
pub use fit::{GapFit, NoGapFit};
pub use scenes::{uncoupled, Outcome, RunEnd};
pub use study::{covering_rule, GapPlanError, GapRun, GapStudy, PairGap, STOPPED};
pub use table::RuleSummary;
