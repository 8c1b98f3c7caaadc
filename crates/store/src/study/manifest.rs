//! Study manifests: `experiments/STUDY.toml`.
//!
//! ```toml
//! description = "Example 7.1, adaptive and uniform"
//!
//! [defaults]                 # every run starts from these
//! problem = "ex71"           # a built-in problem, or a problem file: "problems/hertz.toml"
//! mesh = "structured:4"       # or "symmetric:N", or "gmsh:meshes/NAME.msh" (a Gmsh file)
//!                            # (relative paths are relative to this manifest's folder)
//! levels = 24
//! quick_levels = 8           # the --quick form: the first levels of the same runs
//! theta = 0.5
//! refine = "adaptive"        # or "uniform"
//! max_ndof = 2000000         # optional: no level with more unknowns is solved
//! stop_ndof = 10000000       # optional: the first level with at least this many is the last
//! save_levels = []           # levels written as VTU (and mesh JSON)
//! [defaults.estimator]
//! c0 = 0.45
//! contact_term = "as_written"   # or "without_full_contact"
//! log_factor = "squared"        # or "linear", "one"
//! sampling = "quadrature"       # or "dense"
//! stress_frame = "normal"       # or "cartesian": how eta_4, eta_5 read sigma-hat (settings::estimator::StressFrame)
//! [defaults.reference]       # optional: errors against a finer adaptive solution
//! theta = 0.5
//! min_ndof = 640000
//! contact_term = "without_full_contact"   # the default; see records::ReferenceSpec
//!
//! [[run]]                    # each run overrides what it names
//! id = "adaptive"
//! role = "paper-adaptive"    # optional: what the run stands for to CLAIMS and the figures
//!                            # (analysis::roles), once per study, on a line of its own
//! [[run]]
//! id = "uniform"
//! refine = "uniform"
//! levels = 9
//! no_reference = true        # drop the defaults' reference in this run (only where [defaults] has one)
//!
//! [drift]                    # tolerances of the drift check (study::drift): a float passes
//!                            # when |fresh - stored| <= rel |stored| + floor max_run |stored|
//!                            # (rel and floor in [0, 1]: a larger tolerance lets anything pass)
//! default = { rel = 1e-9, floor = 1e-14 }
//! fields = { err_nodal = { rel = 1e-6, floor = 1e-12 } }   # float fields of LevelRecord only
//! [[drift.rates]]            # one-sided floors on observed rates in NDF
//! run = "uniform"
//! field = "err_quadrature"   # a float field of LevelRecord
//! min = 1.4
//! last = 4                   # 2 ..= the run's levels
//! ```
//!
//! Every error names the file, the key and what was expected; unknown keys are errors. The run's
//! loop settings are checked by [`AdaptConfig::validate`](model::settings::adapt::AdaptConfig::validate),
//! as on the command line. `save_levels` may not repeat a level. What needs the runs' files
//! and this machine (the meshes built with their problems, memory for the initial mesh and the
//! reference, `max_ndof` against the initial mesh) is checked by [`Manifest::check_runs`] for
//! every run before any is solved.

use crate::records::{ReferenceSpec, RunSpec};
use model::mesh::MeshSpec;
use model::settings::adapt::AdaptConfig;
use model::settings::adapt::Refine;
use model::settings::estimator::{ContactTerm, EstimatorConfig, LogFactor, StressFrame};
use model::settings::sampling::Sampling;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A derived field's value as a function of its record.
pub type Definition = fn(&model::level::record::LevelRecord) -> Option<f64>;

/// Fields that are functions of other fields of the same record, checked as such (the stored
/// and the fresh value each equal the function of the record's own fields, to the bit) rather
/// than within a tolerance of their own: the efficiency index estimate / err_quadrature carries
/// the error's relative round-off, which near the end of a run is far larger than anything a
/// tolerance on the index itself could be honest about while still seeing a change of 1e-5.
pub const DERIVED: [(&str, Definition); 1] = [("efficiency", |l| l.err_quadrature.map(|e| l.terms.estimate / e))];

/// A manifest as [`model::base::input::read`] reads it: a regular file of at most
/// [`TEXT_LIMIT`](model::base::input::TEXT_LIMIT) bytes.
const MANIFEST: model::base::input::Kind =
    model::base::input::Kind { what: "the manifest", limit: model::base::input::Limit::Bytes(model::base::input::TEXT_LIMIT) };

