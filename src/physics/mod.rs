//! The physics of one run, in f64: two buildings as linear oscillators ([`model`]), the contact
//! laws of an impact ([`contact`]) and the damping that gives a coefficient of restitution
//! ([`restitution`]), exact free-vibration stepping ([`propagator`]), and the solvers that
//! integrate one run through a ground motion ([`solver`]: the fast scheme and the reference).
//!
//! The bottom layer: imports nothing else of the crate (no records, plans, engines, output or
//! studies), so every layer above can use it and its tests need no files.

pub mod contact;
pub mod model;
pub mod propagator;
pub mod restitution;
pub mod row;
pub mod separation;
pub mod shear;
pub mod solver;
