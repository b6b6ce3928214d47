//! The README and the guide (`book/`, built with mdBook by `bash scripts/dev.sh book`):
//! the command-line chapter is what `runner --help` prints, every relative link and image
//! resolves, every chapter is in the summary, the README's library snippet is a piece of
//! the compiled example, and the README stays short.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `book/src/cli.md` is `runner::cli::reference_markdown()`, the help of every subcommand
/// rendered from the clap definitions; `SPLITSUM_BLESS=1` rewrites it.
#[test]
fn the_cli_chapter_is_the_programs_help() {
    let path = root().join("book/src/cli.md");
    let want = runner::cli::reference_markdown();
    if std::env::var_os("SPLITSUM_BLESS").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let got = std::fs::read_to_string(&path).unwrap_or_default();
    if got != want {
        let first = got.lines().zip(want.lines()).position(|(a, b)| a != b).unwrap_or(got.lines().count().min(want.lines().count()));
        panic!(
            "book/src/cli.md differs from the program's help from line {} (`{}` against `{}`): rerun with SPLITSUM_BLESS=1",
            first + 1,
            got.lines().nth(first).unwrap_or(""),
            want.lines().nth(first).unwrap_or("")
        );
    }
}

/// The targets of `[text](target)` and `![alt](target)` in `text`, outside code spans and
/// fenced blocks.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop code spans: a link inside backticks is text.
        let plain: String = line.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        let mut rest = plain.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let end = after.find(')').unwrap_or(after.len());
            out.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    out
}

/// Every relative link of the README and of each chapter (with what it includes) names a
/// file that exists, and an anchor into a chapter names one of its headings; the web
/// addresses are not fetched (CI has no network beyond the registries).
#[test]
fn every_link_of_the_readme_and_the_guide_resolves() {
    let root = root();
    let src = root.join("book/src");
    let mut pages: Vec<PathBuf> = std::fs::read_dir(&src).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "md")).collect();
    pages.sort();
    let mut broken = Vec::new();
    let check = |page: &Path, text: &str, base: &Path, broken: &mut Vec<String>| {
        for link in links(text) {
            if link.starts_with("http://") || link.starts_with("https://") || link.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() { page.to_path_buf() } else { base.join(file) };
            if !target.exists() {
                broken.push(format!("{}: {link}", page.display()));
                continue;
            }
            if !anchor.is_empty() && target.extension().is_some_and(|e| e == "md") {
                let text = expand(&target);
                if !headings(&text).contains(anchor) {
                    broken.push(format!("{}: {link} (no such heading)", page.display()));
                }
            }
        }
    };
    let readme = root.join("README.md");
    check(&readme, &std::fs::read_to_string(&readme).unwrap(), &root, &mut broken);
    for page in &pages {
        check(page, &expand(page), &src, &mut broken);
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));

    // Every chapter is in the summary, and the summary names no missing file.
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<String> = links(&summary).into_iter().collect();
    for page in &pages {
        let name = page.file_name().unwrap().to_string_lossy().to_string();
        assert!(name == "SUMMARY.md" || listed.contains(&name), "book/src/{name} is not in SUMMARY.md");
    }
}

/// A chapter's text with its `{{#include PATH}}` lines replaced by the file they name.
fn expand(page: &Path) -> String {
    let text = std::fs::read_to_string(page).unwrap();
    text.lines()
        .map(|line| match line.trim().strip_prefix("{{#include ").and_then(|l| l.strip_suffix("}}")) {
            Some(path) => {
                std::fs::read_to_string(page.parent().unwrap().join(path.trim())).unwrap_or_else(|e| panic!("{}: {{{{#include {path}}}}}: {e}", page.display()))
            }
            None => line.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The anchors mdBook gives the headings of `text`: lower case, letters, digits, `-` and
/// `_` kept, spaces as `-`, the rest dropped.
fn headings(text: &str) -> BTreeSet<String> {
    let mut fenced = false;
    text.lines()
        .filter(|l| {
            if l.trim_start().starts_with("```") {
                fenced = !fenced;
            }
            !fenced && l.starts_with('#')
        })
        .map(|l| {
            l.trim_start_matches('#')
                .trim()
                .chars()
                .filter_map(|c| match c {
                    ' ' => Some('-'),
                    c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_ascii_lowercase()),
                    _ => None,
                })
                .collect()
        })
        .collect()
}

/// The README's library snippet is lines of `splitsum/examples/bake.rs`, which the crate
/// documentation compiles as a doc test and CI builds: the snippet compiles because the
/// example does. Each snippet line, trimmed, is a line of the example, in the example's order.
#[test]
fn the_readmes_snippet_is_the_compiled_example() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme.find("```rust\n").expect("a Rust snippet in the README") + "```rust\n".len();
    let snippet = &readme[start..start + readme[start..].find("```").unwrap()];
    let example = std::fs::read_to_string(root().join("splitsum/examples/bake.rs")).unwrap();
    let lines: Vec<&str> = example.lines().map(str::trim).collect();
    let mut at = 0;
    for line in snippet.lines().map(str::trim).filter(|l| !l.is_empty()) {
        match lines[at..].iter().position(|l| *l == line) {
            Some(i) => at += i + 1,
            None => panic!("README snippet line `{line}` is not in splitsum/examples/bake.rs (after line {at})"),
        }
    }
}

/// At most 200 lines: what splitsum is, the commands, the library in one snippet, the
/// targets, three figures, the links; the rest is the guide's.
#[test]
fn the_readme_is_short() {
    let n = std::fs::read_to_string(root().join("README.md")).unwrap().lines().count();
    assert!(n <= 200, "README.md has {n} lines");
}

/// The README's accuracy figures are those of `book/src/figures/sets.md`, which
/// `runner report ENV --sets` writes (`figures.md`, with its date, machine and commit) and
/// the accuracy chapter includes: held out, the defaults over every point, at `n·v ≥ 0.6`
/// and at `n·v ≤ 0.1`, 16 fetches, and the seed's settings.
#[test]
fn the_readmes_accuracy_figures_are_the_generated_ones() {
    let figures = std::fs::read_to_string(root().join("book/src/figures/sets.md")).unwrap();
    let header: Vec<&str> = figures.lines().find(|l| l.starts_with("| method |")).expect("the table's header").split('|').map(str::trim).collect();
    let cell = |method: &str, column: &str| -> String {
        let row: Vec<&str> =
            figures.lines().find(|l| l.starts_with(&format!("| {method}"))).unwrap_or_else(|| panic!("no row {method}")).split('|').map(str::trim).collect();
        let k = header.iter().position(|h| *h == column).unwrap_or_else(|| panic!("no column {column}"));
        row[k].to_string()
    };
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap().replace('\n', " ");
    for (method, column) in [
        ("defaults (one fetch)", "held-out set: all"),
        ("defaults (one fetch)", "held-out set: n·v 0.6–1"),
        ("defaults (one fetch)", "held-out set: ≤ 0.1"),
        ("defaults, 16 fetches", "held-out set: all"),
        ("seed", "held-out set: all"),
    ] {
        let figure = cell(method, column);
        assert!(readme.contains(&figure), "README.md does not quote {method}, {column}: {figure}");
    }
}