#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{file}: {error}")]
    Read { file: PathBuf, error: model::base::input::InputError },
    #[error("{file}: {}", model::base::input::excerpt(message))]
    Syntax { file: PathBuf, message: String },
    #[error("{file}: key `{key}`: expected {expected}, got {}", model::base::input::excerpt(got))]
    Invalid { file: PathBuf, key: String, expected: String, got: String },
    /// The file's name cannot name a study ([`crate::records::study_name_fault`]).
    #[error(
        "{file}: a study is named after its manifest's file, and `{study}` cannot name one: {why}. Rename the file (e.g. experiments/my_study.toml)"
    )]
    Name { file: PathBuf, study: String, why: String },
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table of estimator settings (c0, contact_term, log_factor, sampling)")]
struct EstimatorOverrides {
    c0: Option<f64>,
    contact_term: Option<ContactTerm>,
    log_factor: Option<LogFactor>,
    sampling: Option<Sampling>,
    stress_frame: Option<StressFrame>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table { theta, min_ndof, contact_term }")]
struct ReferenceToml {
    theta: f64,
    min_ndof: usize,
    contact_term: Option<ContactTerm>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table of run settings")]
struct RunToml {
    id: Option<String>,
    /// What the run stands for to CLAIMS.md and the figures ([`claims::analysis`] finds its runs
    /// by role, never by id): unique within the study.
    role: Option<String>,
    problem: Option<String>,
    mesh: Option<String>,
    levels: Option<usize>,
    quick_levels: Option<usize>,
    theta: Option<f64>,
    refine: Option<Refine>,
    max_ndof: Option<usize>,
    stop_ndof: Option<usize>,
    save_levels: Option<Vec<usize>>,
    estimator: Option<EstimatorOverrides>,
    reference: Option<ReferenceToml>,
    /// `no_reference = true` in a run drops the defaults' reference.
    no_reference: Option<bool>,
    /// Values for some of the problem file's `[constants]` (a run's entries override the
    /// defaults' one by one).
    constants: Option<std::collections::BTreeMap<String, f64>>,
}

/// A tolerance of the drift check: |fresh - stored| <= rel |stored| + floor scale, where scale is
/// the field's largest |value| over the stored run's levels (see `study::drift`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tolerance {
    pub rel: f64,
    #[serde(default)]
    pub floor: f64,
}

/// A one-sided floor on an observed rate: the slope of -log(field) in log(NDF) over the last
/// `last` levels of run `run` must be at least `min`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateFloor {
    pub run: String,
    pub field: String,
    pub min: f64,
    pub last: usize,
}

/// Tolerances of the drift check, per field, with a default; rate floors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriftSpec {
    /// The tolerance of fields not listed in `fields` (rel 1e-9, floor 0 when not given).
    #[serde(default = "default_tolerance")]
    pub default: Tolerance,
    #[serde(default)]
    pub fields: BTreeMap<String, Tolerance>,
    #[serde(default)]
    pub rates: Vec<RateFloor>,
    /// A deep study (runs too long to rerun in `make test`): see [`DeepTier`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deep: Option<DeepTier>,
}

/// The drift tiers of a deep study. `signorini drift` (what `make test` runs) reruns each run
/// in its quick form (the first `quick_levels` levels: an exact prefix, kept to small sizes) and
/// compares those levels, except the runs in `full`, which it reruns to the end and compares at
/// every level (a deep level of the study checked in every test run). The last level of each
/// run in `replay` (the last with at most `replay_max_ndof` unknowns, where that is given: a
/// level whose solve fits the memory of the machines `make test` runs on) is rebuilt from its
/// stored refinement history and solved once more (`adapt::replay`), without the levels before
/// it, and compared with its stored record; every
/// run's history is compared exactly with the stored one as far as it was rerun.
/// `signorini drift --deep` (the scheduled job, `make drift`) reruns every run to the end.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeepTier {
    #[serde(default)]
    pub full: Vec<String>,
    #[serde(default)]
    pub replay: Vec<String>,
    /// The replayed level is the last with at most this many unknowns (all levels: the last).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replay_max_ndof: Option<usize>,
}

fn default_tolerance() -> Tolerance {
    Tolerance { rel: 1e-9, floor: 0.0 }
}

impl Default for DriftSpec {
    fn default() -> Self {
        DriftSpec { default: default_tolerance(), fields: BTreeMap::new(), rates: Vec::new(), deep: None }
    }
}

impl DriftSpec {
    pub fn tolerance(&self, field: &str) -> Tolerance {
        self.fields.get(field).copied().unwrap_or(self.default)
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a manifest (description, [defaults], [[run]], [drift])")]
struct ManifestToml {
    description: Option<String>,
    defaults: Option<RunToml>,
    run: Vec<RunToml>,
    drift: Option<DriftSpec>,
}

/// One declared run with its quick form.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRun {
    pub spec: RunSpec,
    /// Levels of the `--quick` form (a prefix of the full run: same meshes, same numbers).
    pub quick_levels: usize,
}

/// A parsed and validated manifest.
#[derive(Clone, Debug)]
pub struct Manifest {
    /// The study's name: the manifest's file stem.
    pub study: String,
    pub file: PathBuf,
    pub description: String,
    pub runs: Vec<PlannedRun>,
    pub drift: DriftSpec,
    /// The manifest's bytes without its `role = "..."` lines ([`without_roles`]): hashed into
    /// the provenance.
    pub bytes: Vec<u8>,
    /// What runs stand for (role -> run id, from `role = "..."` in the `[[run]]` tables): how
    /// CLAIMS.md and the figures find their runs ([`claims::analysis::roles`]).
    pub roles: BTreeMap<String, String>,
}

impl Manifest {
    /// The manifest as `signorini drift` reruns it, and whether in quick forms: a deep study
    /// ([`DeepTier`]) in its quick forms but its `full` runs to the end, unless `deep`; any study
    /// in its quick forms with `quick`.
    pub fn for_drift(&self, quick: bool, deep: bool) -> (Manifest, bool) {
        let mut m = self.clone();
        match (&self.drift.deep, quick, deep) {
            (Some(tier), false, false) => {
                for p in m.runs.iter_mut().filter(|p| tier.full.contains(&p.spec.id)) {
                    p.quick_levels = p.spec.levels;
                }
                (m, true)
            }
            _ => (m, quick),
        }
    }

