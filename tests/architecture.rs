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

/// The top-level module a `crate::` path names, for every such path in `file`: use trees
/// (grouped ones too: `use crate::{a, b::c}` names `a` and `b`), paths in code, and paths
/// inside macro calls (read from their tokens, which syn does not parse).
fn crate_paths(file: &syn::File) -> BTreeSet<String> {
    use syn::visit::Visit;
    #[derive(Default)]
    struct Names(BTreeSet<String>);
    fn use_tree(tree: &syn::UseTree, under_crate: bool, out: &mut BTreeSet<String>) {
        match tree {
            syn::UseTree::Path(p) if !under_crate => use_tree(&p.tree, p.ident == "crate", out),
            syn::UseTree::Path(p) => drop(out.insert(p.ident.to_string())),
            syn::UseTree::Name(n) if under_crate => drop(out.insert(n.ident.to_string())),
            syn::UseTree::Rename(r) if under_crate => drop(out.insert(r.ident.to_string())),
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| use_tree(t, under_crate, out)),
            _ => {}
        }
    }
    impl<'a> Visit<'a> for Names {
        fn visit_item_use(&mut self, u: &'a syn::ItemUse) {
            use_tree(&u.tree, false, &mut self.0);
        }
        fn visit_path(&mut self, p: &'a syn::Path) {
            let mut s = p.segments.iter();
            if let (Some(first), Some(second)) = (s.next(), s.next())
                && first.ident == "crate"
            {
                self.0.insert(second.ident.to_string());
            }
            syn::visit::visit_path(self, p);
        }
        fn visit_macro(&mut self, m: &'a syn::Macro) {
            let tokens: Vec<String> = m.tokens.to_string().split_whitespace().map(str::to_string).collect();
            for w in tokens.windows(3) {
                if w[0] == "crate" && w[1] == "::" {
                    self.0.insert(w[2].clone());
                }
            }
            syn::visit::visit_macro(self, m);
        }
    }
    let mut names = Names::default();
    names.visit_file(file);
    names.0
}

/// What the crate root re-exports, by name, and the top-level module each comes from
/// (`pub use settings::{Job, Settings}` maps `Job` and `Settings` to `settings`), so that
/// `crate::Settings` counts as an import of `settings`.
fn root_reexports(lib: &syn::File) -> BTreeMap<String, String> {
    fn leaves(tree: &syn::UseTree, module: &Option<String>, out: &mut BTreeMap<String, String>) {
        match tree {
            syn::UseTree::Path(p) if p.ident == "crate" && module.is_none() => leaves(&p.tree, module, out),
            syn::UseTree::Path(p) => leaves(&p.tree, &Some(module.clone().unwrap_or_else(|| p.ident.to_string())), out),
            syn::UseTree::Name(n) => drop(module.as_ref().map(|m| out.insert(n.ident.to_string(), m.clone()))),
            syn::UseTree::Rename(r) => drop(module.as_ref().map(|m| out.insert(r.rename.to_string(), m.clone()))),
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| leaves(t, module, out)),
            syn::UseTree::Glob(_) => {}
        }
    }
    let mut out = BTreeMap::new();
    for item in &lib.items {
        if let syn::Item::Use(u) = item {
            leaves(&u.tree, &None, &mut out);
        }
    }
    out
}

/// Top-level module of each source file of `src`, and the top-level modules it names.
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
    let top = |f: &Path| f.strip_prefix(src).unwrap().components().next().unwrap().as_os_str().to_string_lossy().trim_end_matches(".rs").to_string();
    let modules: BTreeSet<String> = files.iter().map(|f| top(f)).collect();
    let lib = syn::parse_file(&std::fs::read_to_string(src.join("lib.rs")).unwrap()).unwrap();
    let reexports = root_reexports(&lib);
    for f in &files {
        let rel = f.strip_prefix(src).unwrap();
        let module = rel.components().next().unwrap().as_os_str().to_string_lossy().trim_end_matches(".rs").to_string();
        if module == "lib" {
            continue;
        }
        let file = syn::parse_file(&std::fs::read_to_string(f).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let uses = graph.entry(module.clone()).or_default();
        // A module, or an item the root re-exports from one; not the crate root's own items.
        let named = crate_paths(&file).into_iter().filter_map(|n| if modules.contains(&n) { Some(n) } else { reexports.get(&n).cloned() });
        uses.extend(named.filter(|m| *m != module && modules.contains(m)));
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

#[test]
fn the_reader_sees_grouped_imports_paths_and_macros() {
    let file: syn::File = syn::parse_str(
        "use crate::{alpha, beta::Gamma, delta::{self, x}};\n\
         use std::fmt;\n\
         fn f() { crate::epsilon::go(); let _ = format!(\"{}\", crate::zeta::Z); }\n\
         /// [crate::eta] is a doc link, not an import\n\
         fn g() {}",
    )
    .unwrap();
    let names: Vec<String> = crate_paths(&file).into_iter().collect();
    assert_eq!(names, ["alpha", "beta", "delta", "epsilon", "zeta"]);
    let lib: syn::File = syn::parse_str("pub use crate::settings::{Job, Settings as S};\npub use textures::Baker;\npub use glam;").unwrap();
    let map = root_reexports(&lib);
    assert_eq!(map.get("S").map(String::as_str), Some("settings"));
    assert_eq!(map.get("Job").map(String::as_str), Some("settings"));
    assert_eq!(map.get("Baker").map(String::as_str), Some("textures"));
    // And a circle closed through a grouped import is found.
    let mut graph = BTreeMap::new();
    graph.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    graph.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert!(cycle(&graph).is_some());
}

#[test]
fn the_executors_take_a_job_not_settings_and_settings_know_no_file_format() {
    let graph = module_graph(&root().join("splitsum").join("src"));
    for (from, to) in [("backend", "settings"), ("settings", "ktx2"), ("settings", "textures"), ("bake", "ktx2")] {
        let edges = &graph[from];
        assert!(!edges.contains(to), "splitsum: {from} imports {to}; it must not (ARCHITECTURE.md)");
    }
}
