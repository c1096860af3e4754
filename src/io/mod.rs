//! Everything that touches a file: where a command may write ([`target`]), files that appear
//! whole ([`atomic`]), a sweep's rows as CSV ([`csv`]) or Parquet ([`parquet`]), an `--aggregate`
//! summary ([`summary`]), the sweep's output protocol ([`sweep_output`]: `.partial`, journal,
//! resume, rename), what an output holds and was computed from ([`journal`], [`provenance`]),
//! combining shards ([`merge`]) and reading results back for the studies ([`table`]).
//!
//! May import the physics, the plan and the engine's row types; never studies or the command
//! line.

pub mod atomic;
pub mod csv;
pub mod journal;
pub mod merge;
pub mod parquet;
pub mod paths;
pub mod provenance;
pub mod summary;
pub mod sweep_output;
pub mod table;
pub mod target;
