//! The layering `src/lib.rs` promises: each folder imports only the layers below it, so there is
//! no module cycle and the physics knows nothing of plans, engines, files or studies.

use std::path::Path;

/// Bottom up, as in `src/lib.rs`.
const LAYERS: [&str; 8] = [
    "physics", "record", "config", "plan", "engine", "io", "sweep", "studies",
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

/// A source file's code lines with comments and `#[cfg(test)]` modules taken out, each with its
/// line number and the inline modules (`mod name { ... }`) it sits in: `super::` inside one
/// names the module around it, not the folder.
fn code_lines(text: &str) -> Vec<(usize, usize, String)> {
    let mut out = Vec::new();
    let mut depth = 0i64; // braces open
    let mut inline: Vec<i64> = Vec::new(); // the depth each open inline module started at
    let mut test_from: Option<i64> = None; // skipping a #[cfg(test)] module opened at this depth
    let mut after_cfg_test = false;
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let trimmed = code.trim();
        let opens_module = (trimmed.starts_with("mod ") || trimmed.starts_with("pub mod "))
            && trimmed.ends_with('{');
        if test_from.is_none() && after_cfg_test && opens_module {
            test_from = Some(depth);
        } else if test_from.is_none() && opens_module {
            inline.push(depth);
        }
        if test_from.is_none() {
            out.push((i + 1, inline.len(), code.to_string()));
        }
        after_cfg_test = trimmed == "#[cfg(test)]" || (after_cfg_test && trimmed.starts_with("#["));
        depth += code.matches('{').count() as i64 - code.matches('}').count() as i64;
        if test_from.is_some_and(|d| depth <= d) {
            test_from = None;
        }
        while inline.last().is_some_and(|d| depth <= *d) {
            inline.pop();
        }
    }
    out
}

/// The paths a line names: each `super::...` and `crate::...` path, groups (`{a, b::c}`) spread
/// into one path each, as segments.
fn paths_in(code: &str) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let bytes: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let rest: String = bytes[i..].iter().collect();
        let starts = (rest.starts_with("super::") || rest.starts_with("crate::"))
            && (i == 0
                || !(bytes[i - 1].is_alphanumeric() || bytes[i - 1] == '_' || bytes[i - 1] == ':'));
        if !starts {
            i += 1;
            continue;
        }
        let (path, used) = path_at(&bytes[i..]);
        found.extend(path);
        i += used.max(1);
    }
    found
}

/// The paths of a `use`-like tree starting at `s` (`a::b::{c, d::e}`), and the characters read.
fn path_at(s: &[char]) -> (Vec<Vec<String>>, usize) {
    let mut prefix = Vec::new();
    let mut i = 0;
    loop {
        let name: String = s[i..]
            .iter()
            .take_while(|c| c.is_alphanumeric() || **c == '_')
            .collect();
        i += name.len();
        if name.is_empty() {
            break;
        }
        prefix.push(name);
        if s[i..].starts_with(&[':', ':']) {
            i += 2;
            if s.get(i) == Some(&'{') {
                // A group: each member is a path of its own under the prefix.
                i += 1;
                let mut out = Vec::new();
                loop {
                    while s.get(i).is_some_and(|c| c.is_whitespace() || *c == ',') {
                        i += 1;
                    }
                    match s.get(i) {
                        None => return (out, i),
                        Some('}') => return (out, i + 1),
                        _ => {}
                    }
                    let (members, used) = path_at(&s[i..]);
                    for m in members {
                        out.push(prefix.iter().cloned().chain(m).collect());
                    }
                    i += used.max(1);
                }
            }
        } else {
            break;
        }
    }
    (vec![prefix], i)
}

/// A module path below `src` (`["engine", "gpu", "row"]`) for a file.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop(); // a folder's mod.rs is the folder itself
    }
    parts
}

/// Every folder under `src` (not `src` itself: the layers above cover it), with the names of its
/// nodes: its files (less mod.rs) and its subfolders.
fn folders(src: &Path) -> std::collections::BTreeMap<Vec<String>, Vec<String>> {
    let mut files = Vec::new();
    sources(src, &mut files);
    let mut map = std::collections::BTreeMap::<Vec<String>, Vec<String>>::new();
    for f in &files {
        let m = module_of(src, f);
        if m.len() >= 2 {
            let folder = m[..m.len() - 1].to_vec();
            map.entry(folder).or_default().push(m[m.len() - 1].clone());
        }
        if f.file_name().is_some_and(|n| n == "mod.rs") {
            map.entry(m).or_default();
        }
    }
    for nodes in map.values_mut() {
        nodes.sort();
        nodes.dedup();
    }
    map
}

/// Items a folder's mod.rs re-exports from a child (`pub use child::{A, b::C}`): item -> child.
fn reexports(src: &Path, folder: &[String]) -> std::collections::HashMap<String, String> {
    let mod_rs = src.join(folder.join("/")).join("mod.rs");
    let text = std::fs::read_to_string(mod_rs).unwrap_or_default();
    let mut map = std::collections::HashMap::new();
    for (_, _, code) in code_lines(&text) {
        let t = code.trim();
        let Some(tree) = t
            .strip_prefix("pub use ")
            .or_else(|| t.strip_prefix("pub(crate) use "))
        else {
            continue;
        };
        let chars: Vec<char> = tree.chars().collect();
        for p in path_at(&chars).0 {
            if p.len() >= 2 {
                map.insert(p[p.len() - 1].clone(), p[0].clone());
            }
        }
    }
    map
}

