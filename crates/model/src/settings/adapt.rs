//! The settings of the adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE.

use super::estimator::{ConfigError, EstimatorConfig};
use super::pdas::PdasOptions;
use serde::{Deserialize, Serialize};

/// How the mesh is refined from level to level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Refine {
    /// Maximum strategy: mark T if eta_T >= theta max eta_T (Section 7, ref. \[35\]).
    Adaptive,
    /// Mark every element (one newest-vertex bisection each, so NDF about doubles per level).
    Uniform,
}

/// Settings of the loop; [`AdaptConfig::validate`] checks them.
#[derive(Clone, Debug)]
pub struct AdaptConfig {
    /// Number of levels solved (level 0 is the initial mesh).
    pub levels: usize,
    /// Stop before solving a level with more unknowns than this.
    pub max_ndof: Option<usize>,
    /// Stop after solving the first level with at least this many unknowns (it is not refined).
    pub stop_ndof: Option<usize>,
    pub refine: Refine,
    pub theta: f64,
    pub estimator: EstimatorConfig,
    pub pdas: PdasOptions,
    /// Start each level's active-set method from the previous level's active set.
    pub warm_start: bool,
}

/// Why the loop could not run: settings out of range (checked before anything is solved) or a
/// level whose solve failed.
impl AdaptConfig {
    /// Check every setting: the one validation behind the command line and the manifests.
    /// With theta > 1 the maximum strategy marks nothing and the loop solves one mesh over and
    /// over; with `levels = 0` or `max_ndof = 0` it solves nothing.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |key, expected: &str, got: String| Err(ConfigError { key, expected: expected.into(), got });
        if self.levels == 0 {
            return bad("levels", "a number of levels >= 1", "0".into());
        }
        if self.max_ndof == Some(0) {
            return bad("max_ndof", "a number of unknowns >= 1", "0".into());
        }
        if self.stop_ndof == Some(0) {
            return bad("stop_ndof", "a number of unknowns >= 1", "0".into());
        }
        if let (Some(stop), Some(max)) = (self.stop_ndof, self.max_ndof)
            && stop > max
        {
            // the loop stops before a level above max_ndof, so no level could reach stop_ndof
            return bad(
                "stop_ndof",
                &format!("a number of unknowns <= max_ndof = {max} (no level above max_ndof is solved, so this stop is never reached)"),
                stop.to_string(),
            );
        }
        if !(self.theta > 0.0 && self.theta <= 1.0) {
            return bad("theta", "a number in (0, 1]", ConfigError::number(self.theta));
        }
        self.estimator.validate()?;
        if self.pdas.max_iterations == 0 {
            return bad("pdas.max_iterations", "a number of iterations >= 1", "0".into());
        }
        Ok(())
    }

    /// Check `max_ndof` against the initial mesh `mesh` of `ndof` unknowns: level 0 is always
    /// solved, so a `max_ndof` below it would contradict itself (refused, not a silent level 0).
    pub fn check_initial(&self, ndof: f64, mesh: &str) -> Result<(), ConfigError> {
        match self.max_ndof {
            Some(max) if (max as f64) < ndof => Err(ConfigError {
                key: "max_ndof",
                expected: format!(
                    "a number of unknowns >= {ndof:.0} (the initial mesh {mesh} has {ndof:.0}, and level 0 is always solved)"
                ),
                got: max.to_string(),
            }),
            _ => Ok(()),
        }
    }
}

impl Default for AdaptConfig {
    fn default() -> Self {
        AdaptConfig {
            levels: 20,
            max_ndof: None,
            stop_ndof: None,
            refine: Refine::Adaptive,
            theta: 0.5,
            estimator: EstimatorConfig::default(),
            pdas: PdasOptions::default(),
            warm_start: true,
        }
    }
}
