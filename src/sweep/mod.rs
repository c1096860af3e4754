//! One sweep, as `pound sweep` and the Python package's `pounding.sweep` both run it: the flags
//! checked against each other ([`options`]), the config settled into a plan, an engine and the
//! columns written ([`prepare`]), then the runs into a sink ([`run`]): a file output (journaled,
//! resumable) or a table in memory. Every check and message is here, in the command line's
//! words, so the two front ends refuse the same mistakes alike; they only turn their own
//! arguments into [`options::Options`] and show what comes back their own way.

pub mod options;
pub mod prepare;
pub mod run;
