//! What users do with sweeps and single collisions: speed against error ([`accuracy`]),
//! throughput ([`bench`](mod@bench)), restitution fidelity and hysteresis loops ([`fidelity`]), an IMK storey's loops under a
//! cyclic protocol ([`hysteresis`](mod@hysteresis)), the
//! formulas' zeta(e) ([`formulas`]), fragility curves ([`fragility`]) with
//! named damage states ([`damage_states`]), incremental dynamic analysis summaries ([`ida`]), what a study of a table gives ([`report`]), sensitivity plots
//! ([`sensitivity`]), one run's time history ([`trace`]), the seed paper's checks ([`paper`]), and drawing
//! them ([`plot`]).
//!
//! The top layer of the library: may import every layer below; nothing below imports it.

pub mod accuracy;
pub mod bench;
pub mod damage_states;
pub mod demands;
pub mod fidelity;
pub mod formulas;
pub mod fragility;
pub mod gap;
pub mod hysteresis;
pub mod ida;
pub mod paper;
pub mod plot;
pub mod report;
pub mod sensitivity;
pub mod stats;
pub mod trace;
