//! The estimator's settings: which contact nodes eta_5 is taken over, the log factor l_h, the
//! frame of the contact stresses, the constant C_0 (Section 7, eq. 7.1).

use super::sampling::Sampling;

/// Which contact nodes eta_5 is taken over. Manifests spell the values in snake_case
/// (`as_written`), the command line in kebab-case (`--contact-term as-written`). The variants'
/// docs are for readers of the code (`help = None`): the flag's help describes the values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ContactTerm {
    /// All contact nodes, as the paper writes eta_5.
    #[value(help = None::<&str>)]
    AsWritten,
    /// Without full-contact nodes N_h^FC (u_h.n = chi_h on all of Gamma_{p,C}), as in
    /// Krause–Veeser–Walloth. At a node in full contact the exact normal stress is a compressive
    /// contact pressure, not an error: taken over all contact nodes, eta_5 measures that pressure
    /// and decays only like h (measured: the `contact_term_ablation` study).
    #[value(help = None::<&str>)]
    WithoutFullContact,
    /// The repaired contact terms (beyond the paper): at a full-contact node eta_5 takes only the
    /// tensile part (n . sigma(u_h) n)^+ of the normal stress, at other contact nodes it is as
    /// written; eta_7 is taken over a narrower Lambda_h^C, the full-contact edges (all three
    /// nodes active) and the edges through an active node with positive contact force that lies
    /// on no full-contact edge (an isolated active node). See [`repair`] for why, and for the
    /// step of the proof that is open.
    #[value(help = None::<&str>)]
    TensileOnFullContact,
}

/// The log factor l_h multiplying the residual terms (`--log-factor`, `estimator.log_factor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum LogFactor {
    /// 1 + |log h_min|^2 (eq. 6.3)
    #[value(help = None::<&str>)]
    Squared,
    /// 1 + |log h_min|
    #[value(help = None::<&str>)]
    Linear,
    /// 1
    #[value(help = None::<&str>)]
    One,
}

impl LogFactor {
    pub fn value(self, h_min: f64) -> f64 {
        let l = h_min.ln().abs();
        match self {
            LogFactor::Squared => 1.0 + l * l,
            LogFactor::Linear => 1.0 + l,
            LogFactor::One => 1.0,
        }
    }
}

/// How the paper's sigma-hat_1, sigma-hat_2 (the components of sigma(u_h) n in eta_5 and eta_4)
/// are read. The paper defines sigma-hat_1 as the first component of sigma n "in a frame where
/// e_1 is the normal"; read literally as the first Cartesian component it is -sigma_12 on the
/// bottom edge of Example 7.1 (n = (0, -1)) and the normal stress sigma_11 on Example 7.2's
/// right edge (n = (1, 0)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StressFrame {
    /// sigma-hat_1 = n . sigma n (normal stress, eta_5), sigma-hat_2 = t . sigma n (eta_4).
    #[default]
    Normal,
    /// sigma-hat_1 = (sigma n)_1 (eta_5), sigma-hat_2 = (sigma n)_2 (eta_4): the Cartesian components.
    Cartesian,
}

/// A declared estimator variant.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EstimatorConfig {
    pub contact_term: ContactTerm,
    pub log_factor: LogFactor,
    /// The constant replacing the hidden one of Theorem 6.1 (Section 7: [`C0_PAPER`]).
    pub c0: f64,
    pub sampling: Sampling,
    /// Reading of sigma-hat_1, sigma-hat_2 in eta_4, eta_5 (absent in older records: normal).
    #[serde(default)]
    pub stress_frame: StressFrame,
}

/// The constant C_0 of Section 7 as a literal, for text that quotes it (`concat!`): its one
/// definition, which [`C0_PAPER`] reads.
#[macro_export]
macro_rules! c0_paper {
    () => {
        0.45
    };
}
pub use crate::c0_paper;

/// The constant C_0 of Section 7, the estimator's default.
pub const C0_PAPER: f64 = c0_paper!();

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            contact_term: ContactTerm::AsWritten,
            log_factor: LogFactor::Squared,
            c0: C0_PAPER,
            sampling: Sampling::Quadrature,
            stress_frame: StressFrame::Normal,
        }
    }
}

/// A setting outside its range: `key` is the field (as manifests spell it: `estimator.c0`,
/// `theta`), `expected` the admissible values, `got` the value given. The one error of the
/// settings' validation, whether they come from a manifest or the command line (which names
/// the flag of `key` instead).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key}: expected {expected}, got {got}")]
pub struct ConfigError {
    pub key: &'static str,
    pub expected: String,
    pub got: String,
}

impl ConfigError {
    /// A number as an error shows it: as Rust prints it while that is short (0.5, -1, NaN),
    /// else in exponent form (1e-320 and 1e308, not hundreds of digits).
    pub fn number(x: f64) -> String {
        let plain = x.to_string();
        if plain.len() <= 24 { plain } else { format!("{x:e}") }
    }
}

impl EstimatorConfig {
    /// Check the settings: C_0 must be a positive normal number (not zero, NaN, infinite or
    /// subnormal, where C_0 eta_h loses its digits). Whether C_0 eta_h is finite depends on
    /// eta_h too: [`Terms::check_finite`] checks that once the estimate is computed.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.c0 > 0.0 && self.c0.is_normal()) {
            let expected = if self.c0 > 0.0 && self.c0.is_finite() {
                format!("a positive number of at least {:e} (a subnormal C_0 leaves C_0 eta_h few digits)", f64::MIN_POSITIVE)
            } else {
                "a positive number".into()
            };
            return Err(ConfigError { key: "estimator.c0", expected, got: ConfigError::number(self.c0) });
        }
        Ok(())
    }
}
