//! A validated sweep: every axis checked, every run numbered. The engine consumes only this:
//! one [`Plan`], of a pair ([`PairPlan`]) or of a row of shear buildings ([`row::RowPlan`]).
//!
//! - [`config`]: the entry points: a config file read ([`crate::config`]) and decoded into a
//!   [`Plan`] ([`decode`]: every value checked, every axis built, records read, samples drawn);
//! - [`scene`]: the [`Plan`] itself, a pair's or a row's; [`pair`]: a pair's; [`row`]: a
//!   row's buildings and gaps;
//! - [`contact`]: the axes every scene shares (contact, record, intensity, scheme), numbered;
//! - [`axes`]: what each value must be, and the errors that say why one is not;
//! - [`sample`]: Latin hypercube and Monte Carlo samples of uncertain parameters;
//! - [`columns`]: the output schema, in one place: every column's name, meaning and cell;
//! - [`settings`]: the scheme as run and the columns written (a sweep's settings stage);
//! - [`shard`]: cost-balanced run ranges for job arrays;
//! - [`limits`]: the bound on every size a user types, with its reason.
//!
//! A new storey key is one field of [`crate::config::row::RawShearBuilding`], one line of
//! [`decode::row`] and one column entry in [`columns::row`] (and its meaning in
//! [`columns::meaning`]).
//!
//! This file only declares and re-exports: each file imports what it uses from the file that
//! holds it, so no import runs in a circle between the files of this folder.
//!
//! May import the physics, the records and the configs; never the engine, io or studies.
//!
//! Every plan is a [`ContactPlan`] (the shared axes, grouped by contact law: within a law's block
//! only the axes that law uses vary, so no run is a duplicate of another) with the scene's own
//! axes below each contact run: run `i` is contact run `i / per_scene` with scene values
//! `i % per_scene`. A pair's axis order, outermost first: law, formula, e, stiffness, record,
//! intensity, sample, m1, T1, xi1, m2, T2, xi2, gap; a row's the same with each building's
//! axes and each gap in place of the pair's ([`row`]). A sample (of uncertain parameters, see
//! [`Samples`]) sets the parameters it holds; their grid axes then hold one placeholder value.
//! Run `i` is decoded from its index (mixed radix), so the plan is never expanded in memory and
//! run numbers do not depend on threads or chunking.

pub mod axes;
pub mod columns;
pub mod config;
pub mod contact;
pub mod decode;
pub mod deterioration;
pub mod intensity;
pub mod limits;
pub mod pair;
pub mod row;
pub mod row_sampled;
pub mod sample;
pub mod scene;
pub mod settings;
pub mod shard;

pub use axes::{Motions, PlanError};
pub use columns::meaning;
pub use contact::{ContactPlan, ContactRun, ContactSpec};
pub use intensity::Intensity;
pub use pair::{
    check_run_count, count_runs, AxisCounts, BuildingAxes, PairPlan, PlanSpec, RunSpec,
    SampledAxis, Samples,
};
pub use scene::Plan;
