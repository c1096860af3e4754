//! Nothing incomplete is called complete: `--resume` checks what a partial output holds against
//! its journal, `pound merge` checks each shard's content against its sidecar, one sweep writes an
//! output at a time, and shards are cut cheaply and exactly. Then property tests that feed random
//! edits to partial outputs, journals and shards.

use crate::scenes::{Scene, CHEAP_SWEEP};
use crate::support::cli::{fragility, interrupt, refused, s, sibling, stderr, sweep};
use crate::support::{assert_same_text, ok, pound, tempdir};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Class 2: `--resume` checks what the partial holds against its journal (run numbers 0..k in
/// order, the byte count, the checksum); every edit is refused, none gives rc 0 with wrong rows.
#[test]
fn resume_verifies_what_the_journal_vouches_for() {
    let sc = Scene::new();
    let out = sc.path("o.csv");
    let journal = sibling(&out, ".progress.toml");
    let partial = sibling(&out, ".partial");
    sc.interrupted(&out, 0.5);
    let (j0, p0) = (
        std::fs::read_to_string(&journal).unwrap(),
        std::fs::read(&partial).unwrap(),
    );
    let field = |name: &str| -> u64 {
        let line = j0.lines().find(|l| l.starts_with(name)).unwrap();
        line.split('=').nth(1).unwrap().trim().parse().unwrap()
    };
    let (done, bytes) = (field("done"), field("bytes"));
    assert!(done > 4, "{j0}");
    let set = |name: &str, v: u64| {
        j0.lines()
            .map(|l| {
                if l.starts_with(&format!("{name} =")) {
                    format!("{name} = {v}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let text = String::from_utf8(p0.clone()).unwrap();
    let second_row = text.match_indices('\n').nth(1).unwrap().0 + 1;
    let mut edited_value = p0.clone();
    let comma = second_row + text[second_row..].find(",0.").unwrap() + 3;
    edited_value[comma] = if edited_value[comma] == b'9' {
        b'8'
    } else {
        b'9'
    };
    let mut dropped_row = text.clone();
    let row_end = second_row + text[second_row..].find('\n').unwrap() + 1;
    // The same length, so the byte count holds and the run sequence is what catches it.
    let row1 = text[second_row..row_end].to_string();
    dropped_row.replace_range(second_row..row_end, "");
    dropped_row.push_str(&row1);
    let cases: Vec<(&str, String, Vec<u8>, &str)> = vec![
        (
            "done = 999999",
            set("done", 999_999),
            p0.clone(),
            "claims 999999 runs",
        ),
        ("done = 0", set("done", 0), p0.clone(), "vouches for 0 runs"),
        (
            "a smaller byte count",
            set("bytes", bytes - 7),
            p0.clone(),
            "cut off",
        ),
        (
            "a larger byte count",
            set("bytes", bytes + 5000),
            p0.clone(),
            "fewer than",
        ),
        (
            "another checksum",
            j0.replace("sha256 = \"", "sha256 = \"00"),
            p0.clone(),
            "checksum",
        ),
        ("an edited value", j0.clone(), edited_value, "checksum"),
        (
            "a dropped row",
            j0.clone(),
            dropped_row.into_bytes(),
            "expected",
        ),
        (
            "a truncated file",
            j0.clone(),
            p0[..p0.len() / 2].to_vec(),
            "fewer than",
        ),
        (
            "a journal that is not TOML",
            "done = ".into(),
            p0.clone(),
            "cannot resume",
        ),
    ];
    for (what, journal_text, partial_bytes, needle) in cases {
        std::fs::write(&journal, &journal_text).unwrap();
        std::fs::write(&partial, &partial_bytes).unwrap();
        let r = sweep(&sc.cfg, &out, &["--resume"]);
        let err = stderr(&r);
        assert!(!r.status.success(), "{what}: rc 0: {err}");
        assert!(err.contains(needle), "{what}: expected `{needle}` in {err}");
        assert!(!out.exists(), "{what}");
        // Nothing the user may want was touched.
        assert_eq!(std::fs::read(&partial).unwrap(), partial_bytes, "{what}");
    }
    // The untouched pair resumes to the uninterrupted output, with `done` runs reused.
    std::fs::write(&journal, &j0).unwrap();
    std::fs::write(&partial, &p0).unwrap();
    let r = sweep(&sc.cfg, &out, &["--resume"]);
    assert!(stderr(&r).contains(&format!("{done} runs already on disk")));
    ok(&r);
    assert_same_text(
        "resumed",
        &std::fs::read_to_string(&out).unwrap(),
        &sc.whole,
    );
    assert!(!journal.exists() && !partial.exists());
    // The sidecar's content hash is the file's.
    let meta: pounding::io::provenance::Meta =
        pounding::io::provenance::read_toml(&sibling(&out, ".meta.toml")).unwrap();
    let c = meta.content.unwrap();
    assert_eq!(c.rows, 96);
    assert_eq!(c.sha256, pounding::io::journal::file_sha256(&out).unwrap());
}

/// Class 3: merge verifies each shard's content against its sidecar and names the shard and
/// runs that differ; studies warn about results without a sidecar or edited since.
#[test]
fn merge_checks_content_and_studies_warn() {
    let sc = Scene::new();
    let shards: Vec<PathBuf> = (0..3).map(|i| sc.path(&format!("s{i}.csv"))).collect();
    for (i, p) in shards.iter().enumerate() {
        ok(&sweep(&sc.cfg, p, &["--shard", &format!("{i}/3")]));
    }
    let merged = sc.path("m.csv");
    let merge = |out: &Path| {
        let mut a = vec!["merge", "-o", s(out)];
        a.extend(shards.iter().map(|p| s(p)));
        pound(&a)
    };
    ok(&merge(&merged));
    assert_same_text(
        "merged",
        &std::fs::read_to_string(&merged).unwrap(),
        &sc.whole,
    );
    let original = std::fs::read_to_string(&shards[1]).unwrap();
    let first_run: u64 = original
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let edits = [
        ("a value", original.replacen(",0.0", ",0.1", 1)),
        ("a status", original.replacen(",ok,", ",garbage,", 1)),
    ];
    for (what, text) in edits {
        assert_ne!(text, original, "{what}");
        std::fs::write(&shards[1], &text).unwrap();
        let out = sc.path("bad.csv");
        let r = merge(&out);
        refused(&r, "differ from what the sweep wrote", Some(&out));
        let err = stderr(&r);
        assert!(
            err.contains("s1.csv") && err.contains(&format!("runs {first_run}..")),
            "{what}: {err}"
        );
        assert!(!sibling(&out, ".partial").exists(), "{what}");
        // The studies warn, and still run.
        let w = pound(&[
            "plot",
            s(&shards[1]),
            "--x",
            "gap_m",
            "--y",
            "peak_force_n",
            "-o",
            s(&sc.path("p.svg")),
        ]);
        assert!(stderr(&w).contains("it was edited since"), "{}", stderr(&w));
    }
    // A dropped row is a run missing, named by line.
    let mut lines: Vec<&str> = original.lines().collect();
    lines.remove(3);
    std::fs::write(&shards[1], lines.join("\n") + "\n").unwrap();
    refused(
        &merge(&sc.path("bad.csv")),
        "where run",
        Some(&sc.path("bad.csv")),
    );
    // No sidecar: studies warn.
    let bare = sc.path("bare.csv");
    std::fs::write(&bare, &sc.whole).unwrap();
    let w = fragility(&bare, &["-o", s(&sc.path("f.csv"))]);
    assert!(stderr(&w).contains("has no sidecar"), "{}", stderr(&w));
    ok(&w);
    // A complete output with its sidecar: no warning.
    let w = fragility(&merged, &["-o", s(&sc.path("f.csv"))]);
    assert!(!stderr(&w).contains("warning"), "{}", stderr(&w));
}

/// Class 4: one sweep per output. A second sweep, with or without `--resume`, is refused while
/// the first runs, and leaves nothing that blocks later runs; a journal whose sweep died is
/// recoverable with `--resume`.
#[test]
fn one_sweep_writes_an_output_at_a_time() {
    let sc = Scene::new();
    // A slower copy of the scene (longer records), so the first sweep is surely running.
    let slow = sc.path("slow.toml");
    std::fs::write(
        &slow,
        CHEAP_SWEEP
            .replace("duration_s = 3.0", "duration_s = 40.0")
            .replace(
                "gap_m = [0.0, 0.01, 0.03]",
                "gap_m = { from = 0.0, to = 0.05, n = 30 }",
            ),
    )
    .unwrap();
    let out = sc.path("o.csv");
    let first = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args([
            "sweep",
            s(&slow),
            "-o",
            s(&out),
            "--backend",
            "cpu",
            "--threads",
            "1",
            "--chunk",
            "1",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let journal = sibling(&out, ".progress.toml");
    let t = Instant::now();
    while !journal.exists() && t.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    for extra in [&["--resume"][..], &[][..]] {
        let mut args = vec!["sweep", s(&slow), "-o", s(&out), "--backend", "cpu"];
        args.extend_from_slice(extra);
        let r = pound(&args);
        let err = stderr(&r);
        assert!(!r.status.success());
        assert!(err.contains("another running `pound sweep`"), "{err}");
    }
    let r = first.wait_with_output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(!journal.exists(), "the winner removes its journal");
    let whole = std::fs::read_to_string(&out).unwrap();
    // Plain reruns are not blocked by anything the refused sweeps left.
    ok(&sweep(&slow, &out, &[]));
    assert_same_text("rerun", &std::fs::read_to_string(&out).unwrap(), &whole);
    // A sweep that died holds no lock: its journal resumes.
    let out2 = sc.path("o2.csv");
    sc.interrupted(&out2, 0.4);
    refused(&sweep(&sc.cfg, &out2, &[]), "rerun with --resume", None);
    ok(&sweep(&sc.cfg, &out2, &["--resume"]));
    assert_same_text(
        "after a dead sweep",
        &std::fs::read_to_string(&out2).unwrap(),
        &sc.whole,
    );
}

/// Class 6: cutting a shard costs O(blocks x records) per probe, not O(runs): a 1e8-run plan
/// is cut at once, and the cuts equal the linear scan's on a small plan.
#[test]
fn shard_cuts_are_cheap_and_exact() {
    use pounding::plan::shard::{shard_range, Shard};
    let d = tempdir();
    let text = CHEAP_SWEEP
        .replace(
            "period_s = [0.3, 0.6]",
            "period_s = { from = 0.1, to = 2, n = 10000 }",
        )
        .replace(
            "gap_m = [0.0, 0.01, 0.03]",
            "gap_m = { from = 0, to = 0.1, n = 1250 }",
        );
    std::fs::write(d.path().join("rec.txt"), "0.1\n0.2\n0.1\n0.0\n-0.1").unwrap();
    let p =
        pounding::plan::config::parse(&text, Path::new("big.toml"), d.path(), d.path()).unwrap();
    assert_eq!(p.len(), 200_000_000);
    let t = Instant::now();
    let p = pounding::plan::Plan::Pair(p);
    let last = shard_range(
        &p,
        Shard {
            index: 999_999,
            count: 1_000_000,
        },
    );
    assert!(last.end == p.len() && last.start < last.end);
    // Generous: a linear scan of 4e8 runs takes minutes.
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    // Against the linear scan's definition on the small plan: cut k is the first run whose
    // preceding cost reaches k / N of the total.
    let small = pounding::plan::config::parse(CHEAP_SWEEP, Path::new("s.toml"), d.path(), d.path())
        .unwrap();
    let costs: Vec<u64> = small
        .contact
        .spec
        .records
        .iter()
        .map(|r| r.forcing(1.0, small.contact.spec.tail).intervals().max(1) as u64)
        .collect();
    let mut acc = vec![0u128];
    for i in 0..small.len() {
        acc.push(acc[i as usize] + costs[small.run(i).record] as u128);
        assert_eq!(small.cost_before(i + 1, &costs), acc[i as usize + 1]);
    }
    let total = *acc.last().unwrap();
    for n in [1u64, 2, 3, 7, 96, 200] {
        let cut = |k: u64| -> u64 {
            (0..=small.len())
                .find(|&i| acc[i as usize] * n as u128 >= total * k as u128)
                .unwrap()
        };
        let mut next = 0;
        let whole = pounding::plan::Plan::Pair(small.clone());
        for k in 0..n {
            let r = shard_range(&whole, Shard { index: k, count: n });
            assert_eq!(
                r,
                cut(k)..if k + 1 == n { small.len() } else { cut(k + 1) },
                "{k}/{n}"
            );
            assert_eq!(r.start, next);
            next = r.end;
        }
        assert_eq!(next, small.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Random byte edits of an interrupted sweep's partial output and journal: `--resume`
    /// either refuses or gives exactly the uninterrupted output. Never rc 0 with other rows.
    #[test]
    fn edited_partials_never_resume_into_wrong_output(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>(), any::<bool>()), 1..4),
        fraction in 0.2f64..0.8,
    ) {
        let sc = scene();
        let d = tempdir();
        let out = d.path().join("o.csv");
        let cfg = d.path().join("sweep.toml");
        std::fs::copy(&sc.cfg, &cfg).unwrap();
        std::fs::copy(&sc.record, d.path().join("rec.txt")).unwrap();
        interrupt(&cfg, sc.whole.len(), &out, fraction);
        for (at, byte, journal) in edits {
            let p = if journal { sibling(&out, ".progress.toml") } else { sibling(&out, ".partial") };
            let mut b = std::fs::read(&p).unwrap();
            if b.is_empty() { continue; }
            let i = at.index(b.len());
            b[i] = byte;
            std::fs::write(&p, b).unwrap();
        }
        let r = sweep(&cfg, &out, &["--resume"]);
        prop_assert!(!stderr(&r).contains("panicked"));
        if r.status.success() {
            prop_assert_eq!(std::fs::read_to_string(&out).unwrap(), sc.whole.clone());
        } else {
            prop_assert!(!out.exists());
        }
    }

    /// Random byte edits of a shard: merge refuses, or gives exactly the unsharded output.
    #[test]
    fn edited_shards_never_merge_into_wrong_output(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4),
        which in 0usize..2,
    ) {
        let sc = scene();
        let d = tempdir();
        let shards: Vec<PathBuf> = (0..2).map(|i| d.path().join(format!("s{i}.csv"))).collect();
        for (i, p) in shards.iter().enumerate() {
            std::fs::copy(sc.dir.path().join(format!("shard{i}.csv")), p).unwrap();
            std::fs::copy(sc.dir.path().join(format!("shard{i}.csv.meta.toml")), sibling(p, ".meta.toml")).unwrap();
        }
        let mut b = std::fs::read(&shards[which]).unwrap();
        for (at, byte) in edits {
            let i = at.index(b.len());
            b[i] = byte;
        }
        std::fs::write(&shards[which], b).unwrap();
        let out = d.path().join("m.csv");
        let r = pound(&["merge", "-o", s(&out), s(&shards[0]), s(&shards[1])]);
        prop_assert!(!stderr(&r).contains("panicked"));
        if r.status.success() {
            prop_assert_eq!(std::fs::read_to_string(&out).unwrap(), sc.whole.clone());
        } else {
            prop_assert!(!out.exists());
        }
    }
}

/// One scene and its two shards for the property tests (built once).
fn scene() -> &'static Scene {
    static SCENE: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    SCENE.get_or_init(|| {
        let sc = Scene::new();
        for i in 0..2 {
            ok(&sweep(
                &sc.cfg,
                &sc.path(&format!("shard{i}.csv")),
                &["--shard", &format!("{i}/2")],
            ));
        }
        sc
    })
}
