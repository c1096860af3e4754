//! A config's raw sections ([`crate::config`]) decoded into a plan: every value checked, every
//! axis built, the records read, the samples drawn. The entry points are
//! [`crate::plan::config`]'s.
//!
//! - [`contact`]: the sections every scene shares (`[run]`, `[contact]`, records, intensity);
//! - [`intensity`]: `[intensity]`'s axis;
//! - [`records`]: each `[[record]]` read;
//! - [`sampled`]: `[sample]`'s draws, and a key on the grid or sampled;
//! - [`pair`]: a pair's buildings and gap;
//! - [`row`]: a row's buildings and gaps; [`yielding`], their yielding storeys; [`idle`], the
//!   axes no run of the row can use.

pub mod contact;
pub mod idle;
pub mod intensity;
pub mod pair;
pub mod records;
pub mod row;
pub mod sampled;
pub mod yielding;
