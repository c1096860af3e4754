//! Floors that strike columns (issue 50; physics.md section 11): buildings whose floors are at
//! different heights pound floor against column, the column's point moving as
//! `u_(j-1) + (u_j - u_(j-1)) s(xi)`.
//!
//! Checks: the fast scheme against the row reference, run by run, from 8 to 512 substeps per
//! contact (on elastic and yielding rows, a tall Rayleigh building whose substeps run in floor
//! coordinates, a column of a first storey, two points about to become one level, and a row
//! where nothing touches); the energy balance closes with floor/column contact; and the
//! response moves continuously as one building's storey height passes through the neighbour's
//! floor height, where two floor/column points become one floor/floor level.

use crate::convergence::{failures, yielding, SETTINGS};
use crate::scenes::models::{building, forcing, record};
use crate::support::rel;
use pounding::physics::contact::LawKind;
use pounding::physics::model::Status;
use pounding::physics::row::{LevelRule, Row, RowOutput};
use pounding::physics::shear::{Damping, ShearBuilding};
use pounding::physics::solver::row::{
    simulate_row, simulate_row_observed, RowModel, RowSample, RowScheme,
};
use pounding::physics::solver::Mode;
use pounding::physics::solver::{FastOptions, ReferenceOptions};

/// `n` storeys of `h` m, floor masses `m` kg.
fn frame(n: usize, h: f64, m: f64, period: f64, damping: Damping) -> ShearBuilding {
    ShearBuilding::from_period(vec![m; n], &vec![1.0; n], vec![h; n], period, damping)
}

/// 4 storeys of 3 m (floors at 3, 6, 9, 12 m) beside a building whose first storey is 13 m
/// tall: four floors strike one storey's columns, often together.
fn four_on_one() -> Vec<ShearBuilding> {
    vec![
        frame(4, 3.0, 2e5, 0.5, Damping::Modal(0.05)),
        ShearBuilding::from_period(
            vec![3e5; 2],
            &[1.0; 2],
            vec![13.0, 3.0],
            0.7,
            Damping::Modal(0.05),
        ),
    ]
}

/// 3 storeys of 3.5 m (floors at 3.5, 7, 10.5 m) and 4 of 3 m at period `t1`: no floor of one
/// at a floor of the other.
fn low() -> ShearBuilding {
    frame(3, 3.5, 2e5, 0.45, Damping::Modal(0.05))
}

fn tall(t1: f64) -> ShearBuilding {
    frame(4, 3.0, 3e5, t1, Damping::Modal(0.05))
}

fn row(buildings: Vec<ShearBuilding>, gap: f64, law: LawKind) -> Row {
    let stiffness = if law.is_hertzian() { 2.75e9 } else { 1e9 };
    Row::new(buildings, vec![gap], law, stiffness, 0.5)
}

fn reference() -> RowScheme {
    RowScheme::Reference(ReferenceOptions::with_tol(1e-10))
}

fn fast(s: f64) -> RowScheme {
    RowScheme::Fast(FastOptions {
        substeps_per_contact: s,
        ..FastOptions::default()
    })
}

