//! Run roles: what a stored run stands for to CLAIMS.md and the figures. A run declares its role
//! in its manifest (`role = "as-written"` in its `[[run]]` table, unique within the study); the
//! rows and figures name the roles they need ([`NEEDED`], one constant each) and find their runs
//! through [`Roles::find`] alone, never by a run id. [`check`] compares the needed roles with
//! the declared ones when the manifests are read (`signorini figures`, `drift` and `report`): a
//! role a study does not declare is an error naming the role, the study and what needs it, not a
//! row without data.

use crate::analysis::studies::{self, Study};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use store::records::RunRecord;
use store::study::manifest::Manifest;

/// A role a CLAIMS row or a figure needs: in study `study`, the run that declares `name`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Role {
    pub study: Study,
    pub name: &'static str,
    /// What needs it (in the error when no run declares it).
    pub by: &'static str,
}

/// The role constants and [`NEEDED`], the list of all of them (so no constant is left out of
/// the check).
macro_rules! roles {
    ($($(#[$doc:meta])* $id:ident = ($study:expr, $name:literal, $by:literal);)*) => {
        $($(#[$doc])* pub const $id: Role = Role { study: $study, name: $name, by: $by };)*
        /// Every role a CLAIMS row or a figure needs.
        pub const NEEDED: &[Role] = &[$($id),*];
    };
}

roles! {
    /// Example 7.1, adaptive with eta_5 as written (the paper's run).
    EX71_AS_WRITTEN = (studies::EX71, "as-written", "the CLAIMS rows 7.1-* (where deep is not stored) and the figure fig4a");
    /// Its twin with the estimator's maxima on the dense lattice.
    EX71_AS_WRITTEN_DENSE = (studies::EX71, "as-written-dense", "the dense pass of the CLAIMS rows 7.1-* (row sampling)");
    EX71_UNIFORM = (studies::EX71, "uniform", "the CLAIMS rows 7.1-* (where deep is not stored)");
    /// Uniform refinement with sigma-hat read as Cartesian components.
    EX71_UNIFORM_CARTESIAN = (studies::EX71, "uniform-cartesian", "the CLAIMS row 7.1-eta5");
    EX72_AS_WRITTEN = (studies::EX72, "as-written", "the CLAIMS rows 7.2-* and the figures fig3b, fig4b");
    EX72_AS_WRITTEN_DENSE = (studies::EX72, "as-written-dense", "the dense pass of the CLAIMS rows 7.2-* (row sampling)");
    EX72_UNIFORM = (studies::EX72, "uniform", "the CLAIMS rows 7.2-* (where ex72_large holds no errors)");
    ABLATION_EX71_WFC = (studies::CONTACT_TERM_ABLATION, "ex71-without-full-contact", "the CLAIMS rows 7.1-* (where deep is not stored)");
    ABLATION_EX71_WFC_DENSE =
        (studies::CONTACT_TERM_ABLATION, "ex71-without-full-contact-dense", "the dense pass of the CLAIMS rows 7.1-* (row sampling)");
    ABLATION_EX72_WFC =
        (studies::CONTACT_TERM_ABLATION, "ex72-without-full-contact", "the CLAIMS rows 7.2-error, 7.2-refinement and the figure fig3b_variant");
    ABLATION_EX72_AS_WRITTEN = (studies::CONTACT_TERM_ABLATION, "ex72-as-written", "the CLAIMS row 7.2-error");
    DEEP_EX71_AS_WRITTEN = (studies::DEEP, "ex71-as-written", "the CLAIMS rows 7.1-*, efficiency-size, estimator-repair and the figure deep_floor");
    DEEP_EX71_WFC = (studies::DEEP, "ex71-without-full-contact", "the CLAIMS rows 7.1-*, efficiency-size and estimator-repair");
    DEEP_EX71_REPAIRED = (studies::DEEP, "ex71-repaired", "the CLAIMS rows efficiency-size, estimator-repair and the figure estimator_repair");
    DEEP_EX71_UNIFORM = (studies::DEEP, "ex71-uniform", "the CLAIMS rows 7.1-*, estimator-repair and the figure deep_floor");
    DEEP_FB_AS_WRITTEN = (studies::DEEP, "fb-as-written", "the CLAIMS rows fb-*, efficiency-size, estimator-repair and the figure deep_floor");
    DEEP_FB_WFC = (studies::DEEP, "fb-without-full-contact", "the CLAIMS rows fb-*, efficiency-size and estimator-repair");
    DEEP_FB_REPAIRED = (studies::DEEP, "fb-repaired", "the CLAIMS rows efficiency-size, estimator-repair and the figure estimator_repair");
    DEEP_FB_UNIFORM = (studies::DEEP, "fb-uniform", "the CLAIMS rows fb-*, estimator-repair and the figure deep_floor");
    LARGE_AS_WRITTEN = (studies::EX72_LARGE, "as-written", "the CLAIMS rows 7.2-*, efficiency-size and estimator-repair");
    LARGE_WFC = (studies::EX72_LARGE, "without-full-contact", "the CLAIMS rows 7.2-*, efficiency-size and estimator-repair");
    LARGE_REPAIRED = (studies::EX72_LARGE, "repaired", "the CLAIMS rows efficiency-size, estimator-repair and the figure estimator_repair");
    LARGE_UNIFORM = (studies::EX72_LARGE, "uniform", "the CLAIMS rows 7.2-* and estimator-repair");
    ROLLERS_AS_WRITTEN = (studies::EX72_ROLLERS, "as-written", "the CLAIMS rows 7.2r-* and efficiency-size");
    ROLLERS_WFC = (studies::EX72_ROLLERS, "without-full-contact", "the CLAIMS rows 7.2r-* and efficiency-size");
    ROLLERS_REPAIRED = (studies::EX72_ROLLERS, "repaired", "the CLAIMS rows 7.2r-* and efficiency-size");
    ROLLERS_UNIFORM = (studies::EX72_ROLLERS, "uniform", "the CLAIMS rows 7.2r-*");
    /// Hertz, adaptive with the paper's estimator: the run the row `hertz` judges.
    HERTZ_AS_WRITTEN = (studies::HERTZ, "as-written", "the CLAIMS rows hertz, efficiency-size, estimator-repair and the figure hertz_mesh");
    /// Hertz with the smaller load.
    HERTZ_LIGHT = (studies::HERTZ, "as-written-light", "the CLAIMS row efficiency-size");
    HERTZ_REPAIRED = (studies::HERTZ, "repaired", "the CLAIMS rows efficiency-size, estimator-repair and the figure estimator_repair");
    FB_AS_WRITTEN = (studies::FB, "as-written", "the CLAIMS rows fb-* (where deep is not stored) and the figure fb_mesh");
    FB_WFC = (studies::FB, "without-full-contact", "the CLAIMS rows fb-* and the figure fb_mesh");
    FB_UNIFORM = (studies::FB, "uniform", "the CLAIMS rows fb-* (where deep is not stored)");
    REPAIR_EX71 = (studies::ESTIMATOR_REPAIR, "ex71-repaired", "the CLAIMS row estimator-repair (where deep is not stored)");
    REPAIR_EX71_L1 = (studies::ESTIMATOR_REPAIR, "ex71-repaired-l1", "the CLAIMS row estimator-repair and the figure estimator_repair");
    REPAIR_EX71_UNIFORM = (studies::ESTIMATOR_REPAIR, "ex71-uniform", "the CLAIMS row estimator-repair (where deep is not stored)");
    REPAIR_FB = (studies::ESTIMATOR_REPAIR, "fb-repaired", "the CLAIMS row estimator-repair (where deep is not stored)");
    REPAIR_FB_L1 = (studies::ESTIMATOR_REPAIR, "fb-repaired-l1", "the CLAIMS row estimator-repair and the figure estimator_repair");
    REPAIR_FB_UNIFORM = (studies::ESTIMATOR_REPAIR, "fb-uniform", "the CLAIMS row estimator-repair (where deep is not stored)");
    REPAIR_EX72 = (studies::ESTIMATOR_REPAIR, "ex72-repaired", "the CLAIMS row estimator-repair (where ex72_large is not stored)");
    REPAIR_HERTZ = (studies::ESTIMATOR_REPAIR, "hertz-repaired", "the CLAIMS row estimator-repair (where hertz has no repaired run)");
}

/// Each run and its twin with the estimator's maxima on the dense lattice: the dense pass of
/// CLAIMS.md reads the twin in its place (the row `sampling` lists the twins used).
pub const DENSE_TWINS: [(Role, Role); 3] =
    [(EX71_AS_WRITTEN, EX71_AS_WRITTEN_DENSE), (EX72_AS_WRITTEN, EX72_AS_WRITTEN_DENSE), (ABLATION_EX71_WFC, ABLATION_EX71_WFC_DENSE)];

/// The roles the manifests declare: study -> role -> run id.
#[derive(Clone, Debug, Default)]
pub struct Roles {
    declared: BTreeMap<String, BTreeMap<String, String>>,
}

impl Roles {
    /// The id of the run that declares `role` in its study.
    pub fn id(&self, role: Role) -> Option<&str> {
        self.declared.get(role.study)?.get(role.name).map(String::as_str)
    }

    /// The run of `runs` (records of `role.study`) that stands for `role`: the one lookup by
    /// which CLAIMS rows and figures find a run.
    pub fn find<'a>(&self, runs: &'a [RunRecord], role: Role) -> Option<&'a RunRecord> {
        let id = self.id(role)?;
        runs.iter().find(|r| r.run.id == id)
    }

    /// "study/run" of the run declaring `role` (for what a row says it fits before it has data).
    pub fn source(&self, role: Role) -> String {
        format!("{}/{}", role.study, self.id(role).unwrap_or(role.name))
    }
}

/// A role needed and not declared.
#[derive(Debug)]
pub struct Missing {
    pub file: PathBuf,
    pub role: Role,
}

#[derive(Debug, thiserror::Error)]
pub enum RoleError {
    #[error("{}", .0.iter().map(|m| format!(
        "{}: no [[run]] declares role = \"{}\", which {} need(s) from study {}: add it to the run that stands for it",
        m.file.display(), m.role.name, m.role.by, m.role.study
    )).collect::<Vec<_>>().join("\n"))]
    Missing(Vec<Missing>),
}

/// The roles `manifests` declare, checked against [`NEEDED`]: every needed role of a declared
/// study must be declared (a study without a manifest has no data, and its rows say so: `run`
/// checks the manifests it is given only, and a scratch experiments folder may hold one study;
/// that the repository declares every study of [`studies::ALL`] is a test's). Called
/// wherever the manifests are read for CLAIMS.md or the figures (`figures`, `drift`, `report`).
pub fn check(manifests: &[Manifest]) -> Result<Roles, RoleError> {
    let roles = Roles { declared: manifests.iter().map(|m| (m.study.clone(), m.roles.clone())).collect() };
    let missing: Vec<Missing> = NEEDED
        .iter()
        .filter_map(|&role| {
            let m = manifests.iter().find(|m| m.study == role.study)?;
            roles.id(role).is_none().then(|| Missing { file: m.file.clone(), role })
        })
        .collect();
    if missing.is_empty() { Ok(roles) } else { Err(RoleError::Missing(missing)) }
}

/// The roles declared by every manifest in `experiments`, checked ([`check`]).
pub fn read(experiments: &Path) -> anyhow::Result<Roles> {
    Ok(check(&store::study::manifest::declared(experiments, &[])?)?)
}
