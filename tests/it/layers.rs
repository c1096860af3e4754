//! The layering `src/lib.rs` promises: each folder imports only the layers below it, so there is
//! no module cycle and the physics knows nothing of plans, engines, files or studies.

use std::path::Path;

/// Bottom up, as in `src/lib.rs`.
const LAYERS: [&str; 7] = [
    "physics", "record", "config", "plan", "engine", "io", "studies",
];

fn layer(name: &str) -> Option<usize> {
    LAYERS.iter().position(|l| *l == name)
}

/// Every `crate::NAME` a source file names outside comments.
fn crate_paths(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            rest = &rest[i + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            found.push(name);
        }
    }
    found
}

fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn no_layer_imports_a_higher_one() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut checked = 0;
    for folder in LAYERS {
        let mut files = Vec::new();
        sources(&src.join(folder), &mut files);
        assert!(!files.is_empty(), "src/{folder} has sources");
        let own = layer(folder).unwrap();
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for name in crate_paths(&text) {
                let Some(to) = layer(&name) else {
                    continue; // crate::note and the like, at the root
                };
                assert!(
                    to <= own,
                    "{} ({folder}) imports crate::{name}, a higher layer",
                    f.display()
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 100, "only {checked} imports seen");
    // The library never reaches the command line, which lives in the binary.
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    assert!(!lib.contains("mod cli"));
}
