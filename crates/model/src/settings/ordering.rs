//! Which fill-reducing ordering the sparse factorisations of a process are forced to, if any
//! (the solver chooses by flop count otherwise).

/// A fill-reducing ordering of the sparse Cholesky factorisation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    NestedDissection,
    MinimumDegree,
}

/// The environment variable that forces one ordering for every factorisation in the process:
/// `nested-dissection` or `minimum-degree` (unset or `auto`: the one with fewer flops). A
/// diagnostic, not a setting: the drift check's tolerances are measured by rerunning every study
/// with each ordering forced, since the ordering changes the summation order of the
/// factorisation and so the results at round-off (`results/roundoff/`).
pub const FORCE_ENV: &str = "SIGNORINI_ORDERING";

/// The ordering forced by [`FORCE_ENV`], read once per process; an unknown value is an error
/// (the command line checks it at start-up, so a measurement never silently runs with the
/// automatic choice).
pub fn forced() -> Result<Option<Method>, String> {
    static FORCED: std::sync::OnceLock<Result<Option<Method>, String>> = std::sync::OnceLock::new();
    FORCED
        .get_or_init(|| match std::env::var(FORCE_ENV).as_deref() {
            Err(_) | Ok("") | Ok("auto") => Ok(None),
            Ok("nested-dissection") => Ok(Some(Method::NestedDissection)),
            Ok("minimum-degree") => Ok(Some(Method::MinimumDegree)),
            Ok(other) => Err(format!("{FORCE_ENV}={other:?}: expected auto, nested-dissection or minimum-degree")),
        })
        .clone()
}
