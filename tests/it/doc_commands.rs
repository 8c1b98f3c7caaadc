//! The commands in the documentation run as written. Every ```` ```console ```` block of
//! README.md and docs/*.md is executed in a scratch copy of the repository's inputs
//! (`experiments/`, `results/`, `figures/`), with the built `signorini` first on PATH, and the
//! output of each command is held against the lines the block shows after it.
//!
//! A small runner of our own rather than trycmd: the blocks need a shell (a `cd`, a `&&`, the
//! working directory at the repository's top for a page under docs/), and trycmd runs each
//! command without one, in the Markdown file's own folder unless a configuration file sits
//! beside every page.
//!
//! The format of a block:
//! * a line `$ COMMAND` is run by bash in the scratch folder (a line ending in `\` continues on
//!   the next), its standard output and error together;
//! * the lines up to the next `$` are what it must print: each line equal to one printed line
//!   (trailing spaces aside), where `[..]` inside a line matches any text and a line `...`
//!   matches any number of lines; no lines means the output is not checked;
//! * the command must exit 0.
//!
//! Progress lines are switched off (`SIGNORINI_PROGRESS=off`): a step slower than 10 s prints
//! one, so whether they appear depends on the machine's speed, not on the command.

use crate::common::copy_dir;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// One command of a block and the lines it must print.
#[derive(Debug)]
struct Case {
    page: String,
    line: usize,
    command: String,
    expected: Vec<String>,
}

/// The `console` blocks of one Markdown page, as cases.
fn cases(page: &Path) -> Vec<Case> {
    let text = std::fs::read_to_string(page).unwrap();
    let name = page.strip_prefix(repo()).unwrap_or(page).display().to_string();
    let mut out: Vec<Case> = Vec::new();
    let mut in_block = false;
    let mut lines = text.lines().enumerate().peekable();
    while let Some((i, l)) = lines.next() {
        let fence = l.trim_start().starts_with("```");
        match (in_block, fence) {
            (false, true) => in_block = l.trim() == "```console",
            (true, true) => in_block = false,
            (true, false) => match l.strip_prefix("$ ") {
                Some(cmd) => {
                    let mut command = cmd.to_string();
                    while command.ends_with('\\') {
                        command.pop();
                        command.push_str(lines.next().map_or("", |(_, n)| n));
                    }
                    out.push(Case { page: name.clone(), line: i + 1, command, expected: Vec::new() });
                }
                None => match out.last_mut() {
                    Some(case) => case.expected.push(l.trim_end().to_string()),
                    None => panic!("{name}:{}: a console block must start with a `$ ` command line", i + 1),
                },
            },
            (false, false) => {}
        }
    }
    out
}

/// Does `line` match `pattern`, where `[..]` matches any text?
fn line_matches(pattern: &str, line: &str) -> bool {
    let parts: Vec<&str> = pattern.split("[..]").collect();
    if parts.len() == 1 {
        return pattern == line;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if !line.starts_with(first) || !line[first.len()..].ends_with(last) || line.len() < first.len() + last.len() {
        return false;
    }
    let mut rest = &line[first.len()..line.len() - last.len()];
    for p in &parts[1..parts.len() - 1] {
        match rest.find(p) {
            Some(at) => rest = &rest[at + p.len()..],
            None => return false,
        }
    }
    true
}

/// Do the printed lines match the expected ones (`...` matching any number of lines)?
fn output_matches(expected: &[String], printed: &[&str]) -> bool {
    match expected.split_first() {
        None => printed.is_empty(),
        Some((e, rest)) if e == "..." => (0..=printed.len()).any(|skip| output_matches(rest, &printed[skip..])),
        Some((e, rest)) => printed.first().is_some_and(|p| line_matches(e, p.trim_end()) && output_matches(rest, &printed[1..])),
    }
}

/// A scratch copy of what the documented commands read.
fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-doc-commands-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for d in ["experiments", "results", "figures"] {
        copy_dir(&repo().join(d), &dir.join(d));
    }
    std::fs::create_dir_all(dir.join("target")).unwrap();
    dir
}

fn pages() -> Vec<PathBuf> {
    let mut pages = vec![repo().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(repo().join("docs")).unwrap().flatten().map(|e| e.path()).collect();
    docs.retain(|p| p.extension().is_some_and(|e| e == "md"));
    docs.sort();
    pages.extend(docs);
    pages
}

#[test]
fn the_runner_matches_what_it_should() {
    let exp = |s: &[&str]| s.iter().map(|l| l.to_string()).collect::<Vec<_>>();
    assert!(line_matches("drift: none (1 study [..] at every level[..])", "drift: none (1 study of x compared at every level; y)"));
    assert!(!line_matches("drift: none[..]", "drift: 3 fields moved"));
    assert!(line_matches("a[..]b[..]c", "abc") && !line_matches("a[..]a", "a"));
    assert!(output_matches(&exp(&["...", "last"]), &["one", "two", "last"]));
    assert!(output_matches(&exp(&["first", "..."]), &["first", "two"]));
    assert!(!output_matches(&exp(&["first"]), &["first", "extra"]));
    assert!(!output_matches(&exp(&["...", "missing"]), &["one", "two"]));
}

#[test]
fn every_console_block_in_the_docs_runs_as_written() {
    let all: Vec<Case> = pages().iter().flat_map(|p| cases(p)).collect();
    assert!(all.len() >= 5, "expected the README and docs/ to hold runnable commands, found {}", all.len());
    let dir = scratch();
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_signorini")).parent().unwrap().to_path_buf();
    let path = format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap_or_default());
    let mut failures = Vec::new();
    for case in &all {
        let out = Command::new("bash")
            .arg("-c")
            .arg(format!("exec 2>&1; set -o pipefail; {}", case.command))
            .current_dir(&dir)
            .env("PATH", &path)
            // progress lines come with time (a step slower than 10 s prints one): not part of
            // what a block shows
            .env("SIGNORINI_PROGRESS", "off")
            .output()
            .unwrap();
        let printed = String::from_utf8_lossy(&out.stdout).into_owned();
        let lines: Vec<&str> = printed.lines().collect();
        let checked = case.expected.is_empty() || output_matches(&case.expected, &lines);
        if !out.status.success() || !checked {
            failures.push(format!(
                "{}:{}: `{}` exited with {} and printed:\n{printed}\nexpected:\n{}",
                case.page,
                case.line,
                case.command,
                out.status,
                case.expected.join("\n")
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{} of {} documented commands failed:\n\n{}", failures.len(), all.len(), failures.join("\n\n"));
}
