//! Hostile pass, round 3 (issue 47): see the classes named in `round3.rs`.
