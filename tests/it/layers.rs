//! The house stays layered: every file of `src/` belongs to a floor (a folder, or one file for
//! a floor of one file), and its code refers only to its own floor and the floors below
//! (`use` lines and paths alike, `crate::`, `super::` and child modules; doc comments and
//! `#[cfg(test)]` modules are not counted), and no two files refer to each other, directly or
//! around a longer circle, except that a module may use the items of the module that declares
//! it (a folder's `mod.rs` assembles its files: `mesh/gmsh.rs` builds the `Mesh` of
//! `mesh/mod.rs`, whose `MeshSpec::build` calls it). The floors, bottom first, are those of
//! `src/lib.rs`'s crate docs.
//!
//! Every `crate::` path is a module's one canonical path: lib.rs's short names (its `pub use`
//! lines, read from the file) are the users' prelude, never used inside the crate, and a path
//! that resolves to no module of `src/` is an error too (a checker that dropped it would pass
//! whatever it hides).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Floors, bottom first: (name, path prefixes under `src/`).
const FLOORS: &[(&str, &[&str])] = &[
    ("base", &["base/"]),
    ("problems", &["problems/"]),
    ("mesh", &["mesh/"]),
    ("sparse", &["sparse/"]),
    ("fem", &["fem/"]),
    ("contact", &["contact/"]),
    ("estimator", &["estimator/"]),
    ("adapt", &["adapt/"]),
    ("records", &["records/"]),
    ("study", &["study/"]),
    ("analysis", &["analysis/"]),
    ("plot", &["plot/"]),
    ("cli", &["main.rs", "bin/"]),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
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

/// "contact::solve" for src/contact/solve.rs, "contact" for src/contact/mod.rs.
fn module_of(rel: &str) -> String {
    let m = rel.trim_end_matches(".rs").trim_end_matches("/mod");
    m.replace('/', "::")
}

fn floor_of(rel: &str) -> Option<usize> {
    FLOORS.iter().position(|(_, prefixes)| prefixes.iter().any(|p| rel.starts_with(p)))
}

/// The code of a file: without comments and without its `#[cfg(test)]` module.
fn code(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or("");
        out.push((i + 1, code.to_string()));
    }
    out
}

/// lib.rs's short names, read from its `pub use` lines (`pub use a::{b, c as d};`, `pub use a::b;`),
/// each with the path it stands for: `("element", "base::element")`.
fn aliases(src: &Path) -> Vec<(String, String)> {
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let text: String = code(&lib).into_iter().map(|(_, l)| l + "\n").collect();
    let mut out = Vec::new();
    for statement in text.split(';').map(str::trim).filter_map(|s| s.strip_prefix("pub use ")) {
        let statement: String = statement.split_whitespace().collect::<Vec<_>>().join(" ");
        let (base, items) = match statement.split_once("::{") {
            Some((base, rest)) => (base.to_string(), rest.trim_end_matches('}').split(',').map(str::trim).map(String::from).collect()),
            None => match statement.rsplit_once("::") {
                Some((base, item)) => (base.to_string(), vec![item.to_string()]),
                None => (String::new(), vec![statement.clone()]),
            },
        };
        for item in items.iter().filter(|i| !i.is_empty()) {
            let (name, alias) = item.split_once(" as ").unwrap_or((item, item));
            let full = if base.is_empty() { name.to_string() } else { format!("{base}::{name}") };
            out.push((alias.trim().to_string(), full.trim_start_matches("self::").to_string()));
        }
    }
    out
}

/// The file (relative to src/) a module path resolves to: the longest prefix that is a module
/// (a short name of lib.rs stands for its module).
fn resolve(path: &[&str], modules: &BTreeMap<String, String>, aliases: &[(String, String)]) -> Option<String> {
    let mut segs: Vec<String> = path.iter().map(|s| s.to_string()).collect();
    if let Some((_, to)) = aliases.iter().find(|(a, _)| Some(a.as_str()) == path.first().copied()) {
        let mut expanded: Vec<String> = to.split("::").map(String::from).collect();
        expanded.extend(segs.drain(1..));
        segs = expanded;
    }
    (1..=segs.len()).rev().find_map(|k| modules.get(&segs[..k].join("::")).cloned())
}

