//! P-Delta and collapse (physics.md section 10, issue 48) against OpenSees:
//! `benches/opensees_pdelta.py` writes `tests/data/opensees_pdelta.toml`, this compares `pound
//! sweep` with it, through configs with the keys a user writes (`p_delta = true`,
//! `gravity_mass_ratio`, `[run] collapse_drift_ratio`).

use crate::support::{floats, ok, pound, records_dir, table, tempdir};
use pounding::record::{read_record, ReadOptions};

/// The scene's config, as a user would write it: each building's storeys from the data file's
/// stiffnesses (as a profile scaled to the period of `(K0, M)`, which the file gives), its P-Delta
/// keys where the file gives a gravity mass ratio, linear contact, the record's first `npts`
/// samples (a window on its own clock) scaled by the file's factor, no tail (the residual drift
/// is the engine's settled one).
fn config(data: &toml::Table, scene: &toml::Value, window: [f64; 2]) -> String {
    let list = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("[{}]", items.join(", "))
    };
    let mut c = format!(
        "[run]\ntail_s = 0.0\ncollapse_drift_ratio = {:?}\n",
        data["collapse_drift_ratio"].as_float().unwrap()
    );
    let gaps = floats(&scene["gaps_m"]);
    for (k, b) in scene["building"].as_array().unwrap().iter().enumerate() {
        let masses = floats(&b["masses_kg"]);
        c += &format!(
            "\n[[building]]\nstoreys = {}\nstorey_height_m = {}\nfloor_masses_kg = {}\n\
             stiffness_profile = {}\nperiod_s = {:?}\ndamping_ratio = {:?}\n",
            masses.len(),
            list(&floats(&b["heights_m"])),
            list(&masses),
            list(&floats(&b["stiffness_n_per_m"])),
            b["period_s"].as_float().unwrap(),
            data["damping_ratio"].as_float().unwrap(),
        );
        if let Some(f) = b.get("yield_force_n") {
            c += &format!(
                "yield_force_n = {}\npost_yield_ratio = {}\n",
                list(&floats(f)),
                list(&floats(&b["post_yield_ratio"]))
            );
        }
        if let Some(r) = b.get("gravity_mass_ratio") {
            c += &format!(
                "p_delta = true\ngravity_mass_ratio = {:?}\n",
                r.as_float().unwrap()
            );
        }
        if let Some(g) = gaps.get(k) {
            c += &format!("gap_right_m = {g:?}\n");
        }
    }
    c += &format!(
        "\n[contact]\nlaw = \"linear\"\nk_n_per_m = {:?}\n\n[[record]]\nfile = \"{}\"\n\
         window_s = [{:?}, {:?}]\n",
        data["contact_k_n_per_m"].as_float().unwrap(),
        scene["record"].as_str().unwrap(),
        window[0],
        window[1]
    );
    if let Some(dt) = scene.get("record_dt_s") {
        c += &format!("dt_s = {:?}\n", dt.as_float().unwrap());
    }
    c += &format!(
        "\n[intensity]\nscale = [{:?}]\n",
        scene["scale"].as_float().unwrap()
    );
    c
}

