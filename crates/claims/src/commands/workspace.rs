//! The declared studies, read once: every manifest of the experiments folder parsed and
//! checked (its runs, its problem files and meshes named), with the run roles CLAIMS.md and the
//! figures read checked against them. `figures`, `report` and `drift` are handed one
//! [`Workspace`] and read no manifest themselves.

use crate::analysis::roles::{self, Roles};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use store::study::manifest::{self, Manifest};

/// The experiments folder as read: its manifests and the roles of their runs.
pub struct Workspace {
    /// Where the manifests are (`experiments/` unless `--experiments` says otherwise).
    pub experiments: PathBuf,
    /// Every declared study, in the order of its file's name.
    pub manifests: Vec<Manifest>,
    /// The runs CLAIMS.md and the figures read, by role, each declared by a manifest.
    pub roles: Roles,
}

impl Workspace {
    /// Read and check every manifest of `experiments`, and the roles the claims need.
    pub fn load(experiments: &Path) -> Result<Self> {
        let manifests = manifest::declared(experiments, &[])?;
        let roles = roles::check(&manifests)?;
        Ok(Workspace { experiments: experiments.to_path_buf(), manifests, roles })
    }

    /// The studies named by `only` (every declared one when it is empty), in file order; a
    /// name no manifest declares is refused, listing the declared ones.
    pub fn studies(&self, only: &[String]) -> Result<Vec<Manifest>> {
        if let Some(name) = only.iter().find(|n| !self.manifests.iter().any(|m| &m.study == *n)) {
            let declared: Vec<&str> = self.manifests.iter().map(|m| m.study.as_str()).collect();
            bail!("unknown study '{name}'; declared studies: {}", declared.join(", "));
        }
        Ok(self.manifests.iter().filter(|m| only.is_empty() || only.contains(&m.study)).cloned().collect())
    }
}
