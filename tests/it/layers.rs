//! The house stays layered. Between crates the compiler keeps the floors (a crate can use only
//! the crates it depends on, and Cargo refuses a cycle). Inside a crate this test keeps them:
//! every file of a crate's `src/` belongs to a floor (a folder), and its code refers only to its
//! own floor and the floors below (`use` lines and paths alike: `crate::`, `super::` however
//! many times, and child modules; comments and `#[cfg(test)]` modules are not counted), and no
//! two files refer to each other, directly or around a longer circle, except that a module may
//! use the items of the module that declares it (a folder's `mod.rs` assembles its files:
//! `mesh/gmsh.rs` builds the `Mesh` of `mesh/mod.rs`, whose `MeshSpec::build` calls it). A
//! `crate::` or `super::` path that resolves to no module of the crate is an error too (a
//! checker that dropped it would pass whatever it hides).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The member crates (folder under the repository) and their floors, bottom first, as their
/// lib.rs's docs draw them.
const CRATES: &[(&str, &[&str])] = &[
    ("crates/model", &["base", "problems", "mesh", "settings", "level"]),
    ("crates/numerics", &["sparse", "fem", "contact", "estimator", "adapt"]),
    ("crates/store", &["records", "study"]),
    ("crates/harness", &["report", "study"]),
    ("crates/claims", &["analysis", "plot", "commands", "bin"]),
];

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file under `dir`, folders too (also read by `study_names`).
pub(crate) fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// "contact::solve" for contact/solve.rs, "contact" for contact/mod.rs.
fn module_of(rel: &str) -> String {
    rel.trim_end_matches(".rs").trim_end_matches("/mod").replace('/', "::")
}

/// The code of a file: without comments and without its `#[cfg(test)]` module.
fn code(text: &str) -> Vec<(usize, String)> {
    let lines = text.lines().take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"));
    lines.enumerate().map(|(i, l)| (i + 1, l.split("//").next().unwrap_or("").to_string())).collect()
}

/// The module paths of a `use` tree at the start of `text`: one path, or one per item of a
/// group `{a::b, c}` (nested groups stop at their module); segments, empty ones dropped.
fn tree_paths(text: &str) -> Vec<Vec<String>> {
    let segments = |s: &str| -> Vec<String> {
        let path = s.trim_start().split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).next().unwrap_or("");
        path.split("::").filter(|s| !s.is_empty()).map(String::from).collect()
    };
    let Some(group) = text.strip_prefix('{') else { return vec![segments(text)] };
    let (mut depth, mut items, mut item) = (0usize, Vec::new(), String::new());
    for c in group.chars() {
        match c {
            '}' if depth == 0 => break,
            ',' if depth == 0 => {
                items.push(std::mem::take(&mut item));
                continue;
            }
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        item.push(c);
    }
    items.push(item);
    items.iter().map(|i| segments(i)).filter(|p| !p.is_empty()).collect()
}

/// What [`scan`] finds in a crate: every file's references to other files (target, line) and
/// the paths that resolve to no module.
struct Scan {
    refs: BTreeMap<String, BTreeMap<String, usize>>,
    bad_paths: Vec<String>,
}

/// The file a module path resolves to: the longest prefix that is a module.
fn resolve(segs: &[String], modules: &BTreeMap<String, String>) -> Option<String> {
    (1..=segs.len()).rev().find_map(|k| modules.get(&segs[..k].join("::")).cloned())
}

/// Where a path starting at `at` of `code` (just after `crate::`, or at the first `super::` of
/// a chain) leads, from module `me`: the absolute module path, `super::` counted however often.
fn absolute(code: &str, at: usize, me: &str, from_crate: bool) -> Vec<Vec<String>> {
    if from_crate {
        return tree_paths(&code[at..]);
    }
    let mut rest = &code[at..];
    let mut base: Vec<String> = me.split("::").filter(|s| !s.is_empty()).map(String::from).collect();
    while let Some(r) = rest.strip_prefix("super::") {
        base.pop();
        rest = r;
    }
    tree_paths(rest).into_iter().map(|p| base.iter().cloned().chain(p).collect()).collect()
}

