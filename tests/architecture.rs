//! The layering ARCHITECTURE.md draws, checked from the sources: no crate depends on one
//! above it, and no module of a library crate reaches, through `crate::` paths, a module
//! that reaches back (an import circle).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// The workspace dependencies named in a crate's manifest.
fn dependencies(krate: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(root().join(krate).join("Cargo.toml")).unwrap();
    let manifest: toml::Table = toml::from_str(&text).unwrap();
    manifest.get("dependencies").and_then(|d| d.as_table()).map(|t| t.keys().cloned().collect()).unwrap_or_default()
}

#[test]
fn no_crate_depends_on_one_above_it() {
    // Bottom to top; each may use only those before it.
    let layers = [
        ("shaders", "splitsum-shaders"),
        ("spirv", "splitsum-spirv"),
        ("reference", "splitsum-reference"),
        ("splitsum", "splitsum"),
        ("display", "splitsum-display"),
        ("report", "splitsum-report"),
        ("runner", "runner"),
    ];
    for (k, (dir, _)) in layers.iter().enumerate() {
        let deps = dependencies(dir);
        for (_, above) in &layers[k..] {
            assert!(!deps.contains(*above), "{dir} depends on {above}, which sits above it");
        }
    }
    assert!(!dependencies("report").contains("splitsum-display"), "report and display are siblings");
    assert!(!dependencies("display").contains("splitsum-reference"), "the references are the report's");
}

/// Top-level module of each source file of `src`, and the `crate::` modules it names.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut files = vec![];
    let mut todo = vec![src.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    for f in &files {
        let rel = f.strip_prefix(src).unwrap();
        let module = rel.components().next().unwrap().as_os_str().to_string_lossy().trim_end_matches(".rs").to_string();
        if module == "lib" {
            continue;
        }
        // Code only: a doc link is no import.
        let text: String = std::fs::read_to_string(f).unwrap().lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n");
        let uses = graph.entry(module.clone()).or_default();
        for (i, _) in text.match_indices("crate::") {
            let name: String = text[i + 7..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if !name.is_empty() && name != module && name.chars().next().unwrap().is_lowercase() {
                uses.insert(name);
            }
        }
    }
    graph
}

/// A cycle of `graph`, if it has one.
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(n: &str, g: &BTreeMap<String, BTreeSet<String>>, path: &mut Vec<String>, done: &mut BTreeSet<String>) -> Option<Vec<String>> {
        if let Some(k) = path.iter().position(|p| p == n) {
            let mut c = path[k..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, g, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|n| visit(n, graph, &mut Vec::new(), &mut done))
}

#[test]
fn no_module_of_a_library_crate_imports_in_a_circle() {
    for krate in ["shaders", "splitsum", "display", "report"] {
        let graph = module_graph(&root().join(krate).join("src"));
        assert!(graph.len() > 3, "{krate}: read its modules");
        if let Some(c) = cycle(&graph) {
            panic!("{krate}: import circle {}", c.join(" → "));
        }
    }
}
