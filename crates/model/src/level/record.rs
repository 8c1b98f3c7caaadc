//! What the loop reports about one level ([`LevelRecord`]: the one record type a study stores
//! per level, behind JSON, CSV, drift and plots).

use super::terms::Terms;
use serde::{Deserialize, Serialize};

/// Everything a study stores about one level: the one record type behind JSON, CSV, drift and
/// plots. Flat, so that it is also one CSV row. Fields starting with `t_` (timings, seconds) and
/// `mem_` (memory) are measurements ([`is_measurement`]), never compared by the drift check.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LevelRecord {
    pub level: usize,
    /// 2 x number of P2 nodes, Dirichlet nodes included (the NDF of every figure and table).
    pub ndof: usize,
    pub ndof_free: usize,
    pub n_elements: usize,
    pub h_min: f64,
    pub h_max: f64,
    pub min_angle: f64,
    pub contact_nodes: usize,
    pub active_nodes: usize,
    pub full_contact_nodes: usize,
    pub pdas_iterations: usize,
    /// The smallest and largest arc length of an active contact node along Gamma_C
    /// (`DiscreteSolution::contact_zone`); on a closed contact loop of length L an active arc
    /// through the loop's start is [s_first, s_last + L], so `zone_max` may exceed L.
    pub zone_min: Option<f64>,
    pub zone_max: Option<f64>,
    /// The estimator's terms (eta_1 .. eta_7, l_h, Psi, eta_h, C_0, the estimate), flattened:
    /// the same fields, in the same place, as in every stored record.
    #[serde(flatten)]
    pub terms: Terms,
    /// ||u - u_h||_Linf at the quadrature points (the paper's way), where u is known.
    pub err_quadrature: Option<f64>,
    pub err_dense: Option<f64>,
    pub err_nodal: Option<f64>,
    /// estimate / err_quadrature
    pub efficiency: Option<f64>,
    /// ||u - u_h||_Linf on Gamma_C (`norms::linf_error_contact`: equally spaced points of every
    /// contact edge), where u is known.
    #[serde(default)]
    pub err_contact: Option<f64>,
    /// ||u - u_h||_Linf over the lattice points with x >= 1/2 (Example 7.2: away from the
    /// corners of the clamped side x = 0), where u is known.
    #[serde(default)]
    pub err_right_half: Option<f64>,
    /// The round-off u_h carries (`DiscreteSolution::roundoff`: the largest nodal component of one
    /// step of iterative refinement in working precision). An error within a few times it is
    /// round-off, not discretisation: rate fits use only levels whose error is at least 10x above.
    #[serde(default)]
    pub roundoff_floor: f64,
    /// Length of the longest contact edge whose three nodes are neither all active nor all
    /// inactive: the edge straddling a free-boundary point, where eta_6 and eta_7 live. None
    /// without such an edge.
    #[serde(default)]
    pub h_free_boundary: Option<f64>,
    /// Centroid of the element with the largest marking indicator eta_T (on ties within 1e-8, the
    /// smallest centroid by x, then y).
    #[serde(default)]
    pub max_indicator_x: f64,
    #[serde(default)]
    pub max_indicator_y: f64,
    /// Elements marked for refinement at this level (also at the last level, not refined).
    pub marked: usize,
    pub t_assembly: f64,
    pub t_factorisation: f64,
    pub t_active_set: f64,
    pub t_solve: f64,
    pub t_estimate: f64,
    pub t_refine: f64,
    pub t_level: f64,
    /// Time of the iterative-refinement step that measures `roundoff_floor` (part of `t_solve`).
    #[serde(default)]
    pub t_roundoff: f64,
    /// Peak resident memory of the process during this level, in MiB (Linux: `VmHWM` after
    /// resetting it at the level's start); None where it cannot be measured.
    #[serde(default)]
    pub mem_peak_mib: Option<f64>,
}

impl LevelRecord {
    /// (unknowns, peak resident bytes) of this level where its peak was measured: what the
    /// memory check of a later level, or of the same level solved again, is scaled from
    /// (`solve::check_memory_measured`).
    pub fn measured_peak(&self) -> Option<(f64, f64)> {
        self.mem_peak_mib.map(|mib| (self.ndof as f64, mib * 1024.0 * 1024.0))
    }
}

/// Whether a level record's field is a measurement of the machine (timings `t_*`, memory
/// `mem_*`), which no two runs share and the drift check never compares.
pub fn is_measurement(field: &str) -> bool {
    field.starts_with("t_") || field.starts_with("mem_")
}

/// The float fields of a level record (the ones the drift check compares within tolerances;
/// integers are compared exactly, measurements `t_*`, `mem_*` never), in record order.
pub fn float_fields() -> Vec<String> {
    let v = serde_json::to_value(LevelRecord::default()).expect("records serialise");
    v.as_object().into_iter().flatten().filter(|(k, v)| !is_measurement(k) && (v.is_f64() || v.is_null())).map(|(k, _)| k.clone()).collect()
}