/// Scan the crate whose sources are at `src`. With `children_too: false`, a module's references
/// to the modules it declares are left out (see the module docs).
fn scan(src: &Path, children_too: bool) -> Scan {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let rel = |p: &PathBuf| p.strip_prefix(src).unwrap().to_string_lossy().replace('\\', "/");
    let mut modules: BTreeMap<String, String> = files.iter().map(rel).filter(|r| r != "lib.rs").map(|r| (module_of(&r), r)).collect();
    // a `#[macro_export]` macro is an item of the crate root, `crate::NAME`, defined in its file
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (at, _) in text.match_indices("#[macro_export]") {
            let name = text[at..]
                .split("macro_rules!")
                .nth(1)
                .and_then(|r| r.split(|c: char| !(c.is_alphanumeric() || c == '_')).find(|w| !w.is_empty()));
            modules.extend(name.map(|n| (n.to_string(), rel(f))));
        }
    }
    let mut out = Scan { refs: BTreeMap::new(), bad_paths: Vec::new() };
    for f in &files {
        let r = rel(f);
        if r == "lib.rs" {
            continue;
        }
        let me = module_of(&r);
        let text = std::fs::read_to_string(f).unwrap();
        let lines = code(&text);
        let joined: String = lines.iter().map(|(_, l)| format!("{l}\n")).collect();
        let mut refs: BTreeMap<String, usize> = BTreeMap::new();
        let line_at = |at: usize| lines[joined[..at].matches('\n').count()].0;
        let mut starts: Vec<(usize, bool)> =
            joined.match_indices("crate::").filter(|(at, _)| !joined[..*at].ends_with('$')).map(|(at, _)| (at + 7, true)).collect();
        starts.extend(joined.match_indices("super::").filter(|(at, _)| !joined[..*at].ends_with("::")).map(|(at, _)| (at, false)));
        for (at, from_crate) in starts {
            for segs in absolute(&joined, at, &me, from_crate) {
                match resolve(&segs, &modules) {
                    Some(t) if t != r => {
                        refs.entry(t).or_insert(line_at(at));
                    }
                    Some(_) => {}
                    None => out.bad_paths.push(format!("{r}:{}: `{}` resolves to no module of the crate", line_at(at), segs.join("::"))),
                }
            }
        }
        let children: BTreeSet<String> = text
            .lines()
            .filter_map(|l| {
                l.trim_start()
                    .trim_start_matches("pub ")
                    .trim_start_matches("pub(crate) ")
                    .strip_prefix("mod ")?
                    .strip_suffix(';')
                    .map(String::from)
            })
            .collect();
        for (line, c) in lines.iter().filter(|_| children_too) {
            for child in &children {
                let used = c
                    .match_indices(&format!("{child}::"))
                    .any(|(at, _)| at == 0 || !c[..at].ends_with(|ch: char| ch.is_alphanumeric() || ch == '_' || ch == ':'));
                if let Some(t) = modules.get(&format!("{me}::{child}")).filter(|_| used) {
                    refs.entry(t.clone()).or_insert(*line);
                }
            }
        }
        out.refs.insert(r, refs);
    }
    out
}

/// The floor of a file: the floor folder it is in, or the floor that is this one file.
fn floor_of(floors: &[&str], rel: &str) -> Option<usize> {
    floors.iter().position(|f| rel.starts_with(&format!("{f}/")) || rel == format!("{f}.rs"))
}

#[test]
fn every_path_resolves_to_a_module_of_its_crate() {
    for (dir, _) in CRATES {
        let bad = scan(&repo().join(dir).join("src"), true).bad_paths;
        assert!(bad.is_empty(), "{dir}: paths that resolve to no module:\n{}", bad.join("\n"));
    }
}

#[test]
fn every_file_belongs_to_a_floor_of_its_crate() {
    for (dir, floors) in CRATES {
        let refs = scan(&repo().join(dir).join("src"), true).refs;
        let homeless: Vec<&String> = refs.keys().filter(|f| floor_of(floors, f).is_none()).collect();
        assert!(homeless.is_empty(), "{dir}: files on no floor (add the floor to CRATES, and to lib.rs's diagram): {homeless:?}");
    }
}

/// The upward references of a crate: "file:line (floor) refers to file (floor)".
fn upward(src: &Path, floors: &[&str]) -> Vec<String> {
    let mut up = Vec::new();
    for (file, targets) in scan(src, true).refs {
        let Some(fl) = floor_of(floors, &file) else { continue };
        for (t, line) in targets {
            if let Some(tf) = floor_of(floors, &t).filter(|&tf| tf > fl) {
                up.push(format!("{file}:{line} ({}) refers to {t} ({})", floors[fl], floors[tf]));
            }
        }
    }
    up
}

#[test]
fn every_reference_points_down_or_within_its_floor() {
    for (dir, floors) in CRATES {
        let up = upward(&repo().join(dir).join("src"), floors);
        assert!(up.is_empty(), "{dir}: references to a higher floor:\n{}", up.join("\n"));
    }
}

