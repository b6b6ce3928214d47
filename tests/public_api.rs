//! The library's face, as a committed list (`splitsum/public-api.txt`): every item an
//! application can name from `splitsum` without features, and the public methods and
//! associated constants of its types (issue 32). Any change to it is deliberate: this test
//! fails with the difference until the list is rewritten (`SPLITSUM_BLESS=1` rewrites it).
//!
//! The walk reads the sources with `syn`, from `lib.rs` through every `pub mod` and `pub
//! use`: an item counts where a path names it (a re-export counts at each path it is
//! public at). Items behind a feature (`internals`, `embedded-environment`), `doc(hidden)`
//! or `wasm32` are left out; modules the `internal_modules!` macro declares are private
//! without `internals`, so nothing in them counts unless re-exported.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../splitsum/src")
}

/// Whether `attrs` leave the item out of a build without features on a native target.
fn left_out(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        let text = quote_attr(a);
        (a.path().is_ident("cfg")
            && (text.contains("feature =") && !text.contains("not (feature")
                || text.contains("target_arch = \"wasm32\"") && !text.contains("not (target_arch")))
            || (a.path().is_ident("doc") && text.contains("hidden"))
    })
}

fn quote_attr(a: &syn::Attribute) -> String {
    match &a.meta {
        syn::Meta::List(l) => l.tokens.to_string(),
        _ => String::new(),
    }
}

fn is_pub(v: &syn::Visibility) -> bool {
    matches!(v, syn::Visibility::Public(_))
}

/// A module's file: `dir/name.rs` or `dir/name/mod.rs`, with the folder its children live in.
fn module_file(dir: &Path, name: &str) -> (PathBuf, PathBuf) {
    let flat = dir.join(format!("{name}.rs"));
    if flat.exists() { (flat, dir.join(name)) } else { (dir.join(name).join("mod.rs"), dir.join(name)) }
}

/// Every module of the crate (public or not), by path, with its items: what `pub use`
/// resolves against.
fn modules(dir: &Path, path: &str, items: Vec<syn::Item>, out: &mut BTreeMap<String, Vec<syn::Item>>) {
    for item in &items {
        if let syn::Item::Mod(m) = item {
            if left_out(&m.attrs) && !is_pub(&m.vis) {
                continue;
            }
            let child = format!("{path}::{}", m.ident);
            match &m.content {
                Some((_, inner)) => modules(dir, &child, inner.clone(), out),
                None => {
                    let (file, sub) = module_file(dir, &m.ident.to_string());
                    let parsed = syn::parse_file(&std::fs::read_to_string(&file).unwrap()).unwrap();
                    modules(&sub, &child, parsed.items, out);
                }
            }
        }
        // `internal_modules! { a; b; }`: private modules without the feature.
        if let syn::Item::Macro(m) = item
            && m.mac.path.is_ident("internal_modules")
        {
            for name in m.mac.tokens.to_string().split(';').map(|s| s.split_whitespace().last().unwrap_or("").to_string()).filter(|s| !s.is_empty()) {
                let (file, sub) = module_file(dir, &name);
                let parsed = syn::parse_file(&std::fs::read_to_string(&file).unwrap()).unwrap();
                modules(&sub, &format!("{path}::{name}"), parsed.items, out);
            }
        }
    }
    out.insert(path.to_string(), items);
}