/// The scenes: name, row, record, and whether it pounds.
fn scenes() -> Vec<(&'static str, Row, Vec<f64>, bool)> {
    vec![
        (
            "3 storeys of 3.5 m beside 4 of 3 m (Kelvin-Voigt)",
            row(
                vec![
                    low(),
                    tall(0.55),
                ],
                0.01,
                LawKind::KelvinVoigtNoTension,
            ),
            record(7, 8.0, 0.5),
            true,
        ),
        (
            "the same, yielding storeys",
            row(
                vec![
                    yielding(low(), 0.004, 0.03),
                    yielding(tall(0.55), 0.005, 0.05),
                ],
                0.01,
                LawKind::KelvinVoigtNoTension,
            ),
            record(7, 8.0, 0.6),
            true,
        ),
        (
            "6 storeys of 3.2 m (Rayleigh: floor coordinates) beside 3 of 3 m (Lankarani-Nikravesh)",
            row(
                vec![
                    frame(6, 3.2, 3e5, 0.8, Damping::Rayleigh(0.05)),
                    frame(3, 3.0, 2.5e5, 0.3, Damping::Rayleigh(0.05)),
                ],
                0.005,
                LawKind::LankaraniNikravesh,
            ),
            record(3, 8.0, 0.5),
            true,
        ),
        (
            "3 storeys of 3.5 m pressed against 4 of 3 m (gap 0, nonlinear viscoelastic: the force's rate unbounded near zero penetration)",
            row(
                vec![
                    low(),
                    yielding(tall(0.6), 0.006, 0.03),
                ],
                0.0,
                LawKind::NonlinearViscoelastic,
            ),
            record(9, 8.0, 0.6),
            true,
        ),
        (
            "a one-storey building of 2 m against a first storey of 3 m",
            row(
                vec![
                    frame(1, 2.0, 1e5, 0.2, Damping::Modal(0.05)),
                    building(3, 0.5, Damping::Modal(0.05)),
                ],
                0.005,
                LawKind::NonlinearViscoelastic,
            ),
            record(11, 8.0, 0.5),
            true,
        ),
        (
            "4 storeys of 3 m beside a first storey of 13 m (four floors on one storey's columns)",
            row(four_on_one(), 0.005, LawKind::KelvinVoigtNoTension),
            record(13, 8.0, 0.5),
            true,
        ),
        (
            "floors 1.5 cm apart (two points about to become one level)",
            row(
                vec![
                    frame(3, 3.0, 2e5, 0.45, Damping::Modal(0.05)),
                    frame(3, 3.015, 3e5, 0.35, Damping::Modal(0.05)),
                ],
                0.01,
                LawKind::KelvinVoigtNoTension,
            ),
            record(5, 8.0, 0.5),
            true,
        ),
        (
            "3 storeys of 3.5 m beside 4 of 3 m, 1 m apart (never touching)",
            row(
                vec![
                    low(),
                    tall(0.55),
                ],
                1.0,
                LawKind::KelvinVoigtNoTension,
            ),
            record(7, 8.0, 0.5),
            false,
        ),
    ]
}

/// A run's worst relative error against the reference: peak force, each struck column's
/// peak shear, each building's peak roof and drift ratio, ductility where storeys yield.
fn run_error(o: &RowOutput, t: &RowOutput) -> f64 {
    let mut e: f64 = 0.0;
    if t.impacts > 0 {
        e = e.max(rel(o.peak_force, t.peak_force));
    }
    for (lo, lt) in o.levels.iter().zip(&t.levels) {
        if lt.column_shear > 0.0 {
            e = e.max(rel(lo.column_shear, lt.column_shear));
        }
    }
    for (bo, bt) in o.buildings.iter().zip(&t.buildings) {
        e = e
            .max(rel(bo.peak_roof, bt.peak_roof))
            .max(rel(bo.peak_drift_ratio, bt.peak_drift_ratio));
        if let (Some(yo), Some(yt)) = (bo.inelastic, bt.inelastic) {
            e = e.max(rel(yo.peak_ductility, yt.peak_ductility));
        }
    }
    e
}

