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

/// The cell of a generated figures table (`book/src/figures/FILE`): the row that begins
/// with `row` (after its bar, backticks aside), the column headed `column`, trimmed, bold marks dropped.
fn figure_cell(file: &str, row: &str, column: &str) -> String {
    let text = std::fs::read_to_string(root().join("book/src/figures").join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let cells = |line: &str| -> Vec<String> { line.split('|').map(|c| c.trim().trim_matches('*').to_string()).collect() };
    let header = cells(text.lines().find(|l| l.starts_with("| ")).unwrap_or_else(|| panic!("{file}: no table")));
    let k = header.iter().position(|h| h == column).unwrap_or_else(|| panic!("{file}: no column {column:?} in {header:?}"));
    // Rows are named without their code marks (a command's backticks).
    let line = text.lines().find(|l| l.replace('`', "").starts_with(&format!("| {row}"))).unwrap_or_else(|| panic!("{file}: no row {row:?}"));
    cells(line)[k].clone()
}

/// Every figure the README quotes is a cell of a generated file (`book/src/figures/`,
/// written by `bash scripts/dev.sh figures` with its command, date, machine and commit),
/// named by the comment right after it: `VALUE<!-- figure: FILE | ROW | COLUMN -->`, the
/// value a number with an optional unit (`%`, `s`, `MiB`), bold or not (in a table's cell
/// ` ¦ ` separates the three, where a bar would end the cell). The test fails on a quote
/// that differs from its cell; `SPLITSUM_BLESS=1` rewrites the quotes instead.
#[test]
fn the_readmes_figures_are_the_generated_ones() {
    let path = root().join("README.md");
    let text = std::fs::read_to_string(&path).unwrap();
    const MARK: &str = "<!-- figure: ";
    let (mut out, mut rest, mut quotes, mut wrong) = (String::new(), text.as_str(), 0, Vec::new());
    while let Some(at) = rest.find(MARK) {
        let (before, after) = rest.split_at(at);
        let end = after.find(" -->").expect("a figure comment ends");
        let inner = &after[MARK.len()..end];
        let spec: Vec<&str> = inner.split(if inner.contains(" ¦ ") { " ¦ " } else { " | " }).collect();
        assert_eq!(spec.len(), 3, "figure comment {:?}: FILE | ROW | COLUMN", &after[..end]);
        // The quote before the comment: `**`? number, then an optional unit, then `**`?.
        let body = before.strip_suffix("**").unwrap_or(before);
        let unit = [" %", " s", " MiB"].into_iter().find(|u| body.ends_with(u)).unwrap_or("");
        let number = body[..body.len() - unit.len()].chars().rev().take_while(|c| c.is_ascii_digit() || *c == '.').count();
        let start = body.len() - unit.len() - number;
        assert!(number > 0, "no number before {:?}", &after[..end]);
        let quoted = &body[start..];
        let cell = figure_cell(spec[0], spec[1], spec[2]);
        if quoted != cell {
            wrong.push(format!("{} | {} | {}: README says {quoted:?}, the file {cell:?}", spec[0], spec[1], spec[2]));
        }
        out.push_str(&before[..start]);
        out.push_str(&cell);
        out.push_str(&before[start + quoted.len()..]);
        out.push_str(&after[..end + 4]);
        rest = &after[end + 4..];
        quotes += 1;
    }
    out.push_str(rest);
    assert!(quotes >= 11, "the README quotes {quotes} generated figures, fewer than its three headline figures need");
    if std::env::var_os("SPLITSUM_BLESS").is_some() {
        std::fs::write(&path, out).unwrap();
    } else {
        assert!(wrong.is_empty(), "README.md differs from the generated figures (SPLITSUM_BLESS=1 rewrites it):\n{}", wrong.join("\n"));
    }
}
