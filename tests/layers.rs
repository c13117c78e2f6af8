//! Imports point down: every `crate::…` path (and `super::` between sibling files) in
//! `src/` is read, and the test fails, naming the file and the import, when a module
//! imports from a higher layer, when top-level modules import each other in a cycle, or
//! when sibling files of one module do.
//!
//! The layer table is ARCHITECTURE.md's ("## Layers"): the test reads it there, so the
//! document and the code cannot drift apart, and a module the table does not place is a
//! failure too. `checker_names_an_upward_import_and_a_cycle` feeds the checker a made-up
//! crate with one wrong import (`geometry` reaching up into `scene`) and one cycle, and
//! asserts that both are reported: the check can fail.
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source file: its path under `src/` (e.g. `sky/mie.rs`) and its text.
struct Source {
    rel: String,
    text: String,
}

/// Layer of each top-level module, from the "## Layers" table of ARCHITECTURE.md: rows
/// `| N name | `a`, `b` … |`.
fn layer_table(architecture: &str) -> BTreeMap<String, u32> {
    let mut table = BTreeMap::new();
    let section = architecture
        .split("\n## Layers")
        .nth(1)
        .expect("ARCHITECTURE.md has a \"## Layers\" section");
    let section = section.split("\n## ").next().unwrap();
    for line in section.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 3 {
            continue;
        }
        let Some(level) = cells[1]
            .split_whitespace()
            .next()
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        for m in cells[2].split('`').skip(1).step_by(2) {
            let m = m.trim_end_matches(".rs").trim_end_matches('/');
            table.insert(m.to_string(), level);
        }
    }
    table
}