/// Every run's error against the reference falls from 8 to 512 substeps per contact, is
/// within 1e-5 at 128 and reaches 1e-6 at 512 (`convergence::failures`), with the
/// reference's impacts from the default on; and every scene has floor/column levels.
#[test]
fn every_floor_column_run_converges() {
    let mut bad = Vec::new();
    for (name, row, accel, pounds) in scenes() {
        assert!(
            row.levels.iter().any(|l| l.floor_column()),
            "{name}: a floor strikes a column"
        );
        let m = RowModel::new(&row);
        let f = forcing(&accel);
        let t = simulate_row(&m, &f, m.at_rest(), &reference());
        assert_eq!(t.status, Status::Ok, "{name}: reference");
        assert_eq!(
            t.impacts > 0,
            pounds,
            "{name}: the reference pounds as meant"
        );
        let mut errs = Vec::new();
        for s in SETTINGS {
            let o = simulate_row(&m, &f, m.at_rest(), &fast(s));
            assert_eq!(o.status, Status::Ok, "{name} at {s}");
            if s >= 16.0 && o.impacts != t.impacts {
                bad.push(format!(
                    "{name} at {s}: {} impacts, the reference {}",
                    o.impacts, t.impacts
                ));
            }
            errs.push((s, run_error(&o, &t)));
        }
        bad.extend(failures(&format!("{name} ({} impacts)", t.impacts), &errs));
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The energy balance closes with floors striking columns: the contact's work is
/// `int F delta' dt` with `delta` read at the column's point, and its force reaches the floors by
/// the same shares, so no energy is made or lost between them.
#[test]
fn the_energy_balance_closes_with_floor_column_contact() {
    for (name, row, accel, pounds) in scenes() {
        if !pounds || row.buildings.iter().any(|b| b.yielding.is_some()) {
            continue;
        }
        let m = RowModel::new(&row);
        let f = forcing(&accel);
        let scheme = RowScheme::Fast(FastOptions {
            substeps_per_contact: 64.0,
            energy: true,
            ..FastOptions::default()
        });
        let o = simulate_row(&m, &f, m.at_rest(), &scheme);
        let e = o.energy.expect("the energy balance");
        eprintln!(
            "{name}: residual {:.1e}, contact work {:.3e} J",
            e.residual, o.dissipated_energy
        );
        assert!(o.impacts > 0, "{name}");
        assert!(e.residual.abs() < 1e-6, "{name}: residual {}", e.residual);
    }
}

/// Four floors striking one 13 m storey's columns: each level's column shear is the storey's
/// spring force with the shares of every force on those columns at that instant, on the worst
/// segment between the points (above them all `V - sum s_i F_i`, below point k `F_i` more for
/// each point at or above it), as the reference's every accepted step gives it (`s` from the
/// floors' heights); and it is larger than any one level's force alone gives (the scene tests
/// the sum).
#[test]
fn a_storeys_column_shear_sums_every_floor_striking_it() {
    let r = row(four_on_one(), 0.005, LawKind::KelvinVoigtNoTension);
    let k = r.buildings[1].stiffness[0];
    let m = RowModel::new(&r);
    let accel = record(13, 8.0, 0.5);
    let f = forcing(&accel);
    let s_of = |z: f64| {
        let xi = z / 13.0;
        3.0 * xi * xi - 2.0 * xi * xi * xi
    };
    let points: Vec<(usize, f64)> = (r.levels.iter().enumerate())
        .filter(|(_, l)| l.floor_column())
        .map(|(i, l)| (i, s_of(l.elevation)))
        .collect();
    assert_eq!(points.len(), 4, "{:?}", r.levels);
    let (mut together, mut alone) = (vec![0.0f64; r.levels.len()], vec![0.0f64; r.levels.len()]);
    let mut observer = |x: &RowSample| {
        let v = k * x.floors[1][0];
        // The left building's floors push the struck building to the right.
        let on = |i: usize| x.modes[i] != Mode::Free;
        let load = |below: &dyn Fn(f64) -> bool| -> f64 {
            (points.iter().filter(|&&(i, _)| on(i)))
                .map(|&(i, s)| x.forces[i] * if below(s) { 1.0 - s } else { -s })
                .sum()
        };
        let mut worst = (v + load(&|_| false)).abs();
        for &(_, at) in &points {
            worst = worst.max((v + load(&|s| s >= at)).abs());
        }
        for &(i, s) in &points {
            if on(i) {
                together[i] = together[i].max(worst);
                let own = (v - s * x.forces[i])
                    .abs()
                    .max((v + (1.0 - s) * x.forces[i]).abs());
                alone[i] = alone[i].max(own);
            }
        }
    };
    let o = simulate_row_observed(&m, &f, m.at_rest(), &reference(), &mut observer);
    assert_eq!(o.status, Status::Ok);
    for &(i, _) in &points {
        let got = o.levels[i].column_shear;
        eprintln!(
            "level {i}: {got:.6e} N; sampled {:.6e} ({:.1e} above), alone {:.6e}",
            together[i],
            got / together[i] - 1.0,
            alone[i]
        );
        assert!(together[i] > 0.0, "level {i} strikes");
        assert!(
            got >= together[i] * (1.0 - 1e-9) && got <= together[i] * (1.0 + 1e-6),
            "level {i}: {got} against {} sampled",
            together[i]
        );
    }
    assert!(
        points.iter().any(|&(i, _)| together[i] > 1.05 * alone[i]),
        "the floors strike together: {together:?} against {alone:?}"
    );
}

/// As the right building's storey height passes through the left's floor height (3 m), the
/// response moves continuously: where two floor/column points become one floor/floor level
/// (0.01 m apart) the peaks change no more than between neighbouring heights on either side;
/// with floor/column contact turned off they jump (the buildings stop touching).
#[test]
fn the_response_is_continuous_where_two_points_become_one_level() {
    let accel = record(5, 6.0, 0.45);
    let f = forcing(&accel);
    let run = |h: f64, rule: LevelRule| -> RowOutput {
        let r = Row::with_levels(
            vec![
                frame(3, 3.0, 2e5, 0.45, Damping::Modal(0.05)),
                frame(3, h, 3e5, 0.35, Damping::Modal(0.05)),
            ],
            vec![0.01],
            LawKind::KelvinVoigtNoTension,
            1e9,
            0.5,
            rule,
        );
        let m = RowModel::new(&r);
        simulate_row(&m, &f, m.at_rest(), &fast(64.0))
    };
    let peaks = |o: &RowOutput| -> Vec<f64> {
        let mut p: Vec<f64> = (o.buildings.iter())
            .flat_map(|b| [b.peak_roof, b.peak_drift_ratio])
            .collect();
        p.push(o.dissipated_energy);
        p
    };
    let change = |a: &RowOutput, b: &RowOutput| -> f64 {
        (peaks(a).iter().zip(peaks(b)))
            .map(|(x, y)| rel(*x, y))
            .fold(0.0, f64::max)
    };
    let on = LevelRule::default();
    let eps = 2e-5;
    let tol = on.same_level_m;
    let heights = [
        3.0 + tol - 2.0 * eps,
        3.0 + tol - eps,
        3.0 + tol + eps,
        3.0 + tol + 2.0 * eps,
    ];
    let outs: Vec<RowOutput> = heights.iter().map(|&h| run(h, on)).collect();
    assert!(outs.iter().all(|o| o.impacts > 0));
    let (below, across, above) = (
        change(&outs[0], &outs[1]),
        change(&outs[1], &outs[2]),
        change(&outs[2], &outs[3]),
    );
    eprintln!("change below {below:.1e}, across {across:.1e}, above {above:.1e}");
    assert!(
        across <= 10.0 * below.max(above).max(1e-6),
        "a jump where two points become one level: {across:.2e} (beside it {below:.2e}, {above:.2e})"
    );
    // Without floor/column contact the floors stop touching past the tolerance: a jump.
    let off = LevelRule {
        floor_column: false,
        ..on
    };
    let (a, b) = (run(heights[1], off), run(heights[2], off));
    assert!(a.impacts > 0 && b.impacts == 0);
    assert!(change(&a, &b) > 100.0 * across.max(1e-6));
}

/// `[levels]` as the config gives it: floor/column levels by default, none with
/// `floor_column = false`, a wider `same_level_m` merging floors 3.5 m and 3.4 m high into one
/// level, and out-of-range values and unknown keys refused with the key named.
#[test]
fn the_levels_section_sets_the_contact_levels() {
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("levels.toml");
    // Building 2's floors at 3, 6, 9.5, 13 m; building 3's at 3, 6, 9 m.
    let base = crate::scenes::ROW_CONFIG;
    let load =
        |extra: &str| pounding::plan::config::load_row_text(&format!("{base}\n{extra}"), &cfg);
    let names = |extra: &str| load(extra).unwrap().level_names();
    let all = names("");
    assert!(all.contains(&"level_b2c3_b3f3".to_string()), "{all:?}");
    let off = names("[levels]\nfloor_column = false\n");
    assert!(off.iter().all(|n| !n.contains('c')), "{off:?}");
    assert_eq!(off.len() + 1, all.len());
    // Within 0.5 m the 9 m roof and the 9.5 m floor are one floor/floor level.
    let wide = names("[levels]\nsame_level_m = 0.5\n");
    assert!(wide.contains(&"level_b2f3_b3f3".to_string()), "{wide:?}");
    for (extra, needle) in [
        ("[levels]\nsame_level_m = -0.1\n", "levels.same_level_m"),
        ("[levels]\nsame_level_m = 0\n", "levels.same_level_m"),
        ("[levels]\nsame_level_m = 0.6\n", "levels.same_level_m"),
        ("[levels]\nfloor_colum = false\n", "floor_colum"),
    ] {
        let e = load(extra).unwrap_err().to_string();
        assert!(e.contains(needle), "{extra}: {e}");
    }
}

/// `[levels]` is part of a plan's fingerprint, so `--resume` and `pound merge` refuse to join
/// outputs made with other contact levels; the default rule hashes as a config without
/// `[levels]` (whose sweeps before it keep their fingerprint).
#[test]
fn the_levels_section_is_in_the_fingerprint() {
    use pounding::io::provenance::Fingerprint;
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("levels.toml");
    let base = crate::scenes::ROW_CONFIG;
    let print = |extra: &str| {
        let plan =
            pounding::plan::config::load_row_text(&format!("{base}\n{extra}"), &cfg).unwrap();
        Fingerprint::of_row(&plan).plan
    };
    let plain = print("");
    assert_eq!(
        plain,
        print("[levels]\nsame_level_m = 0.01\nfloor_column = true\n")
    );
    assert_ne!(plain, print("[levels]\nsame_level_m = 0.015\n"));
    assert_ne!(plain, print("[levels]\nfloor_column = false\n"));
}

/// Floors at equal heights: the same levels and the same output to the bit with floor/column
/// contact on or off (the CSVs of the shipped rows with equal floors were compared byte for
/// byte before and after the change: docs/floor-column.md).
#[test]
fn equal_floors_are_unchanged_by_floor_column_contact() {
    let accel = record(7, 6.0, 0.5);
    let f = forcing(&accel);
    let off = LevelRule {
        floor_column: false,
        ..LevelRule::default()
    };
    for (buildings, gaps) in [
        (
            vec![tall(0.55), building(6, 0.8, Damping::Rayleigh(0.05))],
            vec![0.005],
        ),
        (
            vec![
                building(2, 0.3, Damping::Modal(0.05)),
                yielding(building(5, 0.7, Damping::Rayleigh(0.05)), 0.005, 0.03),
                building(3, 0.4, Damping::Modal(0.05)),
            ],
            vec![0.004, 0.0],
        ),
    ] {
        let at = |rule: LevelRule| {
            Row::with_levels(
                buildings.clone(),
                gaps.clone(),
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.5,
                rule,
            )
        };
        let (with, without) = (at(LevelRule::default()), at(off));
        assert_eq!(with.levels, without.levels);
        assert!(with.levels.iter().all(|l| !l.floor_column()));
        for scheme in [fast(16.0), reference()] {
            let run = |r: &Row| {
                let m = RowModel::new(r);
                simulate_row(&m, &f, m.at_rest(), &scheme)
            };
            let (a, b) = (run(&with), run(&without));
            assert!(a.impacts > 0);
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }
}

/// docs/floor-column.md's worked example states what its first command gives: each row of its
/// table, rebuilt from `pound sweep configs/floor-column.toml --aggregate ...` now.
#[test]
fn the_worked_example_states_what_its_command_gives() {
    use crate::support::{ok, pound, table};
    let dir = crate::support::tempdir();
    let out = dir.path().join("floor-column.csv");
    let level = "level_b1f3_b2c4";
    let exceed = [
        "impacts=0".to_string(),
        format!("{level}_impacts=0"),
        format!("{level}_column_shear_ratio=1"),
    ];
    let mut args = vec![
        "sweep",
        "configs/floor-column.toml",
        "-o",
        out.to_str().unwrap(),
        "--aggregate",
        "target_sa_g,gap_1_2_m",
    ];
    for e in &exceed {
        args.extend(["--exceed", e]);
    }
    ok(&pound(&args));
    let doc = std::fs::read_to_string("docs/floor-column.md").unwrap();
    let rows = table(&out);
    assert_eq!(rows.len(), 16);
    let mut stated = 0;
    for r in &rows {
        let num = |c: &str| r[c].parse::<f64>().unwrap();
        let sa = format!("{} g", num("target_sa_g"));
        let gap = match num("gap_1_2_m") {
            0.0 => "0".to_string(),
            g => format!("{} mm", (g * 1e3).round()),
        };
        let force = match num(&format!("{level}_peak_force_n_max")) {
            0.0 => "0".to_string(),
            f => format!("{:.2} MN", f / 1e6),
        };
        let ratio = |c: &str| match num(&format!("{level}_column_shear_ratio_{c}")) {
            0.0 => "0".to_string(),
            x => format!("{x:.2}"),
        };
        let line = format!(
            "| {sa} | {gap} | {} / {} | {} | {} | {force} | {} | {} |",
            r["exceed_impacts>0"],
            r["runs"],
            r[&format!("exceed_{level}_impacts>0")],
            r[&format!("exceed_{level}_column_shear_ratio>1")],
            ratio("max"),
            ratio("p50"),
        );
        let prefix = format!("| {sa} | {gap} |");
        if doc.contains(&prefix) {
            assert!(
                doc.contains(&line),
                "docs/floor-column.md does not say `{line}`"
            );
            stated += 1;
        }
    }
    assert_eq!(stated, 10, "the table's rows");
}