    pub fn load(path: &Path) -> Result<Self, ManifestError> {
        let bytes = model::base::input::read(path, MANIFEST).map_err(|error| ManifestError::Read { file: path.to_path_buf(), error })?;
        let text = String::from_utf8_lossy(&bytes);
        Self::parse(path, &text).map(|mut m| {
            m.bytes = without_roles(&bytes);
            m
        })
    }

    pub fn parse(path: &Path, text: &str) -> Result<Self, ManifestError> {
        let file = path.to_path_buf();
        let raw: ManifestToml = toml::from_str(text)
            .map_err(|e| ManifestError::Syntax { file: file.clone(), message: model::base::toml_text::plain(e.to_string().trim_end()) })?;
        let study = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if let Some(why) = crate::records::study_name_fault(&study) {
            return Err(ManifestError::Name { file, study, why });
        }
        let invalid = Invalid(&file);
        if raw.run.is_empty() {
            return Err(invalid.at("run".into(), "at least one [[run]] table", "none".into()));
        }
        let d = raw.defaults.clone().unwrap_or_default();
        check_defaults(&d, &invalid)?;
        let (mut ids, mut roles) = (std::collections::BTreeSet::new(), BTreeMap::new());
        let runs = raw
            .run
            .iter()
            .enumerate()
            .map(|(i, r)| parse_run(path, i, r, &d, (&mut ids, &mut roles), &invalid))
            .collect::<Result<Vec<_>, _>>()?;
        let (runs, declared): (Vec<PlannedRun>, Vec<Option<String>>) = runs.into_iter().unzip();
        let drift = raw.drift.unwrap_or_default();
        check_drift(&drift, &runs, &invalid)?;
        check_role_lines(&declared, text, &invalid)?;
        let bytes = without_roles(text.as_bytes());
        Ok(Manifest { study, file, description: raw.description.unwrap_or_default(), runs, drift, bytes, roles })
    }

    /// The id of the run that declares `role`, if one does.
    pub fn run_with_role(&self, role: &str) -> Option<&str> {
        self.roles.get(role).map(String::as_str)
    }
}

/// Whether `line` (without its end) declares a role: `role = "NAME"` and nothing else.
fn is_role_line(line: &[u8]) -> bool {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    line.strip_prefix(b"role = \"").and_then(|r| r.strip_suffix(b"\"")).is_some_and(|name| name.iter().all(|&b| is_role_byte(b)))
}

fn is_role_byte(b: u8) -> bool {
    b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-'
}

/// The manifest's bytes without its `role = "..."` lines: what the provenance hashes. A role
/// says what a run stands for to CLAIMS and the figures and changes no number, so declaring or
/// renaming one does not make the stored runs stale (their `manifest_sha256` stays); everything
/// else in the file does.
pub fn without_roles(bytes: &[u8]) -> Vec<u8> {
    bytes.split_inclusive(|&b| b == b'\n').filter(|l| !is_role_line(l.strip_suffix(b"\n").unwrap_or(l))).flatten().copied().collect()
}

/// Every role declared as a line of its own (`role = "NAME"`, which [`without_roles`] leaves out
/// of the hash): as many such lines in `text` as declared roles. A role written otherwise (an
/// inline table, a comment after it) would be hashed, and declaring or renaming it would look
/// like a change of the runs; it is refused here.
fn check_role_lines(roles: &[Option<String>], text: &str, invalid: &Invalid) -> Result<(), ManifestError> {
    let lines = text.as_bytes().split(|&b| b == b'\n').filter(|l| is_role_line(l)).count();
    let declared: Vec<(usize, &str)> = roles.iter().enumerate().filter_map(|(i, r)| Some((i, r.as_deref()?))).collect();
    match declared.first() {
        Some(&(i, role)) if lines != declared.len() => Err(invalid.at(
            format!("run[{i}].role"),
            "every role as role = \"NAME\" on a line of its own in its [[run]] table, NAME of lower-case letters, digits and '-' (the provenance hashes the manifest without these lines)",
            format!("{} role(s) declared, {lines} such line(s) (the first role: {role:?})", declared.len()),
        )),
        _ => Ok(()),
    }
}

/// A run's role: a name of lower-case letters, digits and '-' not declared by an earlier run of
/// the study (`roles`: the earlier runs' roles and ids). The error's (expected, got).
fn check_role(role: &str, id: &str, roles: &mut BTreeMap<String, String>) -> Result<(), (String, String)> {
    if role.is_empty() || !role.bytes().all(is_role_byte) {
        return Err(("a role of lower-case letters, digits and '-'".into(), format!("{role:?}")));
    }
    if let Some(other) = roles.get(role) {
        return Err((
            "a role declared once in the study (the CLAIMS rows and figures that need it read one run)".into(),
            format!("role {role:?} twice, by runs {other:?} and {id:?}"),
        ));
    }
    roles.insert(role.to_string(), id.to_string());
    Ok(())
}

/// Builds the error for a key of the manifest `.0` that does not hold what is expected.
struct Invalid<'a>(&'a Path);

impl Invalid<'_> {
    fn at(&self, key: String, expected: &str, got: String) -> ManifestError {
        ManifestError::Invalid { file: self.0.to_path_buf(), key, expected: expected.to_string(), got }
    }
}