/// What an item is, in the list's words, its name, its visibility and its attributes.
fn describe(item: &syn::Item) -> Option<(&'static str, String, &syn::Visibility, &[syn::Attribute])> {
    Some(match item {
        syn::Item::Struct(i) => ("struct", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Enum(i) => ("enum", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Fn(i) => ("fn", i.sig.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Const(i) => ("const", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Static(i) => ("static", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Type(i) => ("type", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Trait(i) => ("trait", i.ident.to_string(), &i.vis, &i.attrs),
        syn::Item::Mod(i) => ("mod", i.ident.to_string(), &i.vis, &i.attrs),
        _ => return None,
    })
}

/// The public associated items of type `ty` (inherent impls anywhere in the crate).
fn associated(all: &BTreeMap<String, Vec<syn::Item>>, ty: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for items in all.values() {
        for item in items {
            let syn::Item::Impl(i) = item else { continue };
            if i.trait_.is_some() || left_out(&i.attrs) {
                continue;
            }
            let syn::Type::Path(p) = &*i.self_ty else { continue };
            if p.path.segments.last().is_none_or(|s| s.ident != ty) {
                continue;
            }
            for a in &i.items {
                match a {
                    syn::ImplItem::Fn(f) if is_pub(&f.vis) && !left_out(&f.attrs) => {
                        out.insert(format!("fn {}", f.sig.ident));
                    }
                    syn::ImplItem::Const(c) if is_pub(&c.vis) && !left_out(&c.attrs) => {
                        out.insert(format!("const {}", c.ident));
                    }
                    _ => {}
                }
            }
        }
    }
    out
}

/// The public face: `kind path` lines, items first, then each type's associated items.
fn public_api() -> (Vec<String>, Vec<String>) {
    let lib = syn::parse_file(&std::fs::read_to_string(src().join("lib.rs")).unwrap()).unwrap();
    let mut all = BTreeMap::new();
    modules(&src(), "splitsum", lib.items, &mut all);
    let mut items = BTreeSet::new();
    let mut methods = BTreeSet::new();
    // Public modules reachable from the root, walked breadth first.
    let mut queue = vec!["splitsum".to_string()];
    while let Some(module) = queue.pop() {
        for item in &all[&module] {
            if let syn::Item::Use(u) = item {
                if is_pub(&u.vis) && !left_out(&u.attrs) {
                    let mut leaves = Vec::new();
                    use_leaves(&u.tree, String::new(), &mut leaves);
                    for (from, name) in leaves {
                        let (kind, target) = resolve(&all, &module, &from);
                        items.insert(format!("{kind} {module}::{name}"));
                        if let Some(t) = target {
                            for a in associated(&all, &t) {
                                methods.insert(format!("{a} of {module}::{name}"));
                            }
                        }
                    }
                }
                continue;
            }
            let Some((kind, name, vis, attrs)) = describe(item) else { continue };
            if !is_pub(vis) || left_out(attrs) {
                continue;
            }
            items.insert(format!("{kind} {module}::{name}"));
            if kind == "mod" {
                queue.push(format!("{module}::{name}"));
            } else if ["struct", "enum", "trait"].contains(&kind) {
                for a in associated(&all, &name) {
                    methods.insert(format!("{a} of {module}::{name}"));
                }
            }
        }
    }
    (items.into_iter().collect(), methods.into_iter().collect())
}

/// `(path used, name it is public as)` for each leaf of a use tree.
fn use_leaves(tree: &syn::UseTree, prefix: String, out: &mut Vec<(String, String)>) {
    let join = |p: &str, s: &str| if p.is_empty() { s.to_string() } else { format!("{p}::{s}") };
    match tree {
        syn::UseTree::Path(p) => use_leaves(&p.tree, join(&prefix, &p.ident.to_string()), out),
        syn::UseTree::Name(n) => out.push((join(&prefix, &n.ident.to_string()), n.ident.to_string())),
        syn::UseTree::Rename(r) => out.push((join(&prefix, &r.ident.to_string()), r.rename.to_string())),
        syn::UseTree::Group(g) => g.items.iter().for_each(|t| use_leaves(t, prefix.clone(), out)),
        syn::UseTree::Glob(_) => out.push((join(&prefix, "*"), "*".into())),
    }
}

/// The kind of what `path` (as written in a `use` of `module`) names, and its type name
/// when it is a type of this crate; items of other crates are `use`.
fn resolve(all: &BTreeMap<String, Vec<syn::Item>>, module: &str, path: &str) -> (&'static str, Option<String>) {
    let mut segs: Vec<&str> = path.split("::").collect();
    let name = segs.pop().unwrap();
    let base = match segs.first().copied() {
        Some("crate") => std::iter::once("splitsum").chain(segs[1..].iter().copied()).collect::<Vec<_>>().join("::"),
        Some("self") => std::iter::once(module).chain(segs[1..].iter().copied()).collect::<Vec<_>>().join("::"),
        Some("super") => {
            let parent = module.rsplit_once("::").map(|p| p.0).unwrap_or(module);
            std::iter::once(parent).chain(segs[1..].iter().copied()).collect::<Vec<_>>().join("::")
        }
        Some(first) if all.contains_key(&format!("{module}::{first}")) => std::iter::once(module).chain(segs.iter().copied()).collect::<Vec<_>>().join("::"),
        Some(first) if all.contains_key(&format!("splitsum::{first}")) => {
            std::iter::once("splitsum").chain(segs.iter().copied()).collect::<Vec<_>>().join("::")
        }
        _ => return ("use", None),
    };
    let Some(items) = all.get(&base) else { return ("use", None) };
    // A definition first (a module may also import a name it defines, as `thiserror::Error`
    // beside `enum Error`), then what the module itself imports.
    for item in items {
        if let Some((kind, n, _, _)) = describe(item)
            && n == name
        {
            return (kind, ["struct", "enum", "trait"].contains(&kind).then(|| n.clone()));
        }
    }
    for item in items {
        if let syn::Item::Use(u) = item {
            let mut leaves = Vec::new();
            use_leaves(&u.tree, String::new(), &mut leaves);
            if let Some((from, _)) = leaves.iter().find(|(_, n)| n == name) {
                return resolve(all, &base, from);
            }
        }
    }
    ("use", None)
}

/// The committed list's path.
fn listed() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../splitsum/public-api.txt")
}

fn render(items: &[String], methods: &[String]) -> String {
    let mut s = String::from(
        "# What an application can name from `splitsum` without features (tests/public_api.rs\n\
         # writes and checks this file: `SPLITSUM_BLESS=1 cargo test --release -p splitsum-tests\n\
         # --test suite public_api` after a deliberate change).\n",
    );
    s += &format!("# {} items\n", items.len());
    for i in items {
        s += i;
        s.push('\n');
    }
    s += &format!("# {} associated items of those types\n", methods.len());
    for m in methods {
        s += m;
        s.push('\n');
    }
    s
}

#[test]
fn the_public_api_is_the_committed_list() {
    let (items, methods) = public_api();
    let now = render(&items, &methods);
    println!("{} public items, {} associated items", items.len(), methods.len());
    if std::env::var_os("SPLITSUM_BLESS").is_some() {
        std::fs::write(listed(), &now).unwrap();
        return;
    }
    let was = std::fs::read_to_string(listed()).unwrap_or_default();
    let (a, b): (BTreeSet<&str>, BTreeSet<&str>) =
        (was.lines().filter(|l| !l.starts_with('#')).collect(), now.lines().filter(|l| !l.starts_with('#')).collect());
    let gone: Vec<_> = a.difference(&b).collect();
    let new: Vec<_> = b.difference(&a).collect();
    assert!(
        gone.is_empty() && new.is_empty(),
        "the public API changed; if on purpose, run with SPLITSUM_BLESS=1 and commit splitsum/public-api.txt\nremoved: {gone:#?}\nadded: {new:#?}"
    );
}

#[test]
fn the_walk_sees_modules_reexports_and_features() {
    let (items, methods) = public_api();
    // The root's re-export of a type from a private module, a public module's own item, a
    // feature-gated item left out, and a method of a public type.
    assert!(items.iter().any(|i| i == "struct splitsum::Baker"), "{items:#?}");
    assert!(items.iter().any(|i| i == "fn splitsum::environment::load"), "{items:#?}");
    assert!(!items.iter().any(|i| i.contains("EMBEDDED_DEFAULT")));
    assert!(!items.iter().any(|i| i.contains("splitsum::cache")));
    assert!(methods.iter().any(|m| m == "fn resolve of splitsum::Settings"), "{methods:#?}");
}
