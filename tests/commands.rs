//! Every command the README, the guide (`book/src`) and the scripts name runs as written (issue 31): each is
//! taken from the text (fenced shell blocks, inline code, the scripts' usage lines), its
//! placeholders filled in, and checked without doing the work:
//! - `runner …` (or `target/release/runner …`, `cargo run -p runner -- …`): parsed by the
//!   runner's own clap definition, exactly as `runner` parses it;
//! - `bash scripts/X.sh …`: run with `SPLITSUM_DRY_RUN=1`, which prints each command the
//!   script would run instead of running it (and installs nothing); it must exit 0, and
//!   every command it prints is checked in turn;
//! - `cargo …`: its package, test target, example, features and paths must exist, and the
//!   test names it filters by or skips must match tests of this suite (listed by running
//!   this very binary with `--list`).

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The commands a text names: lines of fenced shell blocks (`sh`, `bash`, `console`) and
/// inline code spans (which may run over a line break) that start with `bash scripts/`,
/// `runner `, `target/release/runner ` or `cargo `, and a script's usage lines
/// (`#   bash scripts/…`).
fn commands_in(text: &str) -> Vec<String> {
    let starts = ["bash scripts/", "runner ", "target/release/runner ", "cargo "];
    let wanted = |c: &str| starts.iter().any(|s| c.starts_with(s));
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    let mut prose = String::new();
    for line in text.lines() {
        let t = line.trim();
        if let Some(tag) = t.strip_prefix("```") {
            fence = if fence.is_some() { None } else { Some(tag.to_string()) };
            prose.push('\n');
            continue;
        }
        match &fence {
            Some(tag) => {
                let c = t.split(" #").next().unwrap_or("").trim();
                if ["sh", "bash", "console"].contains(&tag.as_str()) && wanted(c) {
                    out.push(c.to_string());
                }
            }
            None => {
                if let Some(c) = t.strip_prefix('#').map(str::trim)
                    && c.starts_with("bash scripts/")
                {
                    out.push(c.split(" #").next().unwrap_or(c).trim().to_string());
                }
                prose.push_str(t);
                prose.push(' ');
            }
        }
    }
    for (k, span) in prose.split('`').enumerate() {
        let span = span.split_whitespace().collect::<Vec<_>>().join(" ");
        if k % 2 == 1 && wanted(&span) {
            out.push(span);
        }
    }
    out
}

/// A command's words with its placeholders filled in: optional parts (`[--model M.glb]`)
/// kept, alternatives (`khronos|bevy|filament`) the first, `…` dropped, and the names of
/// files and values replaced by real ones.
fn words(command: &str, env: &str) -> Vec<String> {
    let mut out = Vec::new();
    for w in command.replace(['[', ']'], " ").split_whitespace() {
        let w = w.split('|').next().unwrap_or(w);
        let w = match w {
            "…" | "..." => continue,
            "ENV" | "A.exr" | "B.exr" | "sky.hdr" | "X.hdr" => env.to_string(),
            "SCENE" => "scenes/brushed-metal.toml".into(),
            "DIR" => "out".into(),
            "M.glb" => "display/assets/torus.glb".into(),
            "SECONDS" | "SPP" | "RES" | "W" | "H" => "1".into(),
            "ARGS..." | "ARGS" | "SUBCOMMAND" => "--help".into(),
            w => w.to_string(),
        };
        out.push(w);
    }
    out
}

/// Checks `runner` arguments with the runner's own parser.
fn check_runner(args: &[String], said: &str) -> Result<(), String> {
    let mut argv = vec!["runner".to_string()];
    argv.extend(args.iter().cloned());
    use clap::error::ErrorKind;
    match runner::cli::parses(&argv) {
        Ok(()) => Ok(()),
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => Ok(()),
        // The prose names a subcommand or a flag (`runner bench`, `runner bake --budget`):
        // every word given parsed, and only what follows is missing.
        Err(e) if e.kind() == ErrorKind::MissingRequiredArgument => Ok(()),
        Err(e) if e.kind() == ErrorKind::InvalidValue && args.last().is_some_and(|w| w.starts_with("--")) && e.to_string().contains("a value is required") => {
            Ok(())
        }
        Err(e) => Err(format!("{said}: runner {}: {}", args.join(" "), e.render())),
    }
}

/// The names of this suite's tests, ignored ones included.
fn suite_tests() -> &'static Vec<String> {
    static TESTS: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    TESTS.get_or_init(|| {
        let o = std::process::Command::new(std::env::current_exe().unwrap()).args(["--list", "--include-ignored"]).output().unwrap();
        String::from_utf8_lossy(&o.stdout).lines().filter_map(|l| l.strip_suffix(": test")).map(str::to_string).collect()
    })
}