/// `[defaults]` holds what runs share: no run name, no `no_reference`.
fn check_defaults(d: &RunToml, invalid: &Invalid) -> Result<(), ManifestError> {
    if d.id.is_some() {
        return Err(invalid.at(
            "defaults.id".into(),
            "no id in [defaults] (every [[run]] names its own)",
            format!("{:?}", d.id.clone().unwrap_or_default()),
        ));
    }
    if let Some(role) = &d.role {
        return Err(invalid.at(
            "defaults.role".into(),
            "no role in [defaults] (a role is one run's, in its [[run]] table)",
            format!("{role:?}"),
        ));
    }
    if d.no_reference.is_some() {
        return Err(invalid.at(
            "defaults.no_reference".into(),
            "no_reference only in a [[run]] (leave [defaults.reference] out instead)",
            "a value".into(),
        ));
    }
    Ok(())
}

/// The longest run id: the longest file name the store makes from an id is a snapshot's
/// temporary `.ID_levelL.json.tmpPID.N` (`records::temporary_for`, `StudyDir::mesh_file`), which
/// adds at most 67 bytes to the id (a level and a counter of 20 digits, a process id of 10), and
/// a file name has at most 255 bytes (NAME_MAX). 128 leaves room for what a later name may add.
pub const RUN_ID_MAX: usize = 128;

/// `[[run]]` number `i`, completed from `[defaults]` `d` and checked key by key; `ids` holds the
/// names of the runs before it, `roles` their roles (role -> id).
fn parse_run(
    path: &Path,
    i: usize,
    r: &RunToml,
    d: &RunToml,
    (ids, roles): (&mut std::collections::BTreeSet<String>, &mut BTreeMap<String, String>),
    invalid: &Invalid,
) -> Result<(PlannedRun, Option<String>), ManifestError> {
    let key = |k: &str| format!("run[{i}].{k}");
    let id = r.id.clone().ok_or_else(|| invalid.at(key("id"), "a run name (string)", "nothing".into()))?;
    // the first character a letter or digit: a record runs/.ID.json would be a hidden file, and
    // the store's temporaries (.NAME.tmpPID.N) and leftovers start with '.'
    if !id.starts_with(|c: char| c.is_ascii_alphanumeric()) || !id.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)) {
        return Err(invalid.at(
            key("id"),
            "a name of letters, digits, '_', '-', '.' that starts with a letter or digit",
            format!("{id:?}"),
        ));
    }
    if id.len() > RUN_ID_MAX {
        return Err(invalid.at(
            key("id"),
            &format!("a name of at most {RUN_ID_MAX} characters (the store's file names made from it must fit in 255 bytes)"),
            format!("{} characters", id.len()),
        ));
    }
    // unique ignoring case too: runs/A.json and runs/a.json are one file where the results folder
    // is copied to a case-insensitive file system (macOS, Windows)
    if let Some(other) = ids.iter().find(|o| o.eq_ignore_ascii_case(&id)) {
        let got = if *other == id { format!("{id:?} twice") } else { format!("{id:?} and {other:?}, the same name but for case") };
        return Err(invalid.at(key("id"), "a name unique within the study (ignoring case: the records' file names)", got));
    }
    ids.insert(id.clone());
    let role = r.role.clone();
    if let Some(role) = &role {
        check_role(role, &id, roles).map_err(|(expected, got)| invalid.at(key("role"), &expected, got))?;
    }
    let problem = r.problem.clone().or(d.problem.clone()).ok_or_else(|| invalid.at(key("problem"), "a problem name", "nothing".into()))?;
    let problem = if model::problems::is_file(&problem) { spelled_for(path, &problem) } else { problem };
    let mut constants = d.constants.clone().unwrap_or_default();
    constants.extend(r.constants.clone().unwrap_or_default());
    if let Err(e) = model::problems::load(&resolve_problem(path, &problem), &constants) {
        let expected = match e {
            model::problems::ProblemError::Unknown(_) => format!(
                "a built-in problem ({}) or the path of a problem file (NAME.toml, relative to the manifest)",
                model::problems::KNOWN.join(", ")
            ),
            model::problems::ProblemError::File(e) => format!("a valid problem file ({e})"),
            model::problems::ProblemError::Constants(_) => {
                return Err(invalid.at(
                    key("constants"),
                    "no constants: the problem is built in",
                    format!("{constants:?} for {problem:?}"),
                ));
            }
        };
        return Err(invalid.at(key("problem"), &expected, format!("{problem:?}")));
    }
    let mesh = r.mesh.clone().or(d.mesh.clone()).unwrap_or_else(|| MeshSpec::DEFAULT.into());
    // one mesh, one spelling: `structured:04` and `structured: 4` are `structured:4`
    let mesh = match mesh.strip_prefix("gmsh:") {
        Some(file) => format!("gmsh:{}", spelled_for(path, file.trim())),
        None => MeshSpec::parse(&mesh).map(|m| m.to_string()).unwrap_or(mesh),
    };
    MeshSpec::parse(&resolve_mesh(path, &mesh)).map_err(|e| invalid.at(key("mesh"), &e.expected(), format!("{mesh:?}")))?;
    let levels = r.levels.or(d.levels).ok_or_else(|| invalid.at(key("levels"), "a number of levels >= 1", "nothing".into()))?;
    let defaults = AdaptConfig::default();
    let theta = r.theta.or(d.theta).unwrap_or(defaults.theta);
    let e = defaults.estimator;
    let (eo, ed) = (r.estimator.clone().unwrap_or_default(), d.estimator.clone().unwrap_or_default());
    let estimator = EstimatorConfig {
        c0: eo.c0.or(ed.c0).unwrap_or(e.c0),
        contact_term: eo.contact_term.or(ed.contact_term).unwrap_or(e.contact_term),
        log_factor: eo.log_factor.or(ed.log_factor).unwrap_or(e.log_factor),
        sampling: eo.sampling.or(ed.sampling).unwrap_or(e.sampling),
        stress_frame: eo.stress_frame.or(ed.stress_frame).unwrap_or(e.stress_frame),
    };
    check_no_reference(r, d).map_err(|(expected, got)| invalid.at(key("no_reference"), expected, got))?;
    let reference = if r.no_reference == Some(true) { None } else { r.reference.clone().or(d.reference.clone()) };
    if let Some(rf) = &reference
        && !(rf.theta > 0.0 && rf.theta <= 1.0)
    {
        return Err(invalid.at(key("reference.theta"), "a number in (0, 1]", model::settings::estimator::ConfigError::number(rf.theta)));
    }
    let inputs = input_hashes(path, &problem, &mesh).map_err(|(k, e)| invalid.at(key(k), "a readable file", e))?;
    let spec = RunSpec {
        id,
        problem,
        mesh,
        refine: r.refine.or(d.refine).unwrap_or(defaults.refine),
        theta,
        levels,
        max_ndof: r.max_ndof.or(d.max_ndof),
        stop_ndof: r.stop_ndof.or(d.stop_ndof),
        estimator,
        reference: reference.map(|rf| ReferenceSpec {
            theta: rf.theta,
            min_ndof: rf.min_ndof,
            contact_term: rf.contact_term.unwrap_or(ReferenceSpec::DEFAULT_CONTACT_TERM),
        }),
        save_levels: r.save_levels.clone().or(d.save_levels.clone()).unwrap_or_default(),
        constants,
        inputs,
    };
    spec.adapt_config().validate().map_err(|e| invalid.at(key(e.key), &e.expected, e.got))?;
    let quick_levels = r.quick_levels.or(d.quick_levels).unwrap_or(levels.min(6));
    if quick_levels == 0 || quick_levels > levels {
        return Err(invalid.at(key("quick_levels"), &format!("a number in 1..={levels} (levels)"), quick_levels.to_string()));
    }
    if let Some(&l) = spec.save_levels.iter().find(|&&l| l >= levels) {
        return Err(invalid.at(
            key("save_levels"),
            &format!("levels in 0..={} (the run has {levels} levels, numbered from 0)", levels - 1),
            l.to_string(),
        ));
    }
    if let Some(l) = first_repeated(&spec.save_levels) {
        return Err(invalid.at(
            key("save_levels"),
            "distinct levels (each level is saved once)",
            format!("{:?} (level {l} more than once)", spec.save_levels),
        ));
    }
    if spec.reference.as_ref().is_some_and(|rf| rf.min_ndof == 0) {
        return Err(invalid.at(key("reference.min_ndof"), "a number of unknowns >= 1", "0".into()));
    }
    Ok((PlannedRun { spec, quick_levels }, role))
}

