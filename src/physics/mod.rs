//! The physics of one run, in f64: a pair of one-storey buildings as linear oscillators
//! ([`model`]) and rows of shear buildings of one or more storeys, elastic or with yielding
//! storeys ([`row`], [`shear`]), the contact laws of an impact ([`contact`]) and the damping
//! that gives a coefficient of restitution ([`restitution`]), exact free-vibration stepping
//! ([`propagator`]), the code rules' separation gaps ([`separation`]), and the solvers that
//! integrate one run through a ground motion ([`solver`]: the fast scheme and the reference,
//! for pairs and rows).
//!
//! The bottom layer: imports nothing else of the crate (no records, plans, engines, output or
//! studies), so every layer above can use it and its tests need no files.

pub mod contact;
pub mod imk;
pub mod model;
pub mod propagator;
pub mod restitution;
pub mod row;
pub mod separation;
pub mod shear;
pub mod solver;
