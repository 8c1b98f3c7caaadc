//! One name, one place, for studies: each study CLAIMS.md and the figures read is named once,
//! in `analysis/studies.rs` (a `Study` constant per study), and every read of a study in
//! `analysis/` and `plot/` goes through it or through a run role (`role.study`). The names the
//! rows and figures give problems are defined once too (`analysis/problem_names.rs`), apart
//! from the studies named after them. Renaming a study's manifest (`experiments/NAME.toml`)
//! then fails here, naming the study, instead of leaving a row or a figure without data.

use signorini::analysis::roles::NEEDED;
use signorini::analysis::{problem_names, studies};
use std::collections::BTreeSet;
use std::path::Path;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The files that define names: study-name literals are written there and nowhere else.
const DEFINITIONS: [&str; 2] = ["crates/claims/src/analysis/studies.rs", "crates/claims/src/analysis/problem_names.rs"];

/// The string literals of Rust source `text` (their contents, unescaped only as far as `\"`),
/// each with its line: comments, char literals and lifetimes are skipped; raw strings are read.
fn string_literals(text: &str) -> Vec<(usize, String)> {
    let c: Vec<char> = text.chars().collect();
    let (mut out, mut i, mut line) = (Vec::new(), 0, 1);
    let newlines = |s: &[char]| s.iter().filter(|&&x| x == '\n').count();
    while i < c.len() {
        let next = c.get(i + 1).copied();
        match c[i] {
            '\n' => line += 1,
            '/' if next == Some('/') => {
                while i < c.len() && c[i] != '\n' {
                    i += 1;
                }
                continue;
            }
            '/' if next == Some('*') => {
                let end = (i + 2..c.len().saturating_sub(1)).find(|&k| c[k] == '*' && c[k + 1] == '/').map_or(c.len(), |k| k + 2);
                line += newlines(&c[i..end]);
                i = end;
                continue;
            }
            '\'' => {
                // a char literal ('x', '\n', '"'), else a lifetime ('a)
                if next == Some('\\') {
                    // past the escaped character: '\'' and '\\' close at i + 3
                    i = (i + 3..c.len()).find(|&k| c[k] == '\'').map_or(c.len(), |k| k + 1);
                    continue;
                }
                if c.get(i + 2) == Some(&'\'') {
                    i += 3;
                    continue;
                }
            }
            'r' if (next == Some('"') || next == Some('#')) && (i == 0 || !(c[i - 1].is_alphanumeric() || c[i - 1] == '_')) => {
                let hashes = c[i + 1..].iter().take_while(|&&x| x == '#').count();
                if c.get(i + 1 + hashes) == Some(&'"') {
                    let start = i + 2 + hashes;
                    let close: String = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
                    let rest: String = c[start..].iter().collect();
                    let len = rest.find(&close).unwrap_or(rest.len());
                    let body: String = c[start..start + rest[..len].chars().count()].iter().collect();
                    out.push((line, body.clone()));
                    line += body.matches('\n').count();
                    i = start + body.chars().count() + close.chars().count();
                    continue;
                }
            }
            '"' => {
                let (start, mut k) = (line, i + 1);
                let mut body = String::new();
                while k < c.len() && c[k] != '"' {
                    if c[k] == '\\' && k + 1 < c.len() {
                        body.push(c[k + 1]);
                        line += usize::from(c[k + 1] == '\n');
                        k += 2;
                        continue;
                    }
                    line += usize::from(c[k] == '\n');
                    body.push(c[k]);
                    k += 1;
                }
                out.push((start, body));
                i = k + 1;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// The studies the repository declares: the stems of `experiments/*.toml`.
fn declared() -> BTreeSet<String> {
    std::fs::read_dir(repo().join("experiments"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// "file:line: "name"" for every literal of `names` in the code of `analysis/` and `plot/`
/// outside [`DEFINITIONS`].
fn literal_uses(names: &BTreeSet<String>) -> Vec<String> {
    let mut files = Vec::new();
    for dir in ["crates/claims/src/analysis", "crates/claims/src/plot"] {
        crate::layers::rust_files(&repo().join(dir), &mut files);
    }
    files.sort();
    let mut found = Vec::new();
    for f in files {
        let rel = f.strip_prefix(repo()).unwrap().to_string_lossy().replace('\\', "/");
        if DEFINITIONS.contains(&rel.as_str()) {
            continue;
        }
        for (line, s) in string_literals(&std::fs::read_to_string(&f).unwrap()) {
            if names.contains(&s) {
                found.push(format!("{rel}:{line}: \"{s}\""));
            }
        }
    }
    found
}

#[test]
fn the_literal_scanner_finds_names_in_code_and_not_in_comments() {
    let text = "let a = shelf.runs(\"ex71\"); // \"deep\"\n/* \"fb\" */ let b = '\"'; let c: &'static str = \"ex71_adaptive\";\nlet d = r#\"hertz\"#; let e = \"a \\\"quoted\\\" c0_sweep\"; f(\"c0_sweep\");";
    let got: Vec<(usize, String)> = string_literals(text);
    let names: Vec<&str> = got.iter().map(|(_, s)| s.as_str()).collect();
    assert_eq!(names, ["ex71", "ex71_adaptive", "hertz", "a \"quoted\" c0_sweep", "c0_sweep"], "{got:?}");
    assert_eq!(got.iter().map(|g| g.0).collect::<Vec<_>>(), [1, 2, 3, 3, 3]);
}

/// The test this file exists for: a study named by a string in `analysis/` or `plot/` (a
/// `shelf.runs("c0_sweep")`, a figure's or a row's study written out) is found, with its file and
/// line, whether or not `studies::ALL` lists it (the repository's manifests are read too).
#[test]
fn no_study_name_is_written_in_analysis_or_plot_outside_its_definition() {
    let mut names: BTreeSet<String> = studies::ALL.iter().map(|s| s.to_string()).collect();
    names.extend(declared());
    let found = literal_uses(&names);
    assert!(
        found.is_empty(),
        "study names written as strings (name them by a constant of analysis/studies.rs, by a role of analysis/roles.rs, or by analysis/problem_names.rs for a problem):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_defined_studies_are_the_declared_ones_each_once() {
    let defined: BTreeSet<String> = studies::ALL.iter().map(|s| s.to_string()).collect();
    assert_eq!(defined.len(), studies::ALL.len(), "a study defined twice in analysis/studies.rs: {:?}", studies::ALL);
    let declared = declared();
    let undeclared: Vec<&String> = defined.difference(&declared).collect();
    assert!(undeclared.is_empty(), "studies the rows and figures read that no experiments/NAME.toml declares: {undeclared:?}");
    let unread: Vec<&String> = declared.difference(&defined).collect();
    assert!(unread.is_empty(), "manifests under experiments/ whose study analysis/studies.rs does not define: {unread:?}");
}

#[test]
fn every_role_figure_and_row_table_reads_a_defined_study() {
    for role in NEEDED {
        assert!(studies::ALL.contains(&role.study), "role {} of study {}: not in studies::ALL", role.name, role.study);
    }
    for figure in signorini::plot::FIGURES {
        let study = signorini::plot::study_of(figure).unwrap_or_else(|| panic!("figure {figure} has no study (plot::study_of)"));
        assert!(studies::ALL.contains(&study), "figure {figure} reads study {study}: not in studies::ALL");
    }
    let shelf = crate::common::shelf(Path::new("results"));
    for c in signorini::analysis::claims::claims(&shelf, crate::common::roles()).unwrap() {
        for study in signorini::plot::page::claim_studies(&c.id) {
            assert!(studies::ALL.contains(study), "CLAIMS row {} reads study {study}: not in studies::ALL", c.id);
        }
    }
}

#[test]
fn the_problem_names_are_problems() {
    let defined: BTreeSet<&str> = problem_names::ALL.into_iter().collect();
    assert_eq!(defined.len(), problem_names::ALL.len(), "a problem named twice: {:?}", problem_names::ALL);
    for name in problem_names::ALL {
        let file = repo().join("experiments/problems").join(format!("{name}.toml"));
        assert!(
            signorini::problems::KNOWN.contains(&name) || file.is_file(),
            "problem_names::{name} is neither a built-in problem ({:?}) nor a problem file {}",
            signorini::problems::KNOWN,
            file.display()
        );
    }
}