/// `[drift]`: tolerances in range for float fields of the records (not the derived ones, which
/// are checked by definition), and rate checks on declared runs.
fn check_drift(drift: &DriftSpec, runs: &[PlannedRun], invalid: &Invalid) -> Result<(), ManifestError> {
    if let Some(deep) = &drift.deep {
        if deep.replay_max_ndof == Some(0) {
            return Err(invalid.at("drift.deep.replay_max_ndof".into(), "a positive number of unknowns", "0".into()));
        }
        for (tier, ids) in [("full", &deep.full), ("replay", &deep.replay)] {
            for (i, id) in ids.iter().enumerate() {
                if !runs.iter().any(|p| &p.spec.id == id) {
                    return Err(invalid.at(format!("drift.deep.{tier}[{i}]"), "the id of a declared run", format!("{id:?}")));
                }
            }
        }
    }
    let floats = model::level::record::float_fields();
    for (key, tol) in
        std::iter::once(("default".to_string(), &drift.default)).chain(drift.fields.iter().map(|(k, t)| (format!("fields.{k}"), t)))
    {
        if let Some(name) = key.strip_prefix("fields.") {
            if DERIVED.iter().any(|(f, _)| *f == name) {
                return Err(invalid.at(
                    format!("drift.{key}"),
                    "a field with a tolerance of its own; this one is checked by its definition, exactly",
                    format!("{name:?}"),
                ));
            }
            if !floats.iter().any(|f| f == name) {
                return Err(invalid.at(
                    format!("drift.{key}"),
                    &format!("a float field of the level records ({})", floats.join(", ")),
                    format!("{name:?}"),
                ));
            }
        }
        for (part, v) in [("rel", tol.rel), ("floor", tol.floor)] {
            if !(v.is_finite() && (0.0..=MAX_TOLERANCE).contains(&v)) {
                return Err(invalid.at(format!("drift.{key}.{part}"), TOLERANCE_RANGE, format!("{v:e}")));
            }
        }
    }
    for (i, r) in drift.rates.iter().enumerate() {
        let key = |k: &str| format!("drift.rates[{i}].{k}");
        let Some(run) = runs.iter().find(|p: &&PlannedRun| p.spec.id == r.run) else {
            return Err(invalid.at(key("run"), "the id of a declared run", format!("{:?}", r.run)));
        };
        if !floats.contains(&r.field) {
            return Err(invalid.at(
                key("field"),
                &format!("a float field of the level records ({})", floats.join(", ")),
                format!("{:?}", r.field),
            ));
        }
        if !r.min.is_finite() {
            return Err(invalid.at(key("min"), "a finite rate", model::settings::estimator::ConfigError::number(r.min)));
        }
        if r.last < 2 || r.last > run.spec.levels {
            return Err(invalid.at(
                key("last"),
                &format!("a number of levels in 2..={} (run {} has {} levels)", run.spec.levels, r.run, run.spec.levels),
                r.last.to_string(),
            ));
        }
    }
    Ok(())
}

