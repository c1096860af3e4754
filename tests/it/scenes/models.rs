//! Scenes built in Rust, for the tests that call the library's solvers directly: records,
//! forcings and shear buildings, and the single-storey pairs that a row of two must reproduce.

use crate::support::pair;
use pounding::physics::contact::LawKind;
use pounding::physics::model::Forcing;
use pounding::physics::row::Row;
use pounding::physics::shear::{Damping, ShearBuilding};
use pounding::physics::solver::row::RowModel;
use pounding::record::{synthetic, SyntheticSpec};

/// A synthetic ground acceleration at 0.01 s steps.
pub fn record(seed: u64, duration: f64, pga_g: f64) -> Vec<f64> {
    let r = synthetic(&SyntheticSpec {
        seed,
        duration,
        dt: 0.01,
        pga_g,
        ..SyntheticSpec::default()
    })
    .unwrap();
    r.accel.clone()
}

/// `accel` as a run's forcing: 0.01 s steps, unscaled, no tail.
pub fn forcing(accel: &[f64]) -> Forcing<'_> {
    Forcing {
        accel,
        dt: 0.01,
        t0: 0.0,
        scale: 1.0,
        tail: 0.0,
    }
}

/// A shear building of `n` storeys, 3 m and 300 t each, uniform stiffness tuned to `period`.
pub fn building(n: usize, period: f64, damping: Damping) -> ShearBuilding {
    ShearBuilding::from_period(vec![3e5; n], &vec![1.0; n], vec![3.0; n], period, damping)
}

/// The single-storey scenes of [`crate::multistorey`]'s `single_storey_rows_are_the_pair`: the pair, and the same pair
/// as a row of two single-storey shear buildings.
pub fn single_storey_scenes() -> Vec<(pounding::physics::model::Pair, RowModel)> {
    [
        (LawKind::NonlinearViscoelastic, 2.75e9, 0.35),
        (LawKind::KelvinVoigt, 2e9, 0.2),
        (LawKind::HuntCrossley, 2.75e9, 0.5),
        (LawKind::Linear, 1e9, 0.0),
    ]
    .into_iter()
    .map(|(law, stiffness, damping)| {
        let p = pair(
            law,
            stiffness,
            damping,
            (2e5, 0.45, 0.05),
            (3e5, 0.9, 0.03),
            0.01,
        );
        let row = Row::new(
            vec![
                ShearBuilding::single(&p.b1, 0.05, 3.0),
                ShearBuilding::single(&p.b2, 0.03, 3.0),
            ],
            vec![p.gap],
            law,
            stiffness,
            damping,
        );
        (p, RowModel::new(&row))
    })
    .collect()
}
