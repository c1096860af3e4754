//! The output schema, in one place: every column a sweep writes (its name, in file order), what
//! each holds and its unit ([`meaning`]), and the cells of a run's row. A pair's columns are
//! fixed ([`pair`]); a row's follow its buildings, storeys and contact levels ([`row`]). A new
//! output is one entry here: its name in the header, its cell, its meaning.

pub mod meaning;
pub mod pair;
pub mod row;

pub(crate) use pair::num;
pub use pair::{
    at, contact_and_motion, header, pair_header, record_meta_cells, record_meta_columns, row,
    select, select_in, CONTACT_AND_MOTION, HEADER, RECORD_IMS, RECORD_META, SUMMARISED,
};