/// The largest drift tolerance, `rel` or `floor`: a relative change of 1 already lets a number
/// fall to 0 or double unnoticed, and `floor = 1` lets it move by the largest value the field
/// takes in its run, so a larger tolerance checks nothing. The measured ones
/// (`results/roundoff/`) are below 1e-6.
pub const MAX_TOLERANCE: f64 = 1.0;
const TOLERANCE_RANGE: &str = "a number in [0, 1] (a tolerance above 1 lets any change pass: rel = 1 already accepts a number falling to 0 or doubling; the measured tolerances are below 1e-6)";

/// `no_reference = true` drops the defaults' reference from one run; anything else is a mistake:
/// `false` (which means nothing), alongside the run's own `reference` (which it would silently
/// drop), or with no reference in `[defaults]` to drop. The error's (expected, got).
fn check_no_reference(run: &RunToml, defaults: &RunToml) -> Result<(), (&'static str, String)> {
    match run.no_reference {
        None => Ok(()),
        Some(false) => Err(("true (drop the reference of [defaults] in this run) or no key at all", "false".into())),
        Some(true) if run.reference.is_some() => {
            Err(("either the run's own reference or no_reference = true, not both", "no_reference = true beside reference".into()))
        }
        Some(true) if defaults.reference.is_none() => {
            Err(("no_reference = true only where [defaults] declares a reference to drop", "true, but [defaults] has no reference".into()))
        }
        Some(true) => Ok(()),
    }
}

/// The first value that occurs twice in `values`.
fn first_repeated(values: &[usize]) -> Option<usize> {
    let mut seen = std::collections::BTreeSet::new();
    values.iter().copied().find(|v| !seen.insert(*v))
}

/// The problem a manifest at `manifest` means by `problem`: a built-in name as it is, the path of
/// a problem file relative to the manifest's folder (an absolute path as it is). The run's spec
/// (and so its record) keeps `problem` as written; the provenance records the file and its hash.
pub fn resolve_problem(manifest: &Path, problem: &str) -> String {
    if !model::problems::is_file(problem) || Path::new(problem).is_absolute() {
        return problem.to_string();
    }
    manifest.parent().unwrap_or(Path::new("")).join(problem).display().to_string()
}

/// The mesh a manifest at `manifest` means by `mesh`: a built-in mesh as it is, a Gmsh file
/// (`gmsh:PATH`) relative to the manifest's folder (an absolute path as it is). Like the problem,
/// the run's spec keeps `mesh` as written; the provenance records the file and its hash.
pub fn resolve_mesh(manifest: &Path, mesh: &str) -> String {
    match mesh.strip_prefix("gmsh:") {
        Some(f) if !f.trim().is_empty() && Path::new(f.trim()).is_relative() => {
            format!("gmsh:{}", manifest.parent().unwrap_or(Path::new("")).join(f.trim()).display())
        }
        _ => mesh.to_string(),
    }
}

/// A relative path as the spec holds it, whatever way the manifest spells it: `.` components
/// dropped and `dir/..` collapsed lexically (`./problems/../problems/p.toml` is
/// `problems/p.toml`), so that one file spelt two ways is one spec, not a changed input. An
/// absolute path, or one that climbs above the manifest's folder, keeps its leading part.
pub fn spelled(path: &str) -> String {
    if path.is_empty() {
        return String::new();
    }
    let absolute = path.starts_with('/');
    let mut parts: Vec<&str> = Vec::new();
    for part in path.split('/') {
        match part {
            "" | "." => {}
            ".." if parts.last().is_some_and(|p| *p != "..") => {
                parts.pop();
            }
            ".." if absolute => {}
            other => parts.push(other),
        }
    }
    let joined = parts.join("/");
    if absolute {
        format!("/{joined}")
    } else if joined.is_empty() {
        ".".into()
    } else {
        joined
    }
}

/// [`spelled`], and an absolute path inside the folder of the manifest at `manifest` made
/// relative to it, as a relative one is written: `/home/me/study/p.toml` in
/// `/home/me/study/s.toml` is `p.toml` (the same file, one spec; compared lexically, so a path
/// through a symbolic link keeps its spelling).
pub fn spelled_for(manifest: &Path, path: &str) -> String {
    let path = spelled(path);
    let folder = manifest.parent().and_then(|d| std::path::absolute(d).ok()).map(|d| spelled(&d.to_string_lossy()));
    match folder.and_then(|d| path.strip_prefix(&format!("{}/", d.trim_end_matches('/'))).map(str::to_string)) {
        Some(inside) if !inside.is_empty() => inside,
        _ => path,
    }
}

