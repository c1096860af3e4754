//! The worked example of docs/collapse.md, "Collapse with deteriorating storeys"
//! (`configs/collapse-imk.toml`), cut down to one record and a few intensities: the same frame
//! with bilinear storeys and with IMK storeys of either rule. The IMK storeys lose strength
//! (their energy capacity spent cycle by cycle) and collapse at a lower intensity than the
//! bilinear ones on the same record.

use pounding::physics::model::Status;
use pounding::physics::row::RowOutput;
use pounding::physics::solver::row::{simulate_row, RowModel};
use pounding::plan::Plan;
use std::path::Path;

/// The Sa(T1) levels of the cut-down ladder, g.
const LADDER: [f64; 4] = [0.4, 0.5, 0.6, 0.8];

/// The IMK keys of the example's frame (left out for its bilinear twin).
const IMK_KEYS: [&str; 4] = [
    "hysteresis",
    "plastic_drift_ratio",
    "post_capping_drift_ratio",
    "energy_capacity_ratio",
];

/// `text` with `line` put after `after`, which must be in it.
fn insert_after(text: &str, after: &str, line: &str) -> String {
    assert!(text.contains(after), "the example no longer has `{after}`");
    text.replacen(after, &format!("{after}{line}"), 1)
}

/// The shipped example without its samples (the frame's period 0.8 s, the gap 30 mm: the
/// samples' medians), on San Fernando 1971 (Pacoima Dam) only, over [`LADDER`].
fn cut_down() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/collapse-imk.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let head = &text[..text.find("[sample]").expect("the example is sampled")];
    let head = insert_after(head, "gravity_mass_ratio = 2.0\n", "period_s = 0.8\n");
    let head = insert_after(&head, "beta_n_per_m1_5 = 2.75e9\n", "gap_m = 0.03\n");
    let ladder: Vec<String> = LADDER.iter().map(f64::to_string).collect();
    format!(
        "{head}[[record]]\nname = \"san_fernando_1971_pacoima\"\nfile = \"sanfernando1971_pacoima_RSN77_PUL164.AT2\"\n\n\
         [intensity]\nsa_g = [{}]\nsa_period_s = \"building1\"\n",
        ladder.join(", ")
    )
}

/// Every run of config `text`, in run order, on the CPU.
fn runs(text: &str) -> Vec<RowOutput> {
    let plan = match pounding::plan::config::load_text(text, Path::new("collapse-imk.toml")) {
        Ok(Plan::Row(plan)) => plan,
        other => panic!("not a row: {other:?}"),
    };
    assert_eq!(plan.len(), LADDER.len() as u64);
    (0..plan.len())
        .map(|i| {
            let spec = plan.run(i);
            let model = RowModel::new(&plan.row(&spec));
            simulate_row(
                &model,
                &plan.forcing(&spec),
                model.at_rest(),
                &plan.scheme(),
            )
        })
        .collect()
}

/// The lowest level of [`LADDER`] at which a run collapsed.
fn first_collapse(outs: &[RowOutput]) -> f64 {
    let at = outs
        .iter()
        .position(|o| o.status == Status::Collapsed)
        .expect("the frame collapses on the ladder");
    LADDER[at]
}

#[test]
fn imk_storeys_lose_strength_and_collapse_below_bilinear_ones() {
    let peak_oriented = cut_down();
    assert!(peak_oriented.contains("hysteresis = \"imk_peak_oriented\""));
    let imk_bilinear = peak_oriented.replace("imk_peak_oriented", "imk_bilinear");
    let bilinear: String = peak_oriented
        .lines()
        .filter(|l| !IMK_KEYS.iter().any(|k| l.starts_with(&format!("{k} = "))))
        .map(|l| format!("{l}\n"))
        .collect();

    let plain = runs(&bilinear);
    for o in &plain {
        assert!(
            o.storeys
                .iter()
                .all(|s| s.strength_ratio.is_nan() && !s.capped),
            "a bilinear storey has no strength to lose"
        );
    }
    let plain_collapse = first_collapse(&plain);
    let mut firsts = Vec::new();
    for (rule, text) in [
        ("imk_peak_oriented", &peak_oriented),
        ("imk_bilinear", &imk_bilinear),
    ] {
        let outs = runs(text);
        let at = first_collapse(&outs);
        firsts.push(at);
        assert!(
            at < plain_collapse,
            "{rule}: collapses first at Sa {at} g, the bilinear frame at {plain_collapse} g"
        );
        for (o, sa) in outs.iter().zip(LADDER) {
            // The frame's three storeys (its neighbour is elastic).
            assert_eq!(o.storeys.len(), 3);
            let weakest = o
                .storeys
                .iter()
                .map(|s| s.strength_ratio)
                .fold(f64::INFINITY, f64::min);
            if o.storeys.iter().any(|s| s.yielded) {
                assert!(
                    weakest < 1.0,
                    "{rule} at {sa} g: a storey yielded and kept all its strength"
                );
            }
            if o.status == Status::Collapsed {
                let c = o.collapse.expect("a collapse's storey");
                assert_eq!(c.building, 1, "{rule} at {sa} g: the frame collapses");
                let storey = &o.storeys[c.storey as usize - 1];
                assert!(
                    storey.capped,
                    "{rule} at {sa} g: collapsed without passing its capping point"
                );
            }
        }
    }
    // docs/collapse.md quotes these levels.
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/collapse.md"))
        .unwrap()
        .replace('\n', " ");
    let said = format!(
        "({} g peak-oriented, {} g IMK bilinear, against {} g)",
        firsts[0], firsts[1], plain_collapse
    );
    assert!(
        doc.contains(&said),
        "docs/collapse.md does not say `{said}`"
    );
}
