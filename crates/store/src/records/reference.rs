//! The stored form of a reference solution (`results/STUDY/references/KEY.json`): not its
//! values (4.5e6 unknowns would be hundreds of megabytes) but how to rebuild them exactly: the
//! refinement history of the adaptive loop that computed it and the record of its last level.
//! With the run's initial mesh, the history rebuilds the last mesh (every level's fingerprint
//! checked) and its stored warm start solves it again to the same numbers in one solve
//! (`study::reference::replay`), where the adaptive loop solves every level.

use super::{History, LevelRecord, ReferenceSpec, RunSpec};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A reference solution as stored: what it is the reference of (problem, constants, initial
/// mesh, the inputs' hashes and how it was computed) and how to rebuild it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    pub problem: String,
    pub mesh: String,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub constants: BTreeMap<String, f64>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, String>,
    pub spec: ReferenceSpec,
    #[serde(flatten)]
    pub rebuild: Rebuild,
}

/// How to rebuild a reference solution from the initial mesh, whatever it is the reference of.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rebuild {
    /// NDF of the reference solution (its last level).
    pub ndof: usize,
    /// The record of the last level (timings and memory as measured when it was computed).
    pub last: LevelRecord,
    /// The refinement history of every level of the loop, the last included.
    pub history: History,
    /// The active set the last level's solve ended with. A replay starts its active-set
    /// iteration there: the first iteration solves the converged iteration's system, the same
    /// solution in one numeric factorisation where the loop's warm start took several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub final_active: Option<model::level::history::Flags>,
}

/// What identifies a run's reference solution: everything it is computed from.
#[derive(Serialize)]
struct Identity<'a> {
    problem: &'a str,
    mesh: &'a str,
    constants: &'a BTreeMap<String, f64>,
    inputs: &'a BTreeMap<String, String>,
    spec: &'a ReferenceSpec,
}

impl ReferenceRecord {
    /// The record of `run`'s reference solution (its spec declares `spec`), rebuilt by `rebuild`.
    pub fn new(run: &RunSpec, spec: &ReferenceSpec, rebuild: Rebuild) -> Self {
        ReferenceRecord {
            problem: run.problem.clone(),
            mesh: run.mesh.clone(),
            constants: run.constants.clone(),
            inputs: run.inputs.clone(),
            spec: spec.clone(),
            rebuild,
        }
    }

    /// The file name's key of `run`'s reference solution (None without one): the first 16 hex
    /// digits of the SHA-256 of what it is computed from, so runs sharing a reference share
    /// the file and a reference computed from anything else never is taken for it.
    pub fn key_of(run: &RunSpec) -> Option<String> {
        let spec = run.reference.as_ref()?;
        Some(key(&Identity { problem: &run.problem, mesh: &run.mesh, constants: &run.constants, inputs: &run.inputs, spec }))
    }

    /// This record's key ([`ReferenceRecord::key_of`] of the runs it belongs to).
    pub fn key(&self) -> String {
        key(&Identity { problem: &self.problem, mesh: &self.mesh, constants: &self.constants, inputs: &self.inputs, spec: &self.spec })
    }
}

fn key(identity: &Identity) -> String {
    use sha2::Digest;
    let bytes = serde_json::to_vec(identity).expect("a reference's identity serialises");
    let digest = sha2::Sha256::digest(bytes);
    digest.iter().take(8).map(|b| format!("{b:02x}")).collect()
}