/// The files a run with `problem` and `mesh` reads (a problem file, a Gmsh mesh): for each,
/// the key naming it in the manifest (`problem` or `mesh`), the path as the manifest writes it
/// (the key of [`RunSpec::inputs`]) and the path resolved against the manifest's folder.
pub fn input_files(manifest: &Path, problem: &str, mesh: &str) -> Vec<(&'static str, String, PathBuf)> {
    let mut out = Vec::new();
    if model::problems::is_file(problem) {
        out.push(("problem", problem.to_string(), PathBuf::from(resolve_problem(manifest, problem))));
    }
    if let Ok(spec) = MeshSpec::parse(&resolve_mesh(manifest, mesh))
        && let Some(file) = spec.file()
    {
        out.push(("mesh", mesh.strip_prefix("gmsh:").unwrap_or(mesh).trim().to_string(), file.to_path_buf()));
    }
    out
}

/// The SHA-256 of every file a run with `problem` and `mesh` reads ([`input_files`]), keyed by
/// the path as the manifest writes it ([`RunSpec::inputs`]). A file that cannot be read is an
/// error for the key naming it: (`problem` or `mesh`, the path and why).
pub fn input_hashes(manifest: &Path, problem: &str, mesh: &str) -> Result<BTreeMap<String, String>, (&'static str, String)> {
    let mut out = BTreeMap::new();
    for (key, written, resolved) in input_files(manifest, problem, mesh) {
        let kind = if key == "mesh" { model::mesh::gmsh::MESH_FILE } else { model::problems::file::PROBLEM_FILE };
        let bytes = model::base::input::read(&resolved, kind).map_err(|e| (key, format!("{}: {e}", resolved.display())))?;
        out.insert(written, model::base::digest::sha256_hex(&bytes));
    }
    Ok(out)
}

/// Pin the input files of a run with `spec` (of the manifest at `manifest`) to the bytes its
/// spec holds the hashes of ([`model::base::pin`]): until the guard is dropped, a read of one
/// of them with other bytes is an error naming it, so the record's `inputs` are the hashes of
/// what the run parsed. (A file the spec holds no hash of, a record of an older format, is not
/// pinned.)
pub fn pin_inputs(manifest: &Path, spec: &RunSpec) -> model::base::pin::Pins {
    model::base::pin::pin(
        input_files(manifest, &spec.problem, &spec.mesh)
            .into_iter()
            .filter_map(|(_, written, resolved)| spec.inputs.get(&written).map(|h| (resolved, h.clone()))),
    )
}

impl Manifest {
    /// The mesh files the runs read, resolved ([`resolve_mesh`]), without repetition.
    pub fn mesh_files(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = self
            .runs
            .iter()
            .filter_map(|r| MeshSpec::parse(&resolve_mesh(&self.file, &r.spec.mesh)).ok()?.file().map(Path::to_path_buf))
            .collect();
        files.sort();
        files.dedup();
        files
    }

    /// The SHA-256 each input file of the runs had when the manifest was read (their specs'
    /// `inputs`), by resolved path: the bytes every run reads, since they are pinned to it
    /// ([`pin_inputs`]). What the provenance records, without reading the files again.
    pub fn planned_hashes(&self) -> BTreeMap<PathBuf, String> {
        let mut out = BTreeMap::new();
        for r in &self.runs {
            for (_, written, resolved) in input_files(&self.file, &r.spec.problem, &r.spec.mesh) {
                if let Some(h) = r.spec.inputs.get(&written) {
                    out.insert(resolved, h.clone());
                }
            }
        }
        out
    }

    /// The problem files the runs name, resolved ([`resolve_problem`]), without repetition.
    pub fn problem_files(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = self
            .runs
            .iter()
            .filter(|r| model::problems::is_file(&r.spec.problem))
            .map(|r| PathBuf::from(resolve_problem(&self.file, &r.spec.problem)))
            .collect();
        files.dedup();
        files
    }
}

/// How many times a level's NDF a reference solution must have for the level's errors to be
/// measured against it: a level at the reference's own NDF measures 1e-17 (its own mesh), and
/// levels near it measure the reference's error, not theirs. 1.5 is below the smallest margin
/// of the stored studies, 1.89 (`ex72`'s uniform run, NDF 132,098, against its adaptive
/// reference of 250,070; hertz's manifest keeps 3.3 by convention), so that none is refused,
/// and far above a reference coarser than the run (such as NDF 218 against 710).
pub const REFERENCE_MARGIN: f64 = 1.5;

/// Whether a reference of `reference_ndof` unknowns is too coarse to measure a level of
/// `level_ndof` ([`REFERENCE_MARGIN`]).
pub fn too_coarse_for(reference_ndof: usize, level_ndof: usize) -> bool {
    (reference_ndof as f64) < REFERENCE_MARGIN * level_ndof as f64
}