/// The text with comments (line, doc and block) and string literals blanked, so that a
/// path named in a doc comment or a message is not taken for an import.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'"' {
            // A plain string; raw strings (r"…", r#"…"#) hold no `crate::` paths here.
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            // A char literal such as '"' (lifetimes have no closing quote here).
            i += 3;
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The first segments of the paths that follow `prefix` (`crate::` or `super::`): for
/// `crate::a::b` it is `a`; for `crate::{a::b, c}` it is `a` and `c`.
fn heads(code: &str, prefix: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = code;
    while let Some(pos) = rest.find(prefix) {
        let before = rest[..pos].chars().last();
        rest = &rest[pos + prefix.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level items of the brace group.
            let (mut depth, mut start) = (0, 0);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        found.push(ident(&group[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        found.push(ident(&group[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            found.push(ident(rest));
        }
    }
    found.retain(|s| !s.is_empty() && s != "self");
    found
}

fn ident(s: &str) -> String {
    s.trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

/// Problems found in `sources` against `layers`, one line each naming the file and the
/// import.
fn check(sources: &[Source], layers: &BTreeMap<String, u32>) -> Vec<String> {
    let mut problems = Vec::new();
    // Top-level module of a file: `sky/mie.rs` → `sky`, `render.rs` → `render`.
    let top = |rel: &str| -> String {
        let first = rel.split('/').next().unwrap();
        first.trim_end_matches(".rs").to_string()
    };
    let mut module_edges: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    // Sibling files of one directory: (dir, file stem) → stems it imports, with where.
    let mut sibling_edges: BTreeMap<(String, String), BTreeMap<String, String>> = BTreeMap::new();
    let files: BTreeSet<&str> = sources.iter().map(|s| s.rel.as_str()).collect();
    for s in sources {
        if s.rel == "lib.rs" || s.rel == "main.rs" {
            continue;
        }
        let from = top(&s.rel);
        let Some(&from_layer) = layers.get(&from) else {
            problems.push(format!(
                "src/{}: module `{from}` is not in ARCHITECTURE.md's layer table",
                s.rel
            ));
            continue;
        };
        let code = code_only(&s.text);
        for to in heads(&code, "crate::") {
            if to == from || to == "HeronError" || to == "Result" {
                // `crate::HeronError`/`crate::Result` are `error`'s, re-exported by lib.rs.
                if to != from {
                    module_edges
                        .entry(from.clone())
                        .or_default()
                        .entry("error".into())
                        .or_insert_with(|| s.rel.clone());
                }
                continue;
            }
            match layers.get(&to) {
                None => problems.push(format!(
                    "src/{}: imports `crate::{to}`, which is not in ARCHITECTURE.md's layer table",
                    s.rel
                )),
                Some(&l) if l > from_layer => problems.push(format!(
                    "src/{}: `{from}` (layer {from_layer}) imports `crate::{to}` (layer {l}): imports must point down",
                    s.rel
                )),
                Some(_) => {
                    module_edges
                        .entry(from.clone())
                        .or_default()
                        .entry(to.clone())
                        .or_insert_with(|| s.rel.clone());
                }
            }
        }
        // `super::x` from a file that is not its directory's mod.rs names a sibling file
        // (or an item of mod.rs, the parent, which is not a sibling).
        let path = Path::new(&s.rel);
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let dir = path
            .parent()
            .map(|p| p.to_string_lossy().into_owned())
            .unwrap_or_default();
        if stem != "mod" && !dir.is_empty() {
            for to in heads(&code, "super::") {
                let sibling = format!("{dir}/{to}.rs");
                let sibling_dir = format!("{dir}/{to}/mod.rs");
                if to != stem
                    && (files.contains(sibling.as_str()) || files.contains(sibling_dir.as_str()))
                {
                    sibling_edges
                        .entry((dir.clone(), stem.clone()))
                        .or_default()
                        .insert(to, s.rel.clone());
                }
            }
            // `crate::dir::sibling` names a sibling too.
            let dir_path = dir.replace('/', "::");
            for to in heads(&code, &format!("crate::{dir_path}::")) {
                let sibling = format!("{dir}/{to}.rs");
                if to != stem && files.contains(sibling.as_str()) {
                    sibling_edges
                        .entry((dir.clone(), stem.clone()))
                        .or_default()
                        .insert(to, s.rel.clone());
                }
            }
        }
    }
    // Cycles among top-level modules (any length).
    for cycle in cycles(&module_edges) {
        let hops: Vec<String> = cycle
            .windows(2)
            .map(|w| {
                format!(
                    "{} → {} (in src/{})",
                    w[0], w[1], module_edges[&w[0]][&w[1]]
                )
            })
            .collect();
        problems.push(format!("modules import each other: {}", hops.join(", ")));
    }
    // Cycles among sibling files, per directory.
    let mut by_dir: BTreeMap<String, BTreeMap<String, BTreeMap<String, String>>> = BTreeMap::new();
    for ((dir, stem), tos) in sibling_edges {
        by_dir.entry(dir).or_default().insert(stem, tos);
    }
    for (dir, edges) in by_dir {
        for cycle in cycles(&edges) {
            let hops: Vec<String> = cycle
                .windows(2)
                .map(|w| format!("{dir}/{}.rs → {}", w[0], w[1]))
                .collect();
            problems.push(format!("files import each other: {}", hops.join(", ")));
        }
    }
    let mut seen = BTreeSet::new();
    problems.retain(|p| seen.insert(p.clone()));
    problems
}

/// One cycle (closed: first = last) through each strongly connected set of nodes.
fn cycles(edges: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let mut reported: BTreeSet<String> = BTreeSet::new();
    for start in edges.keys() {
        if reported.contains(start) {
            continue;
        }
        // Depth-first search for a path back to `start`.
        let mut stack: Vec<(String, Vec<String>)> = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((node, path)) = stack.pop() {
            let Some(next) = edges.get(&node) else {
                continue;
            };
            if next.contains_key(start) {
                let mut cycle = path.clone();
                cycle.push(start.clone());
                reported.extend(cycle.iter().cloned());
                found.push(cycle);
                break;
            }
            for n in next.keys() {
                if seen.insert(n.clone()) {
                    let mut p = path.clone();
                    p.push(n.clone());
                    stack.push((n.clone(), p));
                }
            }
        }
    }
    found
}

fn sources_under(root: &Path) -> Vec<Source> {
    let mut out = Vec::new();
    let mut dirs: Vec<PathBuf> = vec![root.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                out.push(Source {
                    rel,
                    text: std::fs::read_to_string(&p).unwrap(),
                });
            }
        }
    }
    out.sort_by(|a, b| a.rel.cmp(&b.rel));
    out
}

#[test]
fn imports_point_down_the_layer_table() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let architecture = std::fs::read_to_string(manifest.join("ARCHITECTURE.md")).unwrap();
    let layers = layer_table(&architecture);
    assert!(
        layers.len() >= 20,
        "ARCHITECTURE.md's layer table names only {layers:?}"
    );
    let sources = sources_under(&manifest.join("src"));
    let problems = check(&sources, &layers);
    assert!(
        problems.is_empty(),
        "{} import problem(s):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn checker_names_an_upward_import_and_a_cycle() {
    let layers = layer_table(
        "# x\n## Layers\n\n| layer | modules |\n| --- | --- |\n| 0 base | `math`, `error` |\n\
         | 1 data | `geometry`, `spectrum` |\n| 2 physics | `sky`, `medium` |\n| 3 scene | `scene` |\n\n## Next\n| 9 x | `nothing` |\n",
    );
    assert_eq!(layers.len(), 7, "{layers:?}");
    let src = |rel: &str, text: &str| Source {
        rel: rel.into(),
        text: text.into(),
    };
    let sources = [
        // The deliberately wrong import: geometry (1) reaching up into scene (3).
        src(
            "geometry/spawn.rs",
            "use crate::math::Frame;\nfn f() { crate::scene::load::MIN; }\n",
        ),
        // Not imports: a doc comment and a string.
        src(
            "geometry/mod.rs",
            "//! See [`crate::scene`].\nconst S: &str = \"crate::scene\";\nuse crate::{math::{a, b}, error};",
        ),
        // A cycle between two modules of one layer.
        src("sky/mod.rs", "use crate::medium::Medium;"),
        src("medium/mod.rs", "use crate::{sky::mie, spectrum};"),
        // A cycle between sibling files.
        src("sky/mie.rs", "use super::debye::{self, Interface};"),
        src("sky/debye.rs", "use super::{mie::coefficients, Polarisation};"),
        src("scene/mod.rs", "use crate::{geometry, sky};"),
        // A module the table does not place.
        src("stray.rs", "use crate::math;"),
    ];
    let problems = check(&sources, &layers);
    let has = |needle: &str| problems.iter().any(|p| p.contains(needle));
    assert!(
        has("src/geometry/spawn.rs: `geometry` (layer 1) imports `crate::scene` (layer 3)"),
        "{problems:#?}"
    );
    assert!(!has("src/geometry/mod.rs"), "{problems:#?}");
    assert!(has("modules import each other: "), "{problems:#?}");
    assert!(
        has("medium → sky (in src/medium/mod.rs)") && has("sky → medium (in src/sky/mod.rs)"),
        "{problems:#?}"
    );
    assert!(has("files import each other: sky/"), "{problems:#?}");
    assert!(
        has("src/stray.rs: module `stray` is not in"),
        "{problems:#?}"
    );
    assert_eq!(problems.len(), 4, "{problems:#?}");
}