/// What [`scan`] finds: every file's references to other files (target, line), and the
/// `crate::` paths that are not a module's canonical path (through a short name of lib.rs) or
/// that resolve to no module.
struct Scan {
    refs: BTreeMap<String, BTreeMap<String, usize>>,
    bad_paths: Vec<String>,
}

/// The paths of a `use` tree after `crate::` at `at` of `text`: one path, or one per item of a
/// group `crate::{a::b, c}` (nested groups stop at their module); segments, empty ones dropped.
fn crate_paths(text: &str, at: usize) -> Vec<Vec<String>> {
    let segments = |s: &str| -> Vec<String> {
        let path = s.trim_start().split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).next().unwrap_or("");
        path.split("::").filter(|s| !s.is_empty()).map(String::from).collect()
    };
    let Some(group) = text[at..].strip_prefix('{') else { return vec![segments(&text[at..])] };
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

/// Scan the crate at `src`. With `children_too: false`, a module's references to the modules it
/// declares are left out (see the module docs).
fn scan(src: &Path, children_too: bool) -> Scan {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let rel = |p: &PathBuf| p.strip_prefix(src).unwrap().to_string_lossy().replace('\\', "/");
    let modules: BTreeMap<String, String> =
        files.iter().map(rel).filter(|r| r != "lib.rs" && r != "main.rs" && !r.starts_with("bin/")).map(|r| (module_of(&r), r)).collect();
    let aliases = aliases(src);
    let path_re = |s: &str, at: usize| -> Vec<String> {
        s[at..].split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).next().unwrap_or("").split("::").map(String::from).collect()
    };
    let mut out = Scan { refs: BTreeMap::new(), bad_paths: Vec::new() };
    for f in &files {
        let r = rel(f);
        if r == "lib.rs" {
            continue;
        }
        let me = module_of(&r);
        let text = std::fs::read_to_string(f).unwrap();
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
        let mut refs: BTreeMap<String, usize> = BTreeMap::new();
        let add = |refs: &mut BTreeMap<String, usize>, target: Option<String>, line: usize| {
            if let Some(t) = target.filter(|t| *t != r) {
                refs.entry(t).or_insert(line);
            }
        };
        // `crate::` paths over the whole code (a `use crate::{...}` group spans lines)
        let lines = code(&text);
        let joined: String = lines.iter().map(|(_, l)| format!("{l}\n")).collect();
        for (at, _) in joined.match_indices("crate::").filter(|(at, _)| !joined[..*at].ends_with('$')) {
            let line = lines[joined[..at].matches('\n').count()].0;
            for segs in crate_paths(&joined, at + "crate::".len()) {
                let shown = format!("crate::{}", segs.join("::"));
                let first = segs[0].as_str();
                if !modules.keys().any(|m| m.split("::").next() == Some(first))
                    && let Some((_, to)) = aliases.iter().find(|(a, _)| a == first)
                {
                    out.bad_paths
                        .push(format!("src/{r}:{line}: `{shown}` goes through lib.rs's short name `{first}`: write `crate::{to}`"));
                }
                let target = resolve(&segs.iter().map(String::as_str).collect::<Vec<_>>(), &modules, &aliases);
                if target.is_none() {
                    out.bad_paths.push(format!("src/{r}:{line}: `{shown}` resolves to no module of src/"));
                }
                add(&mut refs, target, line);
            }
        }
        for (line, c) in lines {
            for (at, _) in c.match_indices("super::") {
                if at > 0 && c[..at].ends_with("::") {
                    continue;
                }
                let parent = me.rsplit_once("::").map_or(String::new(), |(p, _)| p.to_string());
                let mut segs: Vec<String> = if parent.is_empty() { Vec::new() } else { parent.split("::").map(String::from).collect() };
                segs.extend(path_re(&c, at + "super::".len()));
                add(&mut refs, resolve(&segs.iter().map(String::as_str).collect::<Vec<_>>(), &modules, &aliases), line);
            }
            for child in children.iter().filter(|_| children_too) {
                let used = c
                    .match_indices(&format!("{child}::"))
                    .any(|(at, _)| at == 0 || !c[..at].ends_with(|ch: char| ch.is_alphanumeric() || ch == '_' || ch == ':'));
                if used {
                    add(&mut refs, modules.get(&format!("{me}::{child}")).cloned(), line);
                }
            }
        }
        out.refs.insert(r, refs);
    }
    out
}