impl Manifest {
    /// What a run needs of its files and of this machine, checked for every run before any is
    /// solved (a mistake in the last run must not cost the first one's): the mesh is read and
    /// built with the run's problem (a missing or malformed mesh file, a boundary group the
    /// problem does not name, a kink that is not a vertex), the initial mesh and the reference
    /// solution's `min_ndof` fit in this machine's memory ([`check_memory`](model::base::memory::check_memory)),
    /// `max_ndof` is at least the initial mesh's unknowns (level 0 is always solved), and a
    /// reference is declared only for a problem without an exact solution.
    pub fn check_runs(&self) -> Result<(), ManifestError> {
        for (i, planned) in self.runs.iter().enumerate() {
            self.check_run(i, &planned.spec)?;
        }
        Ok(())
    }

    fn check_run(&self, i: usize, spec: &RunSpec) -> Result<(), ManifestError> {
        let invalid = |k: &str, expected: String, got: String| ManifestError::Invalid {
            file: self.file.clone(),
            key: format!("run[{i}].{k}"),
            expected,
            got: format!("{got} (run {})", spec.id),
        };
        let problem = model::problems::load(&resolve_problem(&self.file, &spec.problem), &spec.constants)
            .map_err(|e| invalid("problem", "a problem that loads".into(), format!("{:?}: {e}", spec.problem)))?;
        let mesh_spec = MeshSpec::parse(&resolve_mesh(&self.file, &spec.mesh))
            .map_err(|e| invalid("mesh", e.expected(), format!("{:?}", spec.mesh)))?;
        let ndof = mesh_spec.ndof().map_err(|e| invalid("mesh", "a readable mesh file".into(), format!("{:?}: {e}", spec.mesh)))?;
        model::base::memory::check_memory(&format!("the initial mesh {}", spec.mesh), ndof)
            .map_err(|e| invalid("mesh", "an initial mesh that fits in this machine's memory".into(), e.to_string()))?;
        mesh_spec
            .build(problem.as_ref())
            .map_err(|e| invalid("mesh", format!("a mesh problem {} can be solved on", spec.problem), format!("{:?}: {e}", spec.mesh)))?;
        spec.adapt_config().check_initial(ndof, &spec.mesh).map_err(|e| invalid(e.key, e.expected, e.got))?;
        if let Some(rf) = &spec.reference {
            if problem.exact().is_some() {
                return Err(invalid(
                    "reference",
                    format!("no reference: problem {} has an exact solution, which the errors are measured against", spec.problem),
                    format!("a reference with min_ndof {}", rf.min_ndof),
                ));
            }
            // level 0 is always measured: a reference that may stop short of the margin above it
            // measures nothing (the levels' own NDF is checked as each is solved)
            if too_coarse_for(rf.min_ndof, ndof as usize) {
                return Err(invalid(
                    "reference.min_ndof",
                    format!(
                        "at least {} times the NDF of every level measured against it; level 0 ({}) has {ndof:.0}, so at least {:.0} (more: the reference must be finer than the run's last level)",
                        REFERENCE_MARGIN,
                        spec.mesh,
                        (REFERENCE_MARGIN * ndof).ceil()
                    ),
                    rf.min_ndof.to_string(),
                ));
            }
            model::base::memory::check_memory(&format!("the reference solution (min_ndof {})", rf.min_ndof), rf.min_ndof as f64).map_err(
                |e| invalid("reference.min_ndof", "a reference solution that fits in this machine's memory".into(), e.to_string()),
            )?;
        }
        Ok(())
    }
}

/// The declared studies: every `*.toml` in `dir`, sorted by name; with `only`, just those
/// (an unknown name is an error listing the declared ones).
pub fn declared(dir: &Path, only: &[String]) -> anyhow::Result<Vec<Manifest>> {
    use anyhow::Context;
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| {
            format!(
                "reading the study manifests in {} (relative to the current folder; pass --experiments DIR where they are elsewhere)",
                dir.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    if files.is_empty() {
        anyhow::bail!("{} holds no study manifest (*.toml): nothing to do (the studies are declared in experiments/)", dir.display());
    }
    // a study is named by its file's stem (`Manifest::parse`): the named ones are found, and
    // only they are read, before any file is parsed
    let stem = |f: &PathBuf| f.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    for name in only {
        if !files.iter().any(|f| &stem(f) == name) {
            anyhow::bail!("unknown study '{name}'; declared studies: {}", files.iter().map(stem).collect::<Vec<_>>().join(", "));
        }
    }
    files
        .iter()
        .filter(|f| only.is_empty() || only.contains(&stem(f)))
        .map(|f| Manifest::load(f).map_err(|e| not_a_manifest(f, e)))
        .collect()
}

/// A manifest's error, with a word where the file is a problem file put beside the manifests
/// (its tables are a problem's, not a study's).
fn not_a_manifest(file: &Path, error: ManifestError) -> anyhow::Error {
    // through the one reader: a named pipe (refused by `load`) must not be read here either
    let tables = model::base::input::read_text(file, MANIFEST).ok().and_then(|t| t.parse::<toml::Table>().ok()).unwrap_or_default();
    let problem_like = ["material", "contact", "parts", "body_force", "dirichlet"].iter().any(|k| tables.contains_key(*k));
    if problem_like && !tables.contains_key("run") {
        anyhow::anyhow!(
            "{error}\n{} looks like a problem file (it has the tables of a problem: [material], [contact], [parts], ...), not a study manifest: every *.toml in the manifests' folder is read as a study; keep problem files in a subfolder (experiments/problems/ holds the declared ones)",
            file.display()
        )
    } else {
        anyhow::Error::new(error)
    }
}