/// A circle of references, if the crate at `src` has one: the files around it.
fn circle(src: &Path) -> Option<Vec<String>> {
    fn visit<'a>(
        f: &'a str,
        refs: &'a BTreeMap<String, BTreeMap<String, usize>>,
        state: &mut BTreeMap<&'a str, u8>,
        stack: &mut Vec<&'a str>,
    ) -> Option<Vec<String>> {
        state.insert(f, 1);
        stack.push(f);
        for t in refs.get(f).into_iter().flat_map(|m| m.keys()) {
            match state.get(t.as_str()) {
                Some(1) => {
                    let start = stack.iter().position(|s| *s == t).unwrap();
                    return Some(stack[start..].iter().map(|s| s.to_string()).chain([t.clone()]).collect());
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(t, refs, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(f, 2);
        None
    }
    let refs = scan(src, false).refs;
    let mut state = BTreeMap::new();
    refs.keys().find_map(|f| if state.contains_key(f.as_str()) { None } else { visit(f, &refs, &mut state, &mut Vec::new()) })
}

#[test]
fn no_two_files_refer_to_each_other() {
    for (dir, _) in CRATES {
        if let Some(c) = circle(&repo().join(dir).join("src")) {
            panic!("{dir}: an import cycle: {}", c.join(" -> "));
        }
    }
}

/// A scratch crate whose files are `files` (path under src/, text): what [`scan`] says of it.
fn scan_scratch(name: &str, files: &[(&str, &str)]) -> Scan {
    let dir = std::env::temp_dir().join(format!("signorini-layers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for (path, text) in files {
        std::fs::create_dir_all(dir.join(path).parent().unwrap()).unwrap();
        std::fs::write(dir.join(path), format!("{text}\n")).unwrap();
    }
    let out = scan(&dir, false);
    std::fs::remove_dir_all(&dir).unwrap();
    out
}

/// `super::super::x` from `a/b/c.rs` is `a::x`, not `a::b`: a cycle through it is found, and an
/// upward reference through it too.
#[test]
fn a_path_up_two_modules_resolves_to_the_grandparent_s_child() {
    let files = [
        ("lib.rs", "pub mod a;"),
        ("a/mod.rs", "pub mod b;\npub mod x;"),
        ("a/b/mod.rs", "pub mod c;"),
        ("a/b/c.rs", "fn f() { super::super::x::g(); }"),
        ("a/x.rs", "use crate::a::b::c::f;"),
    ];
    let scan = scan_scratch("supers", &files);
    assert_eq!(scan.refs["a/b/c.rs"].get("a/x.rs"), Some(&1), "{:?}", scan.refs);
    assert!(scan.bad_paths.is_empty(), "{:?}", scan.bad_paths);
    let grouped = scan_scratch("supers-group", &[files[0], files[1], files[2], ("a/b/c.rs", "use super::super::{x::g, b};"), files[4]]);
    assert_eq!(grouped.refs["a/b/c.rs"].get("a/x.rs"), Some(&1), "{:?}", grouped.refs);
}

/// A `crate::` path that resolves to no module is an error, not dropped; in a group too.
#[test]
fn a_path_that_resolves_to_no_module_fails() {
    let files = [("lib.rs", "pub mod mesh;\npub mod study;"), ("mesh/mod.rs", "pub mod io;"), ("study/mod.rs", "pub struct StudyDir;")];
    let one = scan_scratch("unresolved", &[files[0], files[1], files[2], ("mesh/io.rs", "use crate::nowhere::Thing;")]);
    assert_eq!(one.bad_paths, ["mesh/io.rs:1: `nowhere::Thing` resolves to no module of the crate"]);
    let group =
        scan_scratch("group", &[files[0], files[1], files[2], ("mesh/io.rs", "use crate::{\n    study::StudyDir,\n    nowhere,\n};")]);
    assert_eq!(group.bad_paths, ["mesh/io.rs:1: `nowhere` resolves to no module of the crate"]);
    assert_eq!(group.refs["mesh/io.rs"].get("study/mod.rs"), Some(&1));
}

/// What only the store reads in a results folder: its layout (`records::StudyDir`), its records,
/// snapshots and summaries, and the file system itself. Each line of the claims crate naming one
/// is a reader going past the integrity check.
const PAST_THE_DOOR: &[&str] = &[
    "StudyDir",
    "read_runs",
    "read_run",
    "read_mesh",
    "provenance_file",
    "mesh_file",
    "fs::read",
    "read_dir",
    "Store::",
    "stored_problem",
];

/// The claims crate reads nothing but through the store, except these lines (file, what): the
/// figures' PNGs and the drift report, which are not results files.
const NOT_RESULTS: &[(&str, &str)] = &[("plot/page.rs", "std::fs::read(&png)"), ("plot/page.rs", "std::fs::read_to_string(drift_report)")];

/// The door by construction: the claims crate gets a study's records, mesh snapshots,
/// provenance and problem only from a `store::Shelf` (made by the store after its integrity
/// check); none of its files names a results folder's layout, reads a record or opens a file of
/// it. The check is shown to catch each name on a scratch line.
#[test]
fn claims_and_figures_read_results_only_through_the_shelf() {
    let past = |rel: &str, line: &str| -> Option<&'static str> {
        let allowed = NOT_RESULTS.iter().any(|(f, what)| rel == *f && line.contains(what));
        PAST_THE_DOOR.iter().copied().find(|name| line.contains(name)).filter(|_| !allowed)
    };
    for probe in ["let d = StudyDir::new(results, s);", "x.read_runs()?", "std::fs::read_to_string(p)", "dir.read_mesh(r, 3)"] {
        assert!(past("plot/mod.rs", probe).is_some(), "the check misses {probe}");
    }
    assert!(past("plot/page.rs", "match std::fs::read(&png) {").is_none());
    let src = repo().join("crates/claims/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 10, "{files:?}");
    let mut bad = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        for (n, line) in code(&std::fs::read_to_string(f).unwrap()) {
            if let Some(name) = past(&rel, &line) {
                bad.push(format!("crates/claims/src/{rel}:{n}: {name}: {}", line.trim()));
            }
        }
    }
    assert!(bad.is_empty(), "read past the store's integrity check (take a store::Shelf):\n{}", bad.join("\n"));
}

/// The dependencies a crate's Cargo.toml names, with the package each one is (a renamed path
/// dependency `store = { package = "signorini-store" }` is signorini-store).
fn dependencies_of(dir: &str) -> Vec<String> {
    let text = std::fs::read_to_string(repo().join(dir).join("Cargo.toml")).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let deps = table.get("dependencies").and_then(|d| d.as_table()).cloned().unwrap_or_default();
    deps.iter().map(|(k, v)| v.get("package").and_then(|p| p.as_str()).unwrap_or(k).to_string()).collect()
}

/// `make figures` compiles no solver: the figures binary's crate and every crate it stands on
/// name neither the solver crates nor faer, only each other and crates outside the workspace.
#[test]
fn the_figures_crates_stand_on_no_solver() {
    let light = ["crates/claims", "crates/store", "crates/model"];
    for dir in light {
        let deps = dependencies_of(dir);
        let solver: Vec<&String> =
            deps.iter().filter(|d| ["faer", "signorini-numerics", "signorini-harness", "signorini"].contains(&d.as_str())).collect();
        assert!(solver.is_empty(), "{dir} depends on {solver:?}: `make figures` would compile the solver");
        for d in deps.iter().filter(|d| d.starts_with("signorini")) {
            assert!(light.iter().any(|l| l.trim_start_matches("crates/") == d.trim_start_matches("signorini-")), "{dir} depends on {d}");
        }
    }
    assert!(dependencies_of("crates/numerics").contains(&"faer".to_string()), "the check reads dependencies as the solver's names faer");
}

/// The source files of the targets whose Cargo.toml says `test = false` (a library: its `src/`
/// but `src/bin/`; a binary: its file): `cargo test` does not compile their unit tests.
fn untested_sources() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in std::iter::once(".").chain(CRATES.iter().map(|(d, _)| *d)) {
        let table: toml::Table = std::fs::read_to_string(repo().join(dir).join("Cargo.toml")).unwrap().parse().unwrap();
        let untested = |t: &toml::Value| t.get("test").and_then(|v| v.as_bool()) == Some(false);
        if table.get("lib").is_some_and(untested) {
            let mut files = Vec::new();
            rust_files(&repo().join(dir).join("src"), &mut files);
            out.extend(files.into_iter().filter(|f| !f.starts_with(repo().join(dir).join("src/bin"))));
        }
        for bin in table.get("bin").and_then(|b| b.as_array()).into_iter().flatten().filter(|b| untested(b)) {
            out.push(repo().join(dir).join(bin["path"].as_str().expect("a [[bin]] with test = false names its path")));
        }
    }
    out
}

/// A `#[test]` in a target whose unit tests `cargo test` does not compile would never run.
#[test]
fn no_test_is_left_where_it_would_not_run() {
    let files = untested_sources();
    assert!(files.iter().any(|f| f.ends_with("src/main.rs")), "the command line's unit tests are not compiled: {files:?}");
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(
            !text.contains("#[test]") && !text.contains("#[cfg(test)]"),
            "{}: a unit test in a target with test = false never runs",
            f.display()
        );
    }
}
