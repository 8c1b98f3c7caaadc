//! The house stays layered: every file of `src/` belongs to a floor (a folder, or one file for
//! a floor of one file), and its code refers only to its own floor and the floors below
//! (`use` lines and paths alike, `crate::`, `super::` and child modules; doc comments and
//! `#[cfg(test)]` modules are not counted), and no two files refer to each other, directly or
//! around a longer circle, except that a module may use the items of the module that declares
//! it (a folder's `mod.rs` assembles its files: `mesh/gmsh.rs` builds the `Mesh` of
//! `mesh/mod.rs`, whose `MeshSpec::build` calls it). The floors, bottom first, are those of
//! `src/lib.rs`'s crate docs.

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
    ("records", &["records/"]),
    ("adapt", &["adapt/"]),
    ("study", &["study/"]),
    ("analysis", &["analysis/"]),
    ("plot", &["plot/"]),
    ("cli", &["main.rs", "bin/"]),
];

/// The root's short names (`pub use` in lib.rs) and the module each stands for.
const ALIASES: &[(&str, &str)] = &[
    ("element", "base::element"),
    ("memory", "base::memory"),
    ("ordering", "sparse::ordering"),
    ("symbolic", "sparse::symbolic"),
    ("cholesky", "sparse::cholesky"),
    ("assembly", "fem::assembly"),
    ("solve", "contact::solve"),
    ("certify", "contact::certify"),
    ("norms", "contact::norms"),
    ("estimate", "estimator::estimate"),
    ("report", "records::report"),
    ("claims", "analysis::claims"),
    ("hertz", "analysis::hertz"),
    ("verdict", "analysis::verdict"),
    ("page", "plot::page"),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
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

/// The file (relative to src/) a module path resolves to: the longest prefix that is a module.
fn resolve(path: &[&str], modules: &BTreeMap<String, String>) -> Option<String> {
    let mut segs: Vec<String> = path.iter().map(|s| s.to_string()).collect();
    if let Some((_, to)) = ALIASES.iter().find(|(a, _)| Some(*a) == path.first().copied()) {
        let mut expanded: Vec<String> = to.split("::").map(String::from).collect();
        expanded.extend(segs.drain(1..));
        segs = expanded;
    }
    (1..=segs.len()).rev().find_map(|k| modules.get(&segs[..k].join("::")).cloned())
}

/// Every file's references to other files: (target, line). With `children: false`, a module's
/// references to the modules it declares are left out (see the module docs).
fn references_with(children_too: bool) -> BTreeMap<String, BTreeMap<String, usize>> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let rel = |p: &PathBuf| p.strip_prefix(src()).unwrap().to_string_lossy().replace('\\', "/");
    let modules: BTreeMap<String, String> =
        files.iter().map(rel).filter(|r| r != "lib.rs" && r != "main.rs" && !r.starts_with("bin/")).map(|r| (module_of(&r), r)).collect();
    let path_re = |s: &str, at: usize| -> Vec<String> {
        s[at..].split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).next().unwrap_or("").split("::").map(String::from).collect()
    };
    let mut out = BTreeMap::new();
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
        for (line, c) in code(&text) {
            let mut targets = Vec::new();
            for (at, _) in c.match_indices("crate::") {
                let segs = path_re(&c, at + "crate::".len());
                targets.push(resolve(&segs.iter().map(String::as_str).collect::<Vec<_>>(), &modules));
            }
            for (at, _) in c.match_indices("super::") {
                if at > 0 && c[..at].ends_with("::") {
                    continue;
                }
                let parent = me.rsplit_once("::").map_or(String::new(), |(p, _)| p.to_string());
                let mut segs: Vec<String> = if parent.is_empty() { Vec::new() } else { parent.split("::").map(String::from).collect() };
                segs.extend(path_re(&c, at + "super::".len()));
                targets.push(resolve(&segs.iter().map(String::as_str).collect::<Vec<_>>(), &modules));
            }
            for child in children.iter().filter(|_| children_too) {
                let used = c
                    .match_indices(&format!("{child}::"))
                    .any(|(at, _)| at == 0 || !c[..at].ends_with(|ch: char| ch.is_alphanumeric() || ch == '_' || ch == ':'));
                if used {
                    targets.push(modules.get(&format!("{me}::{child}")).cloned());
                }
            }
            for t in targets.into_iter().flatten() {
                if t != r {
                    refs.entry(t).or_insert(line);
                }
            }
        }
        out.insert(r, refs);
    }
    out
}

fn references() -> BTreeMap<String, BTreeMap<String, usize>> {
    references_with(true)
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
