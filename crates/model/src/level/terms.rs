//! The estimator's terms eta_1 .. eta_7, l_h and C_0 eta_h as a level reports them, and the
//! error of an estimate that is not a finite number.

/// An estimate that is not a finite number: C_0 eta_h overflowed (a C_0 too large for this
/// eta_h) or eta_h itself is not finite (`overflowed` names the term: the problem's data are
/// beyond double precision, which no C_0 mends). Nothing can be compared with it or stored.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the estimate C_0 eta_h = {c0:e} x {eta_h:e} is {estimate}, not a finite number ({})", blame(overflowed))]
pub struct NotFinite {
    pub c0: f64,
    pub eta_h: f64,
    pub estimate: f64,
    /// The first of eta_1 .. eta_7, l_h and their sum eta_h that is not finite, in words, with
    /// its value; None when eta_h is finite (then C_0 is too large for it).
    pub overflowed: Option<(&'static str, f64)>,
}

/// Whom a [`NotFinite`] estimate is due to: C_0, or the term that overflowed.
fn blame(overflowed: &Option<(&'static str, f64)>) -> String {
    match overflowed {
        None => "estimator.c0, --c0: a C_0 for which it is finite".into(),
        Some((term, value)) => format!(
            "{term} is {value}, so no C_0 makes it finite: the problem's data are too large for double precision; \
             rescale its units (body force, loads, Dirichlet data, obstacle)"
        ),
    }
}

/// The estimator's terms (the `estimator` object of `signorini solve --json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Terms {
    pub eta1: f64,
    pub eta2: f64,
    pub eta3: f64,
    pub eta4: f64,
    pub eta5: f64,
    pub eta6: f64,
    pub eta7: f64,
    pub l_h: f64,
    /// Psi = eta_1 + ... + eta_5
    pub psi: f64,
    pub eta_h: f64,
    pub c0: f64,
    /// C_0 eta_h, the quantity compared with the error
    pub estimate: f64,
}

impl Terms {
    pub fn eta(&self) -> [f64; 7] {
        [self.eta1, self.eta2, self.eta3, self.eta4, self.eta5, self.eta6, self.eta7]
    }

    /// The estimate is a finite number: what every path that reports or stores one checks
    /// (the adaptive loop at every level, `signorini solve`).
    pub fn check_finite(&self) -> Result<(), NotFinite> {
        if self.estimate.is_finite() {
            return Ok(());
        }
        let named = [
            ("eta_1, the element residual h^2 |f + div sigma(u_h)| (the body force)", self.eta1),
            ("eta_2, the stress jumps across edges", self.eta2),
            ("eta_3, the Neumann residual (the surface load)", self.eta3),
            ("eta_4, the tangential contact stress", self.eta4),
            ("eta_5, the normal contact stress", self.eta5),
            ("eta_6, the penetration (u_h.n - chi)^+", self.eta6),
            ("eta_7, the gap (chi - u_h.n)^+ where the contact force is positive", self.eta7),
            ("the log factor l_h", self.l_h),
            ("eta_h = l_h (eta_1 + ... + eta_5) + eta_6 + eta_7", self.eta_h),
        ];
        let overflowed = named.into_iter().find(|(_, v)| !v.is_finite());
        Err(NotFinite { c0: self.c0, eta_h: self.eta_h, estimate: self.estimate, overflowed })
    }
}
