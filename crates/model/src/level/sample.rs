//! A contact node of a discrete solution as a level record stores it.

/// A contact node of a discrete solution: its position, the nodal contact force lambda_p (paper
/// eq. 3.6, in the constraint direction), the pressure lambda_p / int_{Gamma_C} psi_p ds (psi_p the
/// P2 basis function of the node; see `solve::contact_samples`) and whether it is active.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactSample {
    pub x: [f64; 2],
    pub lambda: f64,
    pub pressure: f64,
    pub active: bool,
}