fn references_with(children_too: bool) -> BTreeMap<String, BTreeMap<String, usize>> {
    scan(&src(), children_too).refs
}

fn references() -> BTreeMap<String, BTreeMap<String, usize>> {
    references_with(true)
}

#[test]
fn every_crate_path_is_canonical_and_resolves() {
    let bad = scan(&src(), true).bad_paths;
    assert!(bad.is_empty(), "crate:: paths that are not a module's canonical path:\n{}", bad.join("\n"));
}

/// A scratch crate of two floors (`mesh/` below `study/`) whose lib.rs has `extra` added, and
/// whose `mesh/io.rs` holds `code`: what [`scan`] says about it.
fn scan_scratch(name: &str, extra: &str, code: &str) -> Scan {
    let dir = std::env::temp_dir().join(format!("signorini-layers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let files = [
        ("lib.rs", format!("pub mod mesh;\npub mod study;\n{extra}\n")),
        ("mesh/mod.rs", "pub mod io;\n".to_string()),
        ("mesh/io.rs", format!("{code}\n")),
        ("study/mod.rs", "pub mod store;\n".to_string()),
        ("study/store.rs", "pub struct StudyDir;\n".to_string()),
    ];
    for (path, text) in files {
        std::fs::create_dir_all(dir.join(path).parent().unwrap()).unwrap();
        std::fs::write(dir.join(path), text).unwrap();
    }
    let out = scan(&dir, true);
    std::fs::remove_dir_all(&dir).unwrap();
    out
}

/// An upward reference through a short name of lib.rs (`pub use study::store;`, then
/// `crate::store::X` in `mesh/`) is found: as a path that is not canonical, and as the
/// upward reference it is.
#[test]
fn a_path_through_a_short_name_of_lib_rs_fails() {
    let scan = scan_scratch("alias", "pub use study::store;", "use crate::store::StudyDir;");
    assert_eq!(
        scan.bad_paths,
        ["src/mesh/io.rs:1: `crate::store::StudyDir` goes through lib.rs's short name `store`: write `crate::study::store`"],
        "{:?}",
        scan.bad_paths
    );
    assert_eq!(scan.refs["mesh/io.rs"].get("study/store.rs"), Some(&1), "{:?}", scan.refs);
    // the canonical path is found as the upward reference, and is no bad path
    let canonical = scan_scratch("canonical", "pub use study::store;", "use crate::study::store::StudyDir;");
    assert!(canonical.bad_paths.is_empty(), "{:?}", canonical.bad_paths);
    assert_eq!(canonical.refs["mesh/io.rs"].get("study/store.rs"), Some(&1));
}

/// A `crate::` path that resolves to no module is an error, not dropped; in a group too.
#[test]
fn a_path_that_resolves_to_no_module_fails() {
    let scan = scan_scratch("unresolved", "", "use crate::nowhere::Thing;");
    assert_eq!(scan.bad_paths, ["src/mesh/io.rs:1: `crate::nowhere::Thing` resolves to no module of src/"]);
    let group = scan_scratch("group", "", "use crate::{\n    study::store::StudyDir,\n    nowhere,\n};");
    assert_eq!(group.bad_paths, ["src/mesh/io.rs:1: `crate::nowhere` resolves to no module of src/"]);
    assert_eq!(group.refs["mesh/io.rs"].get("study/store.rs"), Some(&1));
}

#[test]
fn every_file_belongs_to_a_floor() {
    let refs = references();
    let homeless: Vec<&String> = refs.keys().filter(|f| floor_of(f).is_none()).collect();
    assert!(homeless.is_empty(), "files on no floor (add them to FLOORS, and to lib.rs's diagram): {homeless:?}");
}

#[test]
fn every_reference_points_down_or_within_its_floor() {
    let refs = references();
    let mut up = Vec::new();
    for (file, targets) in &refs {
        let Some(fl) = floor_of(file) else { continue };
        for (t, line) in targets {
            if let Some(tf) = floor_of(t)
                && tf > fl
            {
                up.push(format!("src/{file}:{line} ({}) refers to src/{t} ({})", FLOORS[fl].0, FLOORS[tf].0));
            }
        }
    }
    assert!(up.is_empty(), "references to a higher floor:\n{}", up.join("\n"));
}

#[test]
fn no_two_files_refer_to_each_other() {
    let refs = references_with(false);
    // depth-first search for a cycle, reporting it with the lines
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
                    let mut circle: Vec<String> = stack[start..].iter().map(|s| format!("src/{s}")).collect();
                    circle.push(format!("src/{t}"));
                    return Some(circle);
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
    let mut state = BTreeMap::new();
    for f in refs.keys() {
        if !state.contains_key(f.as_str()) {
            let mut stack = Vec::new();
            if let Some(circle) = visit(f, &refs, &mut state, &mut stack) {
                panic!("an import cycle: {}", circle.join(" -> "));
            }
        }
    }
}

/// What only the store reads in a results folder: its layout ([`signorini::records::StudyDir`]),
/// its records, snapshots and summaries, and the file system itself. Each line of
/// `src/analysis/` and `src/plot/` naming one is a reader going past the integrity check.
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

/// The files above the store read nothing but through it, except these lines (file, what):
/// the figures' PNGs and the drift report, which are not results files.
const NOT_RESULTS: &[(&str, &str)] = &[("plot/page.rs", "std::fs::read(&png)"), ("plot/page.rs", "std::fs::read_to_string(drift_report)")];

/// The door by construction: `src/analysis/` and `src/plot/` get a study's records, mesh
/// snapshots, provenance and problem only from a `store::Shelf` (made by the store after its
/// integrity check); none names a results folder's layout, reads a record or opens a file of
/// it. The check is shown to catch each name on a scratch line.
#[test]
fn analysis_and_plot_read_results_only_through_the_shelf() {
    let past = |rel: &str, line: &str| -> Option<&'static str> {
        let allowed = NOT_RESULTS.iter().any(|(f, what)| rel == *f && line.contains(what));
        PAST_THE_DOOR.iter().copied().find(|name| line.contains(name)).filter(|_| !allowed)
    };
    for probe in ["let d = StudyDir::new(results, s);", "x.read_runs()?", "std::fs::read_to_string(p)", "dir.read_mesh(r, 3)"] {
        assert!(past("plot/mod.rs", probe).is_some(), "the check misses {probe}");
    }
    assert!(past("plot/page.rs", "match std::fs::read(&png) {").is_none());
    let mut files = Vec::new();
    for floor in ["analysis", "plot"] {
        rust_files(&src().join(floor), &mut files);
    }
    assert!(files.len() > 10, "{files:?}");
    let mut bad = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(src()).unwrap().to_string_lossy().replace('\\', "/");
        for (n, line) in code(&std::fs::read_to_string(f).unwrap()) {
            if let Some(name) = past(&rel, &line) {
                bad.push(format!("src/{rel}:{n}: {name}: {}", line.trim()));
            }
        }
    }
    assert!(bad.is_empty(), "read past the store's integrity check (take a store::Shelf):\n{}", bad.join("\n"));
}