/// The import edges inside each folder: (folder, from node, to node) -> the file and line of one
/// use that makes it.
fn folder_edges(src: &Path) -> std::collections::BTreeMap<(Vec<String>, String, String), String> {
    let folders = folders(src);
    let mut files = Vec::new();
    sources(src, &mut files);
    let mut edges = std::collections::BTreeMap::new();
    for f in &files {
        let module = module_of(src, f);
        if module.is_empty() {
            continue; // lib.rs, main.rs
        }
        let text = std::fs::read_to_string(f).unwrap();
        for (line, nested, code) in code_lines(&text) {
            for path in paths_in(&code) {
                // The module path named, absolute from the crate's root.
                let mut target: Vec<String> = Vec::new();
                let mut segs = path.iter().peekable();
                if path[0] == "crate" {
                    segs.next();
                } else {
                    // `super` from inline modules first leaves them, then climbs from this module.
                    let mut here = module.clone();
                    let mut ups = 0usize;
                    while segs.peek().is_some_and(|s| *s == "super") {
                        segs.next();
                        ups += 1;
                    }
                    let climbs = ups.saturating_sub(nested);
                    if climbs == 0 || climbs > here.len() {
                        continue; // an inline module's parent is this file
                    }
                    here.truncate(here.len() - climbs);
                    target = here;
                }
                target.extend(segs.cloned());
                // The deepest folder the path goes through that holds this file too.
                for depth in (1..target.len()).rev() {
                    let folder = &target[..depth];
                    let Some(nodes) = folders.get(folder) else {
                        continue;
                    };
                    if !module.starts_with(folder) || module.len() <= folder.len() {
                        continue; // not this file's folder: look in the folders around it
                    }
                    let from = module[folder.len()].clone();
                    let mut to = target[depth].clone();
                    if !nodes.contains(&to) {
                        match reexports(src, folder).get(&to) {
                            Some(child) => to = child.clone(),
                            None => break, // an item of the folder's mod.rs
                        }
                    }
                    if from != to && nodes.contains(&to) {
                        edges
                            .entry((folder.to_vec(), from, to))
                            .or_insert_with(|| format!("{}:{line}", f.display()));
                    }
                    break;
                }
            }
        }
    }
    edges
}

/// The circles (strongly connected sets of two nodes or more) of each folder's import graph.
fn circles(
    edges: &std::collections::BTreeMap<(Vec<String>, String, String), String>,
) -> Vec<(Vec<String>, Vec<String>)> {
    let mut by_folder = std::collections::BTreeMap::<Vec<String>, Vec<(String, String)>>::new();
    for (folder, from, to) in edges.keys() {
        by_folder
            .entry(folder.clone())
            .or_default()
            .push((from.clone(), to.clone()));
    }
    let mut found = Vec::new();
    for (folder, es) in by_folder {
        let reach = |a: &str, b: &str| {
            let mut seen = std::collections::BTreeSet::new();
            let mut todo = vec![a.to_string()];
            while let Some(n) = todo.pop() {
                for (x, y) in &es {
                    if *x == n && seen.insert(y.clone()) {
                        todo.push(y.clone());
                    }
                }
            }
            seen.contains(b)
        };
        let mut nodes: Vec<String> = es
            .iter()
            .flat_map(|(a, b)| [a.clone(), b.clone()])
            .collect();
        nodes.sort();
        nodes.dedup();
        let mut placed = std::collections::BTreeSet::new();
        for n in &nodes {
            if placed.contains(n) {
                continue;
            }
            let set: Vec<String> = nodes
                .iter()
                .filter(|m| *m == n || (reach(n, m) && reach(m, n)))
                .cloned()
                .collect();
            if set.len() > 1 {
                placed.extend(set.iter().cloned());
                found.push((folder.clone(), set));
            }
        }
    }
    found
}

/// Issue 66: no folder of `src/` has a circle of imports between its files (`super::`,
/// `crate::folder::file` and `use super::{a, b}` groups counted; a folder's mod.rs is the folder
/// itself, a subfolder one node of its parent), so each folder's files read bottom up too.
#[test]
fn no_folder_has_a_circle_of_imports() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = folder_edges(&src);
    assert!(edges.len() > 50, "only {} edges seen", edges.len());
    let found = circles(&edges);
    let mut report = String::new();
    for (folder, set) in &found {
        report += &format!("src/{}: {}\n", folder.join("/"), set.join(", "));
        for ((f, from, to), at) in &edges {
            if f == folder && set.contains(from) && set.contains(to) {
                report += &format!("    {from} -> {to} ({at})\n");
            }
        }
    }
    assert!(
        found.is_empty(),
        "circles of imports inside folders:\n{report}"
    );
}

/// A file's lines outside its `#[cfg(test)]` modules.
fn lines_outside_tests(text: &str) -> usize {
    code_lines(text).len()
}

/// Issue 66: no source file is over about 800 lines outside its `#[cfg(test)]` module, so each
/// can be read at once.
#[test]
fn no_source_file_is_over_800_lines_outside_its_tests() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.sort();
    let over: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = lines_outside_tests(&std::fs::read_to_string(f).unwrap());
            (n > 800).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(
        over.is_empty(),
        "over 800 lines outside tests:\n{}",
        over.join("\n")
    );
}