/// Against OpenSees (`benches/opensees_pdelta.py`, data in `tests/data/opensees_pdelta.toml`):
/// three scenes on records no other cross-check uses, `Steel01` storeys, Rayleigh dashpots on
/// `K0`, a massless leaning column (`PDelta` geomTransf, gravity `g m_j r` applied first) tied
/// to each P-Delta building's floors, linear compression-only contact: G, a yielding one-storey
/// building (theta 0.071, b 0.02) beside a far neighbour; H, a yielding 3-storey frame with
/// gravity mass ratio 2 pounding an elastic 4-storey; I, a 2-storey frame with gravity mass
/// ratio 3 and b 0.01 that pounds its neighbour and then collapses (first storey past 10 %
/// drift) and leaves the scene (physics.md section 12), while the neighbour goes on through the
/// record and tail (in OpenSees the frame's elements and contacts are removed and its nodes
/// fixed). The OpenSees model meets its closed forms to 3e-12 (the script's checks: the P-Delta
/// SDOF's period `T0 / sqrt(1 - theta)` after gravity, every frame's periods of `(K0 - K_G, M)`,
/// the pushover's slopes `k - P/h` and `-P/h`), and a building leaving the scene leaves its
/// neighbour as it was (scene I with the two 1 m apart: the neighbour equals itself alone to
/// the bit).
///
/// Asserted, for `pound sweep` with each scheme (fast at its default setting and `--scheme
/// reference`), as `inelastic::opensees_cross_check` does: every value within 4 times OpenSees'
/// own change from dt to dt / 2 (its error, which Newmark's order 2 puts at a third of that
/// change) plus a floor, a fraction of a scale. The scales: the scene's largest peak force for
/// forces, the OpenSees peak for drifts, the building's peak drift for each storey's signed
/// residual drift. The floors: the reference scheme 2e-5 (1e-4 for residual drifts, which hang
/// on the whole yielding history), as the other OpenSees cross-checks; the fast scheme at its
/// default setting 2e-3, the target. The collapse: status `collapsed`, the same building
/// and storey (the run's first collapse and the building's own columns; the neighbour's say it
/// stood), the collapsed building's residual drifts empty, and the time within 4 times
/// OpenSees' own change plus the time a drift error of the floor (of the limit) moves the
/// crossing at the drift's rate there (floor x limit / rate); the collapsed building's peaks and
/// its contacts' are over `[0, t_c]` (the collapsing storey's is the limit), the standing
/// neighbour's over the whole run. OpenSees' own changes (in the file): peak drifts up to 4.2e-5
/// of themselves, forces up to 9.6e-6 of the largest, residual drifts up to 4.4e-5 of the peak
/// drift, the collapse time 3.3e-6 s. Measured (this test's last lines with `--nocapture`): the
/// fast scheme within 1.5e-5 of OpenSees on every value, the reference within 1.2e-5, H and I
/// (storeys leaning unequally, so Rayleigh damping on `K0` couples their modes) included; I's
/// neighbour's peak drift over the whole run within 7.2e-7 (fast) and 1.0e-6 (reference).
#[test]
fn opensees_cross_check() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/opensees_pdelta.toml"
    );
    let data: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    let limit = data["collapse_drift_ratio"].as_float().unwrap();
    let dir = records_dir();
    let tmp = tempdir();
    // Worst |pound - OpenSees| over its scale, per scheme: peak force, drift, residual drift,
    // collapse time (over limit / rate: the drift error that moves the crossing as much).
    let mut worst = [[0.0f64; 4]; 2];
    let mut scenes = 0;
    for scene in data["scene"].as_array().unwrap() {
        let name = scene["name"].as_str().unwrap();
        let raw = scene["building"].as_array().unwrap();
        // The window holding the record's first `npts` samples, on its own clock (a two-column
        // file starts at its first time stamp, AT2 and value files at 0).
        let opts = ReadOptions {
            dt: scene.get("record_dt_s").map(|v| v.as_float().unwrap()),
            ..Default::default()
        };
        let rec = read_record(&dir.join(scene["record"].as_str().unwrap()), &opts).unwrap();
        let npts = scene["npts"].as_integer().unwrap() as usize;
        let window = [rec.t0, rec.t0 + (npts - 1) as f64 * rec.dt];
        assert_eq!(
            rec.window(window[0], window[1]).unwrap().npts(),
            npts,
            "{name}: the window"
        );
        let cfg = tmp.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, config(&data, scene, window)).unwrap();
        // The columns compared: each building's peak drift and (yielding) residual drifts, per
        // storey signed, each level's peak force, the collapse.
        let levels: Vec<String> = scene["levels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| format!("level_{}_peak_force_n", l.as_str().unwrap()))
            .collect();
        let mut columns = vec!["status".to_string()];
        columns.extend(levels.iter().cloned());
        for (k, b) in raw.iter().enumerate() {
            columns.push(format!("b{}_peak_drift_ratio", k + 1));
            for c in ["collapsed", "collapse_time_s", "collapse_storey"] {
                columns.push(format!("b{}_{c}", k + 1));
            }
            if b.get("yield_force_n").is_some() {
                columns.push(format!("b{}_residual_drift_ratio", k + 1));
                for j in 1..=floats(&b["masses_kg"]).len() {
                    columns.push(format!("b{}_s{j}_residual_drift_ratio", k + 1));
                }
            }
        }
        columns
            .extend(["collapse_time_s", "collapse_building", "collapse_storey"].map(String::from));
        let collapsed = scene["collapsed"].as_bool().unwrap();
        // The building that collapses (from 1; 0: none). The file holds one collapse per scene.
        let fell = if collapsed {
            scene["collapse_building"].as_integer().unwrap() as usize
        } else {
            0
        };
        for (s, (scheme, floor, residual_floor)) in
            [("fast", 2e-3, 2e-3), ("reference", 2e-5, 1e-4)]
                .into_iter()
                .enumerate()
        {
            let out = tmp.path().join(format!("{name}-{scheme}.csv"));
            ok(&pound(&[
                "sweep",
                cfg.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--backend",
                "cpu",
                "--scheme",
                scheme,
                "--columns",
                &columns.join(","),
            ]));
            let rows = table(&out);
            assert_eq!(rows.len(), 1, "{name}");
            let row = &rows[0];
            let num = |c: &str| -> f64 {
                row[c]
                    .parse()
                    .unwrap_or_else(|_| panic!("{name} {scheme}: {c} = `{}`", row[c]))
            };
            let mut check = |what: &str,
                             slot: usize,
                             got: &[f64],
                             fine: &[f64],
                             coarse: &[f64],
                             scale: &[f64]| {
                assert_eq!(got.len(), fine.len(), "{name} {what}");
                let floor = if slot == 2 { residual_floor } else { floor };
                for (i, (((g, a), b), sc)) in
                    got.iter().zip(fine).zip(coarse).zip(scale).enumerate()
                {
                    let own = (a - b).abs();
                    if *sc > 0.0 {
                        worst[s][slot] = worst[s][slot].max((g - a).abs() / sc);
                    }
                    assert!(
                        (g - a).abs() <= 4.0 * own + floor * sc,
                        "{name} {scheme} {what}[{i}]: pound {g} against OpenSees {a} (its own \
                         error {own}, floor {floor} of {sc})"
                    );
                }
            };
            // The status and the collapse.
            if collapsed {
                assert_eq!(row["status"], "collapsed", "{name} {scheme}");
                for key in ["collapse_building", "collapse_storey"] {
                    assert_eq!(
                        num(key),
                        scene[key].as_integer().unwrap() as f64,
                        "{name} {scheme}: {key}"
                    );
                }
                // pound's clock is the record's; OpenSees' starts at the window's start.
                let t = num("collapse_time_s") - window[0];
                let rate = scene["collapse_drift_rate_per_s"].as_float().unwrap();
                let per_floor = limit / rate;
                check(
                    "collapse time",
                    3,
                    &[t],
                    &[scene["collapse_time_s"].as_float().unwrap()],
                    &[scene["collapse_time_s_coarse"].as_float().unwrap()],
                    &[per_floor],
                );
            } else {
                assert_eq!(row["status"], "ok", "{name} {scheme}");
                for key in ["collapse_time_s", "collapse_building", "collapse_storey"] {
                    assert!(row[key].is_empty(), "{name} {scheme}: {key} = {}", row[key]);
                }
            }
            // Each building's own collapse columns: the one that collapsed has the run's first
            // collapse; the others stood to the end.
            for k in 1..=raw.len() {
                let [flag, time, storey] = ["collapsed", "collapse_time_s", "collapse_storey"]
                    .map(|c| format!("b{k}_{c}"));
                if k == fell {
                    assert_eq!(row[&flag], "1", "{name} {scheme}: {flag}");
                    assert_eq!(
                        row[&time], row["collapse_time_s"],
                        "{name} {scheme}: {time}"
                    );
                    assert_eq!(
                        row[&storey], row["collapse_storey"],
                        "{name} {scheme}: {storey}"
                    );
                } else {
                    assert_eq!(row[&flag], "0", "{name} {scheme}: {flag}");
                    for c in [&time, &storey] {
                        assert!(row[c].is_empty(), "{name} {scheme}: {c} = {}", row[c]);
                    }
                }
            }
            let forces: Vec<f64> = levels.iter().map(|c| num(c)).collect();
            let fine = floats(&scene["peak_force_n"]);
            let largest = fine.iter().cloned().fold(0.0, f64::max);
            check(
                "peak force",
                0,
                &forces,
                &fine,
                &floats(&scene["peak_force_n_coarse"]),
                &vec![largest; fine.len()],
            );
            let drifts: Vec<f64> = (1..=raw.len())
                .map(|k| num(&format!("b{k}_peak_drift_ratio")))
                .collect();
            let fine = floats(&scene["peak_drift_ratio"]);
            check(
                "peak drift",
                1,
                &drifts,
                &fine,
                &floats(&scene["peak_drift_ratio_coarse"]),
                &fine.clone(),
            );
            if collapsed {
                // The collapsing storey's peak drift ratio is the limit.
                assert!(
                    (drifts[fell - 1] - limit).abs() <= 1e-9 * limit,
                    "{name} {scheme}: the collapsing building's peak drift {}",
                    drifts[fell - 1]
                );
            }
            // Residual drifts, storey by storey (signed), against the building's peak drift;
            // empty for the building that collapsed.
            for (k, b) in raw.iter().enumerate() {
                if b.get("yield_force_n").is_none() {
                    continue;
                }
                let n = floats(&b["masses_kg"]).len();
                let cells: Vec<String> =
                    std::iter::once(format!("b{}_residual_drift_ratio", k + 1))
                        .chain((1..=n).map(|j| format!("b{}_s{j}_residual_drift_ratio", k + 1)))
                        .collect();
                if k + 1 == fell {
                    for c in &cells {
                        assert!(row[c].is_empty(), "{name} {scheme}: {c} = {}", row[c]);
                    }
                    continue;
                }
                let got: Vec<f64> = cells[1..].iter().map(|c| num(c)).collect();
                let fine = floats(&b["residual_drift_ratio"]);
                let coarse = floats(&b["residual_drift_ratio_coarse"]);
                let largest = got.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                assert_eq!(
                    num(&cells[0]),
                    largest,
                    "{name} {scheme}: the largest residual"
                );
                check(
                    "residual drift",
                    2,
                    &got,
                    &fine,
                    &coarse,
                    &vec![drifts[k]; n],
                );
            }
        }
        scenes += 1;
    }
    assert_eq!(scenes, 3);
    for (s, scheme) in ["fast", "reference"].iter().enumerate() {
        let w = worst[s];
        eprintln!(
            "worst against OpenSees, {scheme}: peak force {:.1e}, drift {:.1e}, residual {:.1e}, \
             collapse time {:.1e} (of their scales)",
            w[0], w[1], w[2], w[3]
        );
    }
}
