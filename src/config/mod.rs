//! TOML sweep configs as written: plain data (serde structs), read from a file and checked for
//! their form alone (unknown keys, a number where a list is due), with every error in the
//! config's words: the file, the key, what was expected. Nothing here knows a plan: the plan
//! layer ([`crate::plan::config`]) decodes a config into runs.
//!
//! - [`read`]: a config's text, its kind (pair or row, told once) and where its records are;
//! - [`sections`]: `[run]`, `[contact]`, `[[record]]`, `[intensity]`, `[sample]`;
//! - [`pair`] and [`row`]: each scene's buildings;
//! - [`axis`]: a swept key as written (a number, a list or a range table);
//! - [`forms`]: keys of several forms, refused naming every form;
//! - [`error`]: [`ConfigError`] and TOML's messages in the config's words.
//!
//! May import the physics and the records; never the plans or anything above them.

pub mod axis;
pub mod error;
pub mod forms;
pub mod pair;
pub mod read;
pub mod row;
pub mod sections;

pub use axis::{name_given_twice, number_given_twice, parse_colon_range, Axis, RangeSpec};
pub use error::{in_toml_words, ConfigError};
pub use read::{input_files, read_text, records_dir, records_dir_for, Config, DEFAULT_RECORDS_DIR};