/// A workspace package's folder.
fn package_dir(name: &str) -> Option<PathBuf> {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let members: toml::Value = toml::from_str(&manifest).unwrap();
    members["workspace"]["members"].as_array().unwrap().iter().map(|m| root().join(m.as_str().unwrap())).find(|dir| {
        let cargo: toml::Value = toml::from_str(&std::fs::read_to_string(dir.join("Cargo.toml")).unwrap()).unwrap();
        cargo["package"]["name"].as_str() == Some(name)
    })
}

/// Checks a `cargo` command: what it names must exist, and a test run's filters must
/// match tests of this suite.
fn check_cargo(args: &[String], said: &str) -> Result<(), String> {
    let fail = |why: String| Err(format!("{said}: cargo {}: {why}", args.join(" ")));
    let mut a = args.iter().map(String::as_str).filter(|w| !w.starts_with('+')).peekable();
    let sub = a.next().unwrap_or_default();
    let mut package = "runner".to_string();
    let mut manifest = None;
    let (mut test, mut example, mut features, mut rest) = (None, None, Vec::new(), Vec::new());
    let mut after = Vec::new();
    while let Some(w) = a.next() {
        match w {
            "-p" | "--package" => package = a.next().unwrap_or_default().to_string(),
            "--test" => test = a.next().map(str::to_string),
            "--example" => example = a.next().map(str::to_string),
            "--features" => features.extend(a.next().unwrap_or_default().split(',').map(str::to_string)),
            "--path" | "--manifest-path" => {
                let p = a.next().unwrap_or_default();
                if !root().join(p).exists() {
                    return fail(format!("{p} does not exist"));
                }
                if w == "--manifest-path" {
                    manifest = Some(p.to_string());
                }
            }
            "--" => {
                after = a.by_ref().map(str::to_string).collect();
            }
            w if w.starts_with('-') => {}
            w => rest.push(w.to_string()),
        }
    }
    if manifest.is_some() {
        // Another workspace (xtask): its path exists; what it runs is its own.
        return Ok(());
    }
    let Some(dir) = package_dir(&package) else { return fail(format!("no package {package} in the workspace")) };
    let cargo: toml::Value = toml::from_str(&std::fs::read_to_string(dir.join("Cargo.toml")).unwrap()).unwrap();
    for f in &features {
        if cargo.get("features").and_then(|t| t.get(f)).is_none() {
            return fail(format!("package {package} has no feature {f}"));
        }
    }
    if let Some(e) = &example
        && !dir.join("examples").join(format!("{e}.rs")).exists()
    {
        return fail(format!("package {package} has no example {e}"));
    }
    if let Some(t) = &test {
        let declared = cargo.get("test").and_then(|t| t.as_array()).is_some_and(|ts| ts.iter().any(|x| x["name"].as_str() == Some(t)));
        if !declared && !dir.join("tests").join(format!("{t}.rs")).exists() {
            return fail(format!("package {package} has no test target {t}"));
        }
    }
    match sub {
        "run" if package == "runner" && example.is_none() => check_runner(&after, said),
        "test" if package == "splitsum-tests" && test.as_deref() == Some("suite") => {
            // Filters before `--` and after it (but for flags and their values), and skips.
            let mut filters = rest.clone();
            let mut skips = Vec::new();
            let mut it = after.iter();
            while let Some(w) = it.next() {
                match w.as_str() {
                    "--skip" => skips.extend(it.next().cloned()),
                    w if w.starts_with('-') => {}
                    w => filters.push(w.to_string()),
                }
            }
            for f in filters.iter().chain(&skips) {
                if !suite_tests().iter().any(|t| t.contains(f.as_str())) {
                    return fail(format!("no test of the suite matches {f:?}"));
                }
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Checks one command, as written in `said` (the file and the text).
fn check(words: &[String], said: &str) -> Result<(), String> {
    let mut w: Vec<&str> = words.iter().map(String::as_str).collect();
    // `env K=V … COMMAND`, as the scripts print their commands.
    if w.first() == Some(&"env") {
        w.remove(0);
        while w.first().is_some_and(|x| x.contains('=')) {
            w.remove(0);
        }
    }
    let rest: Vec<String> = w.iter().skip(1).map(|s| s.to_string()).collect();
    match w.first().copied() {
        Some("runner") | Some("target/release/runner") => check_runner(&rest, said),
        Some("cargo") => check_cargo(&rest, said),
        Some("bash") => {
            let script = rest.first().cloned().unwrap_or_default();
            if !root().join(&script).is_file() {
                return Err(format!("{said}: {script} does not exist"));
            }
            let o = std::process::Command::new("bash").current_dir(root()).args(&rest).env("SPLITSUM_DRY_RUN", "1").output().unwrap();
            let printed = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
            if !o.status.success() {
                return Err(format!("{said}: bash {} exits {:?} in a dry run:\n{printed}", rest.join(" "), o.status.code()));
            }
            for line in printed.lines().filter_map(|l| l.strip_prefix("dry-run: ")) {
                // The scripts print with `printf %q`: split as the shell would.
                let Some(inner) = shlex::split(line) else {
                    return Err(format!("{said}, via {script}: does not split as shell words: {line}"));
                };
                check(&inner, &format!("{said}, via {script}"))?;
            }
            Ok(())
        }
        Some(p) if p.ends_with("/python") || p.ends_with("python3") => {
            let script = rest.first().cloned().unwrap_or_default();
            if root().join(&script).is_file() { Ok(()) } else { Err(format!("{said}: {script} does not exist")) }
        }
        // mdBook on the guide: the folder must hold a book.
        Some(p) if p.ends_with("mdbook") => match rest.get(1) {
            Some(dir) if root().join(dir).join("book.toml").is_file() => Ok(()),
            _ => Err(format!("{said}: mdbook is not given a folder with book.toml")),
        },
        // Folders and copies inside the checkout (the figures the scripts regenerate).
        Some("mkdir") | Some("cp") => match rest.iter().find(|a| !a.starts_with('-') && !inside_checkout(a)) {
            None => Ok(()),
            Some(a) => Err(format!("{said}: {a} is not a path inside the checkout")),
        },
        // One of the workspace's examples, built by an earlier command of the script.
        Some(p) if p.starts_with("target/release/examples/") => {
            let name = &p["target/release/examples/".len()..];
            let found = std::fs::read_dir(root()).unwrap().flatten().any(|c| c.path().join("examples").join(format!("{name}.rs")).is_file());
            if found { Ok(()) } else { Err(format!("{said}: no example is named {name}")) }
        }
        other => Err(format!("{said}: not a command this test knows: {other:?}")),
    }
}

/// A relative path with no `..` that stays in the checkout once its folders exist.
fn inside_checkout(path: &str) -> bool {
    let p = std::path::Path::new(path);
    p.is_relative() && p.components().all(|c| matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir))
}

#[test]
fn every_command_in_the_readme_and_the_scripts_runs_as_written() {
    let env = root().join("splitsum/assets/courtyard.exr").to_string_lossy().into_owned();
    let mut sources: Vec<PathBuf> = vec![root().join("README.md"), root().join("ARCHITECTURE.md")];
    for d in ["docs", "scripts", "book/src"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(d)).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        sources.extend(files.into_iter().filter(|p| p.extension().is_some_and(|e| e == "md" || e == "sh")));
    }
    let (mut checked, mut failures) = (0, Vec::new());
    for path in &sources {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.strip_prefix(root()).unwrap_or(path).display().to_string();
        for c in commands_in(&text) {
            checked += 1;
            if let Err(e) = check(&words(&c, &env), &format!("{name}: `{c}`")) {
                failures.push(e);
            }
        }
    }
    println!("{checked} commands checked in {} files", sources.len());
    assert!(checked > 40, "only {checked} commands found: is the extraction broken?");
    assert!(failures.is_empty(), "{} commands do not run as written:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn placeholders_are_filled_and_alternatives_take_the_first() {
    assert_eq!(words("runner view [ENV] [--model M.glb]", "e.exr"), ["runner", "view", "e.exr", "--model", "display/assets/torus.glb"]);
    assert_eq!(words("runner bake ENV --target khronos|bevy|filament", "e.exr"), ["runner", "bake", "e.exr", "--target", "khronos"]);
    assert_eq!(words("runner bake A.exr B.exr … --out DIR", "e"), ["runner", "bake", "e", "e", "--out", "out"]);
    assert!(check(&words("runner bake ENV --no-such-flag", "e"), "t").is_err());
    assert!(check(&words("cargo test --release -p splitsum-tests --test no_such_target", "e"), "t").is_err());
    assert!(check(&words("cargo test --release -p splitsum-tests --test suite no_such_test_name", "e"), "t").is_err());
    assert!(check(&words("bash scripts/dev.sh no-such-subcommand", "e"), "t").is_err());
}
