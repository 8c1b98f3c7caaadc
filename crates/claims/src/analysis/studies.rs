//! The declared studies CLAIMS.md and the figures read, each name written once: a study is
//! read as `shelf.runs(studies::C0_SWEEP)` or through a run role (`role.study`, whose study is
//! one of these), never by a string. A study's name is its manifest's file stem
//! (`experiments/NAME.toml`) and its folder under the results (`results/NAME/`). A test holds
//! [`ALL`] to the repository's manifests and finds no study name written anywhere else in
//! `analysis/` or `plot/`; problems have their own names ([`super::problem_names`]).

/// The name of a declared study.
pub type Study = &'static str;

/// The study constants and [`ALL`], the list of all of them.
macro_rules! studies {
    ($($(#[$doc:meta])* $id:ident = $name:literal;)*) => {
        $($(#[$doc])* pub const $id: Study = $name;)*
        /// Every study a CLAIMS row or a figure reads.
        pub const ALL: &[Study] = &[$($id),*];
    };
}

studies! {
    /// Example 7.1 as the paper runs it.
    EX71 = "ex71";
    /// Example 7.2 as the paper runs it.
    EX72 = "ex72";
    /// The free-boundary problem.
    FB = "fb";
    /// Example 7.1 and fb to about 1e7 unknowns.
    DEEP = "deep";
    /// C_0 against the smallest reliable one.
    C0_SWEEP = "c0_sweep";
    /// Example 7.2 against a reference of at least 4e6 unknowns.
    EX72_LARGE = "ex72_large";
    /// Example 7.2 on rollers.
    EX72_ROLLERS = "ex72_rollers";
    /// Hertz's cylinder on a flat.
    HERTZ = "hertz";
    /// eta_5 with and without full-contact nodes.
    CONTACT_TERM_ABLATION = "contact_term_ablation";
    /// The marking parameter theta.
    THETA_ABLATION = "theta_ablation";
    /// The log factor l_h.
    LOG_ABLATION = "log_ablation";
    /// The repaired estimator.
    ESTIMATOR_REPAIR = "estimator_repair";
}
