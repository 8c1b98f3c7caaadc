//! `results/CLAIMS.md`: each quantitative claim of the paper's Section 7 (and the checks of the
//! free-boundary example `fb`), the number we measured with its uncertainty and range, and the
//! verdict, generated from the stored records only (never written by hand).
//!
//! Rates, intervals and the verdict rules are those of [`crate::analysis::verdict`]: least-squares slopes
//! in log NDF with 95% t intervals, every other level, over the last two decades of NDF, with the
//! slopes of the windows ending two and four levels earlier beside them. Example 7.1 and `fb`
//! are judged on the deep study's runs (to at least 1e7 NDF) where it is stored, Example 7.2's
//! estimator on `ex72_large` (to 1.1e6); each row names the runs it fits (`study/run`). Every verdict is
//! computed twice, with errors sampled at the quadrature points (the paper's way) and on a dense
//! lattice (`err_dense`); the `sampling` row lists the verdicts that differ.

pub mod criterion;
mod ex71;
mod ex72;
mod fb;
mod headline;
pub mod repair;
mod rollers;
mod rows;
pub mod terms;

use crate::analysis::roles::{self, DENSE_TWINS, Role, Roles};
use crate::analysis::verdict::{self, RateReport, RateVerdict};
use crate::analysis::{problem_names, studies};
// the paper's C_0 (Section 7, the estimator's default): a reliability row holds when the
// smallest reliable C_0 of its runs is at most this
pub use criterion::{Criterion, Evidence, Kind};
use model::settings::estimator::{C0_PAPER, ContactTerm, LogFactor, c0_paper};
use std::fmt::Write as _;
use std::path::Path;
use store::records::{MeshSnapshot, RunRecord};
use store::study::store::Shelf;

/// The paper's optimal rate in NDF: NDF^(-3/2).
pub const OPTIMAL: f64 = 1.5;
/// The 95% half-width a rate verdict aims at (in NDF; doubled for a fit in h_min): a wider one
/// is marked in its row.
pub const TARGET_HALF_WIDTH: f64 = 0.05;
/// How far along Gamma_C either side of a claimed refinement location the edge lengths are
/// compared ([`verdict::refinement::local_minimum`]).
pub const REFINE_REACH: f64 = 0.15;
/// eta_6 and eta_7 of Example 7.1 vanish: none above this at any level (they are 0 up to
/// round-off).
pub const VANISHING: f64 = 1e-12;
pub use terms::COINCIDE_REL;
/// A reference solution decides a row only while its own error (estimated: [`reference_error`])
/// is at most this fraction of the smallest error the row judges.
pub const REFERENCE_SHARE: f64 = 0.1;
/// The rate in NDF at which uniform refinement shrinks an edge (h ~ NDF^-1/2): refinement at a
/// point is faster than this.
pub const UNIFORM_H_RATE: f64 = 0.5;
/// Poisson ratio of Example 7.2 (E = 500, nu = 0.3).
pub const EX72_NU: f64 = 0.3;
/// The free boundary of `fb`: contact exactly on [a, 1] x {0}, a = sqrt(2) - 1.
pub fn fb_free_boundary() -> f64 {
    std::f64::consts::SQRT_2 - 1.0
}

/// What stops CLAIMS.md from being computed.
#[derive(Debug, thiserror::Error)]
pub enum ClaimsError {
    /// A study's records (or CLAIMS.md itself) cannot be read or written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A checked study folder cannot hand out what a row asks for.
    #[error(transparent)]
    Shelf(#[from] store::study::store::ShelfError),
    /// The problem of a stored run cannot be loaded (the row `hertz` needs its geometry): the
    /// error says which run and why.
    #[error("{0:#}")]
    Problem(anyhow::Error),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Reproduced,
    /// Slower than claimed, beyond the interval.
    NotReproduced,
    /// Faster than claimed, beyond the interval.
    Different,
    Inconclusive,
    /// A check beyond the paper that passes / fails.
    Holds,
    Fails,
    NoData,
    /// Measured beyond the paper (an ablation, or a quantity the paper does not report): no claim to judge.
    NoClaim,
}

impl Verdict {
    pub fn text(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::NotReproduced => "**not reproduced**",
            Verdict::Different => "**different** (faster than claimed)",
            Verdict::Inconclusive => "inconclusive",
            Verdict::Holds => "holds (beyond the paper)",
            Verdict::Fails => "**fails** (beyond the paper)",
            Verdict::NoData => "no data (study not run)",
            Verdict::NoClaim => "no claim in the paper (measured)",
        }
    }
}

impl From<RateVerdict> for Verdict {
    fn from(v: RateVerdict) -> Self {
        match v {
            RateVerdict::Reproduced => Verdict::Reproduced,
            RateVerdict::NotReproduced => Verdict::NotReproduced,
            RateVerdict::Different => Verdict::Different,
            RateVerdict::Inconclusive => Verdict::Inconclusive,
        }
    }
}

/// A claim's line in the summary that opens CLAIMS.md: the claim in a few words, what the paper
/// says, and the headline measurement (one number with its interval, window and run).
#[derive(Clone, Debug, Default)]
pub struct Summary {
    pub topic: String,
    pub paper: &'static str,
    pub headline: String,
}

/// What kind of claim a row judges: rows of one kind are judged by one criterion, whatever the
/// problem or the contact term (a test holds them to it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum RowKind {
    /// A quantity decays at a claimed rate ([`Criterion::Rate`]).
    Rate,
    /// The efficiency index estimate / error is bounded ([`Criterion::Bounded`]).
    Efficiency,
    /// The efficiency index up to the log factor, estimate / error / l_h, is bounded.
    EfficiencyUpToLh,
    /// C_0 = 0.45 is reliable over the levels of the error-rate fit ([`Criterion::AtMost`]).
    Reliability,
    /// The mesh is refined at the free boundary: the contact edge straddling a free-boundary
    /// point shrinks faster than uniform refinement's NDF^(-1/2) ([`Criterion::FasterThan`]).
    Refinement,
    /// A quantity vanishes (at most round-off at every level).
    Vanishing,
    /// A finding of its own (one row, its own rule stated in the row).
    Finding,
    /// A measurement with no claim to judge ([`Criterion::Reported`]).
    Measured,
}

pub struct Claim {
    pub id: String,
    pub summary: Summary,
    pub claim: String,
    pub measured: String,
    /// Judged by `criterion` on the row's evidence ([`Criterion::verdict`]).
    pub verdict: Verdict,
    /// The rule the verdict applies; it also states what would fail the row ([`Criterion::fails_if`]).
    pub criterion: Criterion,
    /// Whose claim `criterion` judges (the verdict's words: reproduced or holds).
    pub kind: Kind,
    /// What kind of claim the row judges: one criterion per kind.
    pub row: RowKind,
    /// The contact terms of eta_5 whose runs the row judges (two where their runs coincide;
    /// none for a row about no one term): the headline counts the paper's claims per term.
    pub terms: Vec<ContactTerm>,
    /// Why the verdict is fragile: it changes with the fit window ([`verdict::window_fragility`])
    /// or with the dense sampling of the error (set by [`claims`]).
    pub fragile: Option<String>,
}

impl Claim {
    /// Whose claim the row judges.
    pub fn kind(&self) -> Kind {
        self.kind
    }
}

/// Which error the verdicts use: sampled at the quadrature points or on the dense lattice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorSampling {
    Quadrature,
    Dense,
}

/// Which alternate levels a fit takes. Newest-vertex bisection refines in two-level staircases,
/// so every fit takes every other level ([`verdict::window`]); `Last` takes the levels of the
/// run's last level's parity, `Other` those of the level before (its last level dropped). Every
/// verdict is computed both ways; one that differs is fragile, and the headline counts it as
/// undecided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parity {
    Last,
    Other,
}

/// A per-level quantity of a run.
#[derive(Clone, Copy, Debug)]
enum Q<'a> {
    Field(&'a str),
    /// ||u - u_h||_Linf in the chosen sampling
    Error,
    /// estimate / error
    Efficiency,
    /// estimate / error / l_h
    EfficiencyOverLh,
    /// The efficiency of the same estimator with l_h = 1 (eq. 6.3's factor dropped) on the same
    /// meshes: C_0 (Psi + eta_6 + eta_7) / error.
    EfficiencyL1,
}

struct Ctx<'r> {
    sampling: ErrorSampling,
    parity: Parity,
    /// The checked study folders the rows are computed from.
    shelf: &'r Shelf,
    /// What the stored runs stand for: every row finds its runs by role ([`Roles::find`]).
    roles: &'r Roles,
}

impl Ctx<'_> {
    /// The run of `runs` that stands for `role` ([`Roles::find`]).
    fn find<'a>(&self, runs: &'a [RunRecord], role: Role) -> Option<&'a RunRecord> {
        self.roles.find(runs, role)
    }

    /// The run of `role`; in the dense pass its twin (estimator maxima on the dense lattice too,
    /// [`DENSE_TWINS`]) where the study has one.
    fn pick<'a>(&self, runs: &'a [RunRecord], role: Role) -> Option<&'a RunRecord> {
        let twin = DENSE_TWINS.iter().find(|(plain, _)| *plain == role).map(|(_, twin)| *twin);
        match (self.sampling, twin) {
            (ErrorSampling::Dense, Some(twin)) => self.find(runs, twin).or_else(|| self.find(runs, role)),
            _ => self.find(runs, role),
        }
    }

    fn err_field(&self) -> &'static str {
        match self.sampling {
            ErrorSampling::Quadrature => "err_quadrature",
            ErrorSampling::Dense => "err_dense",
        }
    }

    fn values(&self, r: &RunRecord, q: Q) -> Vec<Option<f64>> {
        let err = verdict::field(r, self.err_field());
        match q {
            Q::Field(f) => verdict::field(r, f),
            Q::Error => err,
            Q::Efficiency => r.levels.iter().zip(&err).map(|(l, e)| e.filter(|e| *e > 0.0).map(|e| l.terms.estimate / e)).collect(),
            Q::EfficiencyOverLh => {
                r.levels.iter().zip(&err).map(|(l, e)| e.filter(|e| *e > 0.0).map(|e| l.terms.estimate / e / l.terms.l_h)).collect()
            }
            Q::EfficiencyL1 => r
                .levels
                .iter()
                .zip(&err)
                .map(|(l, e)| e.filter(|e| *e > 0.0).map(|e| l.terms.c0 * (l.terms.psi + l.terms.eta6 + l.terms.eta7) / e))
                .collect(),
        }
    }

    /// The rate of `q` against the variable the theory speaks of for `r`'s refinement
    /// ([`verdict::abscissa_of`]: h_min for uniform, NDF for adaptive).
    /// Quantities of the error end at the round-off floor ([`verdict::above_floor`]).
    fn rate(&self, r: Option<&RunRecord>, q: Q) -> Option<RateReport> {
        let r = self.fitted(r?, q);
        RateReport::of_values(&r, &self.values(&r, q))
    }

    fn growth(&self, r: Option<&RunRecord>, q: Q) -> Option<verdict::RateFit> {
        let r = self.fitted(r?, q);
        let ndof: Vec<usize> = r.levels.iter().map(|l| l.ndof).collect();
        verdict::growth(&ndof, &self.values(&r, q))
    }

    /// The levels of `r` a fit of `q` uses: for an error (any `err_*` field) and the efficiency
    /// (estimate / error), those before the error reaches [`verdict::FLOOR_MARGIN`] x the
    /// round-off floor; for another field, those up to its last value above round-off
    /// ([`verdict::above_round_off`]).
    /// With [`Parity::Other`], the last of those levels is dropped too.
    fn fitted<'a>(&self, r: &'a RunRecord, q: Q) -> std::borrow::Cow<'a, RunRecord> {
        let cut = match q {
            Q::Field(f) if f.starts_with("err_") => verdict::above_floor(r, &self.values(r, q)),
            Q::Field(_) => verdict::above_round_off(r, &self.values(r, q)),
            Q::Error | Q::Efficiency | Q::EfficiencyOverLh | Q::EfficiencyL1 => verdict::above_floor(r, &self.values(r, Q::Error)),
        };
        match self.parity {
            Parity::Last => cut,
            Parity::Other => {
                let mut other = cut.into_owned();
                other.levels.pop();
                std::borrow::Cow::Owned(other)
            }
        }
    }

    /// Where `r`'s error meets the round-off floor ([`verdict::floor_text`]).
    fn floor_text(&self, r: &RunRecord) -> String {
        verdict::floor_text(r, &self.values(r, Q::Error))
    }
}

/// "study/run" of a run, for the rows to say what they fit.
fn source(r: Option<&RunRecord>) -> String {
    r.map(|r| format!("{}/{}", r.study, r.run.id)).unwrap_or("no run".into())
}

/// "name 1.52 ± 0.04 (levels …; windows …) → reproduced" against `claim`, or without a verdict;
/// an interval wider than [`TARGET_HALF_WIDTH`] is marked.
fn rate_text(name: &str, rep: Option<&RateReport>, claim: Option<f64>) -> String {
    match (rep, claim) {
        (None, _) => format!("{name} n/a"),
        (Some(r), Some(c)) => {
            let (_, band) = r.main.claim_in_abscissa(c);
            let target = TARGET_HALF_WIDTH * band / verdict::RATE_BAND;
            format!(
                "{name} {} → {}{}{}",
                r.text(),
                verdict::judge_rate(&r.main, c).text(),
                if r.main.rate.half_width <= target { String::new() } else { format!(" (wider than ± {target:.2})") },
                verdict::window_fragility(r, c).map(|f| format!(" (fragile: {f})")).unwrap_or_default()
            )
        }
        (Some(r), None) => format!("{name} {}", r.text()),
    }
}

/// "NDF 1.2e5–1.2e7" of a fit, "h_min, NDF …" for a fit against h_min, with "only 1.0
/// decade(s): no verdict" for a window too short.
fn short_range(fit: &verdict::RateFit) -> String {
    format!(
        "{}NDF {:.1e}–{:.1e}{}",
        if fit.abscissa == verdict::Abscissa::InverseHMin { "in h_min, " } else { "" },
        fit.first_ndof as f64,
        fit.last_ndof as f64,
        if fit.spans_enough() { String::new() } else { format!(", only {:.1} decade(s): no verdict", fit.decades()) }
    )
}

/// A summary's headline for a rate: "1.04 ± 0.03 (NDF 1.2e5–1.2e7, deep/ex71_as_written)".
fn rate_headline(name: &str, rep: Option<&RateReport>, r: Option<&RunRecord>) -> String {
    match rep {
        Some(rep) => format!("{name}{} ({}, {})", rep.main.text(), short_range(&rep.main), source(r)),
        None => format!("{name}n/a"),
    }
}

/// A summary's headline for a trend: "slope 0.21 ± 0.04 (NDF 1.2e5–1.2e7, deep/ex71_as_written)".
fn growth_headline(name: &str, g: Option<&verdict::RateFit>, r: Option<&RunRecord>) -> String {
    match g {
        Some(g) => format!("{name}slope {} ({}, {})", g.text(), short_range(g), source(r)),
        None => format!("{name}n/a"),
    }
}

/// The slowest of `names`' rates for `r`: "eta4 0.50 ± 0.01 (…)" (None without a fit).
fn slowest_headline(ctx: &Ctx, r: Option<&RunRecord>, names: &[&str]) -> String {
    names
        .iter()
        .filter_map(|n| Some((*n, ctx.rate(r, Q::Field(n))?)))
        .min_by(|a, b| a.1.main.rate.slope.total_cmp(&b.1.main.rate.slope))
        .map(|(n, rep)| rate_headline(&format!("slowest {n} "), Some(&rep), r))
        .unwrap_or("n/a".into())
}

/// The window fragility of a rate verdict on `rep` against `claim`.
fn fragility(rep: Option<&RateReport>, claim: f64) -> Option<String> {
    rep.and_then(|r| verdict::window_fragility(r, claim))
}

/// eta_h's rate beside Psi's and the log factor's share: eta_h = l_h Psi + eta_6 + eta_7, so
/// (where eta_6, eta_7 are small) rate(eta_h) = rate(Psi) + rate(l_h), rate(l_h) < 0.
fn estimator_text(ctx: &Ctx, r: Option<&RunRecord>) -> String {
    let (eta, psi, lh) = (ctx.rate(r, Q::Field("eta_h")), ctx.rate(r, Q::Field("psi")), ctx.rate(r, Q::Field("l_h")));
    format!(
        "{}; {}; l_h's share of the slope {}",
        rate_text("eta_h", eta.as_ref(), Some(OPTIMAL)),
        rate_text("Psi", psi.as_ref(), Some(OPTIMAL)),
        lh.map(|l| format!("{:.2}", l.main.rate.slope)).unwrap_or("n/a".into())
    )
}

/// "growth 0.12 ± 0.03 per decade of NDF (levels …): bounded / growing".
fn growth_text(name: &str, g: Option<&verdict::RateFit>) -> String {
    match g {
        None => format!("{name}: n/a"),
        Some(g) => format!("{name}: slope of log against log NDF {} ({}) → {}", g.text(), g.range(), verdict::judge_trend(g).text()),
    }
}

/// How reliable C_0 eta_h is over the levels of a run's error-rate fit window (every level from
/// its first to its last, not only the fitted alternate ones): the reliability the paper's
/// asymptotic bound (6.1) speaks of, not that of the coarsest meshes.
#[derive(Clone, Copy, Debug)]
pub struct Reliability {
    /// The smallest C_0 with C_0 eta_h >= error at every level of the window: max error / eta_h.
    pub c0: f64,
    /// The smallest and largest estimate / error over the window.
    pub lo: f64,
    pub hi: f64,
    pub first_level: usize,
    pub last_level: usize,
}

impl Reliability {
    /// "C_0 >= 4.4e-4 over levels 20–34 (estimate/error 1.0e3 to 2.1e3): 0.45 is 3.0 decades above it"
    fn text(&self, name: &str) -> String {
        format!(
            "{name}: smallest reliable C_0 {:.1e} over levels {}–{} (estimate/error {:.1e} to {:.1e}): {C0_PAPER} is {:.1} decades above it",
            self.c0,
            self.first_level,
            self.last_level,
            self.lo,
            self.hi,
            (C0_PAPER / self.c0).log10()
        )
    }
}

impl Ctx<'_> {
    /// [`Reliability`] of `r` over its error-rate fit window; None without a fit.
    fn reliability(&self, r: &RunRecord) -> Option<Reliability> {
        let rep = self.rate(Some(r), Q::Error)?;
        let err = self.values(r, Q::Error);
        let (first, last) = (rep.main.first_level, rep.main.last_level);
        let pairs: Vec<(f64, f64)> = (first..=last)
            .map(|l| err[l].filter(|e| *e > 0.0).map(|e| (r.levels[l].terms.estimate / e, e / r.levels[l].terms.eta_h)))
            .collect::<Option<_>>()?;
        Some(Reliability {
            c0: pairs.iter().map(|p| p.1).fold(0.0, f64::max),
            lo: pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min),
            hi: pairs.iter().map(|p| p.0).fold(0.0, f64::max),
            first_level: first,
            last_level: last,
        })
    }
}

/// A reference solution's own error, estimated: the fitted error rate of the run of its study
/// that is marked as the reference is (same theta and contact term), extrapolated from that run's
/// last error to the reference's NDF. Where the study holds no such run, the adaptive run that
/// reaches the most unknowns stands in, and the text says so.
#[derive(Clone, Debug)]
pub struct ReferenceError {
    pub ndof: usize,
    pub error: f64,
    /// How it was estimated: "reference NDF 1513938: its own error 1.8e-9, extrapolated from ...".
    pub text: String,
}

impl Ctx<'_> {
    /// The own error of the reference `r`'s errors are measured against; None for a run whose
    /// errors are not against a reference, or where no run of its study has an error-rate fit.
    fn reference_error(&self, r: &RunRecord) -> Option<ReferenceError> {
        let (spec, ndof) = (r.run.reference.as_ref()?, r.reference_ndof?);
        let runs = self.shelf.runs(&r.study).ok()?;
        let adaptive =
            |x: &&RunRecord| x.run.refine == model::settings::adapt::Refine::Adaptive && x.run.estimator.log_factor == LogFactor::Squared;
        let along = runs
            .iter()
            .filter(adaptive)
            .find(|x| x.run.estimator.contact_term == spec.contact_term && x.run.theta == spec.theta)
            .map(|x| (x, "the run marked as the reference is"));
        let (along, why) = along.or_else(|| {
            runs.iter()
                .filter(adaptive)
                .max_by_key(|x| x.levels.last().map_or(0, |l| l.ndof))
                .map(|x| (x, "no run of the study marks as the reference does, the adaptive run reaching the most unknowns stands in"))
        })?;
        let rate = self.rate(Some(along), Q::Error)?;
        let fitted = self.fitted(along, Q::Error);
        let last = fitted.levels.last()?;
        let e_last = self.values(&fitted, Q::Error).last().copied().flatten()?;
        let error = e_last * (last.ndof as f64 / ndof as f64).powf(rate.main.rate.slope);
        Some(ReferenceError {
            ndof,
            error,
            text: format!(
                "reference NDF {ndof}: its own error about {error:.1e}, the error {e_last:.1e} of {} at NDF {} extrapolated at its fitted rate {:.2} ({why})",
                source(Some(along)),
                last.ndof,
                rate.main.rate.slope
            ),
        })
    }

    /// The reference check of a row judging `r`'s errors over levels `first..=last`: the
    /// reference's own error over the smallest error there, and the text; None without a
    /// reference.
    fn reference_check(&self, r: &RunRecord, first: usize, last: usize) -> Option<(f64, String)> {
        let re = self.reference_error(r)?;
        let err = self.values(r, Q::Error);
        let smallest = (first..=last.min(err.len().saturating_sub(1))).filter_map(|l| err[l]).fold(f64::INFINITY, f64::min);
        let ratio = re.error / smallest;
        Some((
            ratio,
            format!(
                "{}; {:.0}% of the smallest error judged ({smallest:.1e}){}",
                re.text,
                100.0 * ratio,
                if ratio > REFERENCE_SHARE {
                    format!(": above {:.0}%, the row is not decided", 100.0 * REFERENCE_SHARE)
                } else {
                    String::new()
                }
            ),
        ))
    }
}

/// The criterion of every reliability row: the smallest reliable C_0 of `runs` over their fit
/// windows at most the paper's.
fn reliability_criterion(runs: &str) -> Criterion {
    Criterion::AtMost {
        what: format!("the smallest reliable C_0 (the largest error / eta_h over the levels of each error-rate fit window) of {runs}"),
        limit: C0_PAPER,
        interval: false,
    }
}

/// The local exponent -log2(e_l / e_(l-2)) of the error per halving of h (two bisection levels)
/// over the last `n` halvings of a uniform run, oldest first: "0.718, 0.719, 0.717, 0.714".
fn halving_exponents(r: &RunRecord, err_field: &str, n: usize) -> String {
    let err = verdict::field(r, err_field);
    let last = err.len().saturating_sub(1);
    let mut out: Vec<String> = (0..n)
        .filter_map(|k| {
            let l = last.checked_sub(2 * k)?;
            Some(format!("{:.3}", -(err[l]? / err[l.checked_sub(2)?]?).log2()))
        })
        .collect();
    out.reverse();
    out.join(", ")
}

/// How near the largest element indicator lies to a point: within this distance.
pub const PEAK_NEAR: f64 = 0.05;

/// "the largest element indicator lies within 0.05 of the wedge tip (1, 0.5) at 8 of 12 levels
/// (the last at (0.996, 0.499))": where the marking sees the error, from the records alone.
fn peak_text(r: &RunRecord, name: &str, at: [f64; 2]) -> String {
    let near = r.levels.iter().filter(|l| model::mesh::dist(at, [l.max_indicator_x, l.max_indicator_y]) <= PEAK_NEAR).count();
    let last = r.levels.last().map_or(String::new(), |l| format!(" (the last at ({:.3}, {:.3}))", l.max_indicator_x, l.max_indicator_y));
    format!(
        "the largest element indicator lies within {PEAK_NEAR} of {name} ({}, {}) at {near} of {} levels{last}",
        at[0],
        at[1],
        r.levels.len()
    )
}

/// The snapshot of the largest level `run` of `study` saves ([`Shelf::latest_mesh`]).
fn latest_mesh(shelf: &Shelf, study: &str, run: &str) -> std::io::Result<Option<MeshSnapshot>> {
    Ok(shelf.latest_mesh(study, run)?)
}

/// The C_0 rows, one per contact term: the smallest reliable C_0 over the fit windows of every
/// run on the shelf with an error whose eta_h carries the paper's log factor l_h (6.3), which
/// (6.1) bounds; a run of the log-factor ablation does not estimate with that eta_h.
fn c0_claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let names: Vec<String> = ctx.shelf.studies().map(str::to_owned).collect();
    let mut runs = Vec::new();
    for study in &names {
        runs.extend(ctx.shelf.runs(study)?);
    }
    for term in terms::ALL {
        let (mut rows, mut other_l_h, mut short) = (Vec::new(), Vec::new(), Vec::new());
        for r in runs.iter().filter(|r| r.run.estimator.contact_term == term) {
            let name = source(Some(r));
            if ctx.values(r, Q::Error).iter().all(Option::is_none) {
                continue;
            }
            match ctx.reliability(r) {
                Some(_) if r.run.estimator.log_factor != LogFactor::Squared => {
                    other_l_h.push(format!("{name} (log_factor {})", format!("{:?}", r.run.estimator.log_factor).to_lowercase()))
                }
                Some(rel) => rows.push((rel.text(&name), rel.c0)),
                None => short.push(name),
            }
        }
        let worst = rows.iter().map(|r| r.1).fold(0.0, f64::max);
        let test = reliability_criterion(&format!("the {} runs with an error", rows.len()));
        let suffix = if term == ContactTerm::AsWritten { String::new() } else { format!(" ({})", terms::name(term)) };
        out.push(Claim {
            fragile: None,
            id: format!("c0{suffix}"),
            summary: Summary {
                topic: format!("Reliability with C_0 = {C0_PAPER}{suffix}"),
                paper: "C_0 eta_h >= error (6.1)",
                headline: if rows.is_empty() {
                    "n/a".into()
                } else {
                    format!(
                        "smallest reliable C_0 {worst:.1e} over the fit windows of {} runs: {C0_PAPER} is {:.1} decades above it",
                        rows.len(),
                        (C0_PAPER / worst).log10()
                    )
                },
            },
            claim: format!(
                "Section 7: C_0 = {C0_PAPER} is consistent with the reliability bound (6.1), C_0 eta_h >= ||u - u_h||_Linf, over the levels of each run's error-rate fit window (the asymptotic regime the bound speaks of, not the coarsest meshes), in all experiments with {}: every stored run with an error, of every study, whose eta_h carries the paper's log factor l_h (6.3); a run that estimates with another l_h has another eta_h, which (6.1) does not bound: those runs are named below and left out",
                terms::name(term)
            ),
            measured: if rows.is_empty() {
                "no data".into()
            } else {
                format!(
                    "{}. Left out, with another l_h: {}. Without an error-rate fit (too few levels): {}",
                    rows.iter().map(|r| r.0.clone()).collect::<Vec<_>>().join("; "),
                    if other_l_h.is_empty() { "none".to_string() } else { other_l_h.join(", ") },
                    if short.is_empty() { "none".to_string() } else { short.join(", ") }
                )
            },
            verdict: test.verdict(Kind::Paper, (!rows.is_empty()).then_some(Evidence::Value(worst)).as_ref()),
            criterion: test,
            kind: Kind::Paper,
            row: RowKind::Reliability,
            terms: vec![term],
        });
    }
    Ok(())
}

/// The size of the efficiency index per problem and variant (beside the paper's C_0): its range
/// and spread over the levels of the error-rate fit, and how far the smallest reliable C_0 of
/// one problem is from another's.
fn efficiency_size_claim(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let load = |s: &str| ctx.shelf.runs(s);
    let (deep, large, rollers, hertz) =
        (load(studies::DEEP)?, load(studies::EX72_LARGE)?, load(studies::EX72_ROLLERS)?, load(studies::HERTZ)?);
    let mut rows = Vec::new();
    let mut per_problem: Vec<(&str, f64)> = Vec::new();
    for (problem, runs, ids) in [
        (problem_names::EX71, &deep, [roles::DEEP_EX71_AS_WRITTEN, roles::DEEP_EX71_WFC, roles::DEEP_EX71_REPAIRED]),
        (problem_names::FB, &deep, [roles::DEEP_FB_AS_WRITTEN, roles::DEEP_FB_WFC, roles::DEEP_FB_REPAIRED]),
        (problem_names::EX72, &large, [roles::LARGE_AS_WRITTEN, roles::LARGE_WFC, roles::LARGE_REPAIRED]),
        (problem_names::EX72_ROLLERS, &rollers, [roles::ROLLERS_AS_WRITTEN, roles::ROLLERS_WFC, roles::ROLLERS_REPAIRED]),
        (problem_names::HERTZ, &hertz, [roles::HERTZ_AS_WRITTEN, roles::HERTZ_LIGHT, roles::HERTZ_REPAIRED]),
    ] {
        for role in ids {
            let Some(r) = ctx.find(runs, role) else { continue };
            let Some(rep) = ctx.rate(Some(r), Q::Error) else { continue };
            let eff = ctx.values(r, Q::Efficiency);
            let window: Vec<f64> = (rep.main.first_level..=rep.main.last_level).filter_map(|l| eff.get(l).copied().flatten()).collect();
            let (lo, hi) = (window.iter().cloned().fold(f64::INFINITY, f64::min), window.iter().cloned().fold(0.0, f64::max));
            if window.is_empty() {
                continue;
            }
            rows.push(format!("{}: {lo:.1e} to {hi:.1e} (spread {:.0}x; {})", source(Some(r)), hi / lo, short_range(&rep.main)));
            if let Some(c0) = ctx.reliability(r).map(|x| x.c0) {
                match per_problem.iter_mut().find(|p| p.0 == problem) {
                    Some(p) => p.1 = p.1.max(c0),
                    None => per_problem.push((problem, c0)),
                }
            }
        }
    }
    let (lo, hi) = (per_problem.iter().map(|p| p.1).fold(f64::INFINITY, f64::min), per_problem.iter().map(|p| p.1).fold(0.0, f64::max));
    let c0s = per_problem.iter().map(|(p, c)| format!("{p} {c:.1e}")).collect::<Vec<_>>().join(", ");
    let reported = Criterion::Reported { why: "the paper makes no claim on the size of the efficiency index".into() };
    out.push(Claim {
        fragile: None,
        id: "efficiency-size".into(),
        summary: Summary {
            topic: "Size of the efficiency index".into(),
            paper: concat!("C_0 = ", c0_paper!(), " for both examples (Section 7)"),
            headline: if per_problem.len() < 2 {
                "n/a".into()
            } else {
                format!("smallest reliable C_0 per problem {c0s}: one problem's C_0 is {:.0}x another's", hi / lo)
            },
        },
        claim: concat!("How large the efficiency index C_0 eta_h / error is, per problem and contact term, over the levels of each run's error-rate fit (the paper plots it in Fig. 2b and uses one C_0 = ", c0_paper!(), " for both examples; no claim on its size), and the smallest reliable C_0 per problem over these runs (the largest of their max error / eta_h over each error-rate fit window; over every stored run with the paper's l_h, of every study: rows c0)").into(),
        measured: if rows.is_empty() { "no data".into() } else { format!("estimate / error: {}. Smallest reliable C_0: {c0s}", rows.join("; ")) },
        verdict: reported.verdict(Kind::Beyond, (!rows.is_empty()).then_some(Evidence::Bool(true)).as_ref()),
        criterion: reported,
        kind: Kind::Beyond,
        row: RowKind::Measured,
        terms: vec![],
    });
    Ok(())
}

/// The marking parameter theta (the paper does not give it): the error rate per theta.
fn theta_claim(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let runs = ctx.shelf.runs(studies::THETA_ABLATION)?;
    let mut rows = Vec::new();
    let mut headline: Vec<(String, Vec<String>)> = Vec::new();
    for r in &runs {
        let rep = ctx.rate(Some(r), Q::Error);
        let last = r.levels.last();
        rows.push(format!(
            "{}: {}; last level NDF {}, error {}",
            r.run.id,
            rate_text("error rate", rep.as_ref(), None),
            last.map_or(0, |l| l.ndof),
            ctx.values(r, Q::Error).last().copied().flatten().map_or("n/a".into(), |e| format!("{e:.2e}"))
        ));
        if r.run.refine == model::settings::adapt::Refine::Adaptive {
            let short = |p: &RateReport| if p.main.spans_enough() { String::new() } else { " (under two decades: no verdict)".into() };
            let text = format!("θ = {}: {}", r.run.theta, rep.map_or("n/a".into(), |p| format!("{}{}", p.main.text(), short(&p))));
            match headline.iter_mut().find(|(p, _)| *p == r.run.problem) {
                Some((_, texts)) => texts.push(text),
                None => headline.push((r.run.problem.clone(), vec![text])),
            }
        }
    }
    let headline: Vec<String> = headline.iter().map(|(p, texts)| format!("{} {}", problem_names::label(p), texts.join(", "))).collect();
    let reported = Criterion::Reported { why: "the paper does not give theta; an ablation".into() };
    out.push(Claim {
        fragile: None,
        id: "theta (ablation)".into(),
        summary: Summary {
            topic: "The marking parameter theta (ablation)".into(),
            paper: "maximum strategy; theta not given",
            headline: if headline.is_empty() { "n/a".into() } else { format!("error rates {} (theta_ablation)", headline.join("; ")) },
        },
        claim: "The maximum strategy's theta (the paper does not give it): the error rate per theta in 0.3, 0.5, 0.7 and under uniform refinement, on Examples 7.1 and 7.2 (study theta_ablation, small runs: windows shorter than two decades are no verdict, and their ranges say so)".into(),
        measured: if rows.is_empty() { "no data".into() } else { rows.join("; ") },
        verdict: reported.verdict(Kind::Beyond, (!rows.is_empty()).then_some(Evidence::Bool(true)).as_ref()),
        criterion: reported,
        kind: Kind::Beyond,
        row: RowKind::Measured,
        terms: vec![],
    });
    Ok(())
}

/// The log-factor ablation: the efficiency trend per l_h.
fn log_factor_claim(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let la = ctx.shelf.runs(studies::LOG_ABLATION)?;
    let rows: Vec<String> =
        la.iter().map(|r| growth_text(&format!("{} efficiency", r.run.id), ctx.growth(Some(r), Q::Efficiency).as_ref())).collect();
    let reported = Criterion::Reported { why: "an ablation of eq. 6.3's factor, no claim of the paper".into() };
    out.push(Claim {
        fragile: None,
        id: "log-factor (ablation)".into(),
        summary: Summary {
            topic: "The log factor l_h (ablation)".into(),
            paper: "l_h = 1 + |log h_min|^2 (6.3); no claim",
            headline: la
                .iter()
                .map(|r| format!("{} {}", r.run.id, ctx.growth(Some(r), Q::Efficiency).map_or("n/a".into(), |g| g.text())))
                .collect::<Vec<_>>()
                .join(", "),
        },
        claim: "Eq. 6.3's factor l_h = 1 + |log h_min|^2 against 1 + |log h_min| and 1: the trend of the efficiency index (no claim of the paper; for reading the rows above)".into(),
        measured: rows.join("; "),
        verdict: reported.verdict(Kind::Beyond, (!rows.is_empty()).then_some(Evidence::Bool(true)).as_ref()),
        criterion: reported,
        kind: Kind::Beyond,
        row: RowKind::Measured,
        terms: vec![],
    });
    Ok(())
}

/// The tolerance of the Hertz check: a and p0 within 2% of Hertz's on the finest adaptive mesh.
pub const HERTZ_TOLERANCE: f64 = 0.02;

/// Hertz's cylinder on a flat (study `hertz`, beyond the paper): the half-width and peak pressure
/// of the finest adaptive mesh of each run against Hertz's at the run's computed force. The run
/// `adaptive` is judged; the others (a smaller load) measure how far the finite body is from
/// Hertz's half-spaces.
fn hertz_claims(ctx: &Ctx, out: &mut Vec<Claim>) -> Result<(), ClaimsError> {
    let study = roles::HERTZ_AS_WRITTEN.study;
    let runs = ctx.shelf.runs(study)?;
    let mut rows = Vec::new();
    let mut judged: Option<Evidence> = None;
    let mut headline = None;
    for r in &runs {
        let Some(snap) = latest_mesh(ctx.shelf, study, &r.run.id)? else { continue };
        let problem = ctx.shelf.problem(study, &r.run).map_err(ClaimsError::Problem)?;
        let Some(h) = crate::analysis::hertz::for_problem(problem.as_ref()) else {
            rows.push(format!("{}: problem {} has no circular contact group", r.run.id, r.run.problem));
            continue;
        };
        let Some(c) = crate::analysis::hertz::compare(&h, &snap.contact_nodes) else {
            rows.push(format!("{}: contact zone not resolved at level {}", r.run.id, snap.level));
            continue;
        };
        let res = c.half_width_resolution / c.hertz_half_width;
        rows.push(format!(
            "{} (level {}, NDF {}): F = {:.4}, a/R = {:.4}; a_h = {:.5} ± {:.5} (half the node spacing at the zone's ends) vs Hertz {:.5}: a_h - a between {:+.3}% and {:+.3}% of a; p0_h = {:.3} vs {:.3} ({:+.2}%); profile max |p_h - p|/p0 = {:.3}",
            r.run.id,
            snap.level,
            snap.ndof,
            c.force,
            c.hertz_half_width / h.radius,
            c.half_width,
            c.half_width_resolution,
            c.hertz_half_width,
            100.0 * (c.half_width_deviation() - res),
            100.0 * (c.half_width_deviation() + res),
            c.peak_pressure,
            c.hertz_peak_pressure,
            100.0 * c.peak_deviation(),
            c.profile_deviation
        ));
        if ctx.roles.id(roles::HERTZ_AS_WRITTEN) == Some(r.run.id.as_str()) {
            let a_dev = c.half_width_deviation();
            let (lo, hi) = (a_dev.abs() - res, a_dev.abs() + res);
            let p_dev = c.peak_deviation().abs();
            headline = Some(format!(
                "a_h - a {:+.2}% to {:+.2}%, p0 {:+.2}% (NDF {}, {})",
                100.0 * (c.half_width_deviation() - res),
                100.0 * (c.half_width_deviation() + res),
                100.0 * c.peak_deviation(),
                snap.ndof,
                source(Some(r))
            ));
            judged = Some(Evidence::All(vec![Some(Evidence::Interval(lo, hi)), Some(Evidence::Value(p_dev))]));
        }
    }
    let test = Criterion::All(vec![
        Criterion::AtMost {
            what: format!(
                "|a_h - a| / a on {}'s finest mesh (a_h ± half the node spacing at the zone's ends)",
                ctx.roles.source(roles::HERTZ_AS_WRITTEN)
            ),
            limit: HERTZ_TOLERANCE,
            interval: true,
        },
        Criterion::AtMost { what: "|p0_h - p0| / p0 there".into(), limit: HERTZ_TOLERANCE, interval: false },
    ]);
    out.push(Claim {
        fragile: None,
        // the row is named after the study it judges
        id: studies::HERTZ.into(),
        summary: Summary { topic: "Hertz: cylinder on a flat".into(), paper: "Hertz's a and p0 within 2% (beyond the paper)", headline: headline.unwrap_or("n/a".into()) },
        claim: format!(
            "Hertz (beyond the paper): an elastic cylinder (plane strain) on a rigid flat, adaptive with the paper's estimator: on the finest mesh the contact half-width a (± half the node spacing at the zone's ends) and the peak pressure p0 within {:.0}% of Hertz's a = sqrt(4FR(1 - nu^2)/(pi E)), p0 = 2F/(pi a) at the computed force F; the run with the smaller load measures the finite-size deviation",
            100.0 * HERTZ_TOLERANCE
        ),
        measured: if rows.is_empty() { "no data".into() } else { rows.join("; ") },
        verdict: test.verdict(Kind::Beyond, judged.as_ref()),
        criterion: test,
        kind: Kind::Beyond,
        row: RowKind::Finding,
        terms: vec![],
    });
    Ok(())
}

/// Every claim with errors sampled one way and fits on alternate levels of one parity.
pub fn claims_with(shelf: &Shelf, roles: &Roles, sampling: ErrorSampling, parity: Parity) -> Result<Vec<Claim>, ClaimsError> {
    let ctx = Ctx { sampling, parity, shelf, roles };
    let mut out = Vec::new();
    ex71::claims(&ctx, &mut out)?;
    ex72::claims(&ctx, &mut out)?;
    c0_claims(&ctx, &mut out)?;
    rollers::claims(&ctx, &mut out)?;
    fb::claims(&ctx, &mut out)?;
    hertz_claims(&ctx, &mut out)?;
    rows::efficiency_up_to_lh(&ctx, &mut out)?;
    efficiency_size_claim(&ctx, &mut out)?;
    log_factor_claim(&ctx, &mut out)?;
    theta_claim(&ctx, &mut out)?;
    repair::estimator_repair_claim(&ctx, &mut out)?;
    Ok(out)
}

/// Mark the rows of `out` whose verdict `other` (the same rows computed another way) changes,
/// saying how (`way`: "the dense sampling of the error"); the rows that flip, as "id: a → b (way: measured)".
fn mark_flips(out: &mut [Claim], other: &[Claim], way: &str) -> Vec<String> {
    let mut flips = Vec::new();
    for q in out.iter_mut() {
        let Some(d) = other.iter().find(|d| d.id == q.id) else { continue };
        if q.verdict != d.verdict {
            let why = format!("{way} gives {}", d.verdict.text().replace("**", ""));
            q.fragile = Some(match q.fragile.take() {
                Some(w) => format!("{w}; {why}"),
                None => why,
            });
            flips.push(format!("{}: {} → {} ({way}: {})", q.id, q.verdict.text(), d.verdict.text(), d.summary.headline));
        }
    }
    flips
}

/// All claims, from the stored studies under `results` whose runs stand for the `roles`
/// ([`roles::check`]), each verdict computed three ways: the fits on the alternate levels of the
/// last level's parity with the error at the quadrature points (the verdict), then on the other
/// parity, then with the error on the dense lattice; a verdict another way changes is fragile,
/// and the rows `parity` and `sampling` list them.
pub fn claims(shelf: &Shelf, roles: &Roles) -> Result<Vec<Claim>, ClaimsError> {
    let mut out = claims_with(shelf, roles, ErrorSampling::Quadrature, Parity::Last)?;
    let other = claims_with(shelf, roles, ErrorSampling::Quadrature, Parity::Other)?;
    let dense = claims_with(shelf, roles, ErrorSampling::Dense, Parity::Last)?;
    let judged = out.len();
    let nothing = out.iter().all(|c| c.verdict == Verdict::NoData);
    let parity_flips = mark_flips(&mut out, &other, "the other parity of levels");
    let dense_flips = mark_flips(&mut out, &dense, "the dense sampling of the error");
    let mut dense_runs = Vec::new();
    for (_, twin) in DENSE_TWINS {
        if let Some(r) = roles.find(&shelf.runs(twin.study).map_err(std::io::Error::from)?, twin) {
            dense_runs.push(source(Some(r)));
        }
    }
    let flip_row = |id: &str, topic: &str, paper: &'static str, claim: String, flips: &[String], extra: String| {
        let test = Criterion::AtMost { what: format!("the number of verdicts above that change {}", topic), limit: 0.0, interval: false };
        // nothing recomputed (every row without data): no verdict can hold or flip
        let evidence = (!nothing).then_some(Evidence::Value(flips.len() as f64));
        Claim {
            fragile: None,
            id: id.into(),
            summary: Summary { topic: capitalised(topic), paper, headline: format!("{} of {judged} verdicts flip", flips.len()) },
            claim,
            measured: format!(
                "{} ({judged} verdicts recomputed{extra})",
                if flips.is_empty() { "no verdict flips".to_string() } else { format!("verdicts that flip: {}", flips.join("; ")) }
            ),
            verdict: test.verdict(Kind::Beyond, evidence.as_ref()),
            criterion: test,
            kind: Kind::Beyond,
            row: RowKind::Finding,
            terms: vec![],
        }
    };
    out.push(flip_row(
        "parity",
        "with the other parity of levels",
        "fits on every other level; which ones not given",
        "Newest-vertex bisection refines in two-level staircases, so every fit takes every other level: every verdict above recomputed on the other alternate levels (the run's last level dropped, the windows ending one level earlier); a verdict that changes is fragile and the headline counts it as undecided".into(),
        &parity_flips,
        String::new(),
    ));
    out.push(flip_row(
        "sampling",
        "with the dense sampling of the error",
        "maxima at quadrature points (the paper's choice)",
        "Gauss-point maxima underestimate the L-infinity norm: every verdict above recomputed with the error maxima over the order-6 barycentric lattice of every element (err_dense) instead of the quadrature points, and with the runs RUN_dense (estimator maxima on the dense lattice and dense edge points too, `estimator.sampling = \"dense\"`) in place of RUN where a study has them".into(),
        &dense_flips,
        format!("; dense-estimator runs used: {}", if dense_runs.is_empty() { "none".to_string() } else { dense_runs.join(", ") }),
    ));
    Ok(out)
}

/// The anchor GitHub gives the heading `### ID` of a claim: lower case, spaces to hyphens, every
/// other character but letters, digits, `-` and `_` dropped.
pub fn anchor(id: &str) -> String {
    id.to_lowercase()
        .chars()
        .filter_map(|c| if c == ' ' { Some('-') } else { (c.is_alphanumeric() || c == '-' || c == '_').then_some(c) })
        .collect()
}

/// `text` with its first letter in upper case.
pub fn capitalised(text: &str) -> String {
    let mut c = text.chars();
    c.next().map(|f| f.to_uppercase().chain(c).collect()).unwrap_or_default()
}

/// The markdown document, generated from the records in `results/`.
pub fn markdown(claims: &[Claim]) -> String {
    markdown_for(claims, Path::new("results"))
}

/// The markdown document, saying which results folder it was generated from.
pub fn markdown_for(claims: &[Claim], results: &Path) -> String {
    let mut s = String::new();
    s += "# Claims of Section 7, measured\n\n";
    let _ = write!(
        s,
        "Generated by `signorini figures` from the records in `{}/` (never edited by hand). One line per claim: what it says in a few words, what the paper says, \
         the headline measurement (rate ± 95% half-width over the window of NDF named, on the run named) and the verdict; the claim's name links to its evidence below.\n\n",
        results.display().to_string().trim_end_matches('/')
    );
    s += "## Headline\n\n";
    for line in headline::lines(claims) {
        s += &line;
        s += "\n";
    }
    let _ = write!(s, "\n{}\n\n", headline::finding(claims));
    s += "## Every row\n\n";
    s += "| claim | the paper | measured | verdict |\n|---|---|---|---|\n";
    let cell = |t: &str| t.replace('|', "\\|");
    for c in claims {
        let fragile = if c.fragile.is_some() { ", *fragile*" } else { "" };
        let _ = writeln!(
            s,
            "| [**{}**](#{}): {} | {} | {} | {}{} |",
            c.id,
            anchor(&c.id),
            cell(&c.summary.topic),
            cell(c.summary.paper),
            cell(&c.summary.headline),
            c.verdict.text(),
            fragile
        );
    }
    s += "\n## How the rows are judged\n\n";
    let _ = write!(
        s,
        "Rates are least-squares slopes of -log(quantity) against log(NDF) with 95% Student-t intervals (rate ± half-width), fitted on every other level \
         (newest-vertex bisection refines in two-level staircases) over the last levels spanning at least {} decades of NDF and at least {} levels; \
         \"windows\" are the slopes of the same fit ending 0, {} and {} levels earlier. Under uniform refinement the exponent is fitted against h_min instead (\"in h_min\": error ~ h_min^rate), \
         over the same levels, and a claim of NDF^-c is judged as h^-2c with the band doubled. Verdict for a claimed rate c: the interval below c - {b} is **not reproduced**, \
         above c + {b} **different** (faster); the whole interval inside c ± {b} is reproduced; anything else, however close its centre, inconclusive, and so is every fit over a window shorter than {d} decades (a run that ends early: its range says so). \
         **Parity.** Every verdict is computed twice, on the alternate levels of the run's last level and on the other alternate levels (the last level dropped); \
         a verdict that differs between them, or changes with the window (ending 2 or 4 levels earlier) or with the dense sampling of the error, is marked *fragile*, with what changes it, \
         and the headline counts it as undecided, a pass or a failure alike (the rows `parity` and `sampling` list the flips). \
         **One rule per kind of claim**, the same on every problem and contact term: a *rate* as above; *efficiency*: the slope of log(estimate / error) against log(NDF) over the same window \
         has an interval containing 0 no wider than {w} (bounded; excluding 0 fails, growing or falling; containing 0 but wider is inconclusive); *efficiency up to l_h*: the same on estimate / error / l_h; \
         *reliability*: the largest error / eta_h over the levels of each error-rate fit window (not from the coarsest mesh) at most C_0 = {C0_PAPER}; \
         *refinement at the free boundary*: the length h_fb of the contact edge straddling a free-boundary point decays faster than NDF^-0.5 (uniform refinement) beyond its interval. \
         **References.** Where errors are measured against a reference solution, its own error is estimated by extrapolating the fitted error rate of the run marked as the reference is to the reference's NDF; \
         a reference whose own error exceeds {r:.0}% of the smallest error a row judges leaves that row undecided. \
         Example 7.1 and fb are judged on the runs of the study deep (to at least 1e7 NDF), Example 7.2's estimator and errors on ex72_large (to 1.1e6 NDF); every row names the runs it fits as study/run. \
         The paper's claims are rows 7.1-*, 7.2-* (those not marked beyond the paper) and c0, each judged once per contact term of eta_5 (one row for two terms whose runs coincide); \
         the claims carried to problems the paper never ran (rollers, fb, Hertz) are beyond the paper, counted apart. \
         Intervals wider than ± {t} (in NDF) are marked. \
         Errors and estimators are maxima over the quadrature points of each element (the `sampling` row repeats every verdict with a dense lattice); estimate = C_0 eta_h with C_0 = {C0_PAPER}.\n\n",
        verdict::MIN_DECADES,
        verdict::MIN_POINTS,
        verdict::WINDOW_SHIFT,
        2 * verdict::WINDOW_SHIFT,
        b = verdict::RATE_BAND,
        w = verdict::MAX_WIDTH,
        d = verdict::MIN_DECADES,
        t = TARGET_HALF_WIDTH,
        r = 100.0 * REFERENCE_SHARE,
    );
    s += "## Evidence\n";
    for c in claims {
        let fragile = c.fragile.as_ref().map(|f| format!(", *fragile*: {f}")).unwrap_or_default();
        let _ = write!(
            s,
            "\n### {}\n\n**Claim.** {}\n\n**What would fail it.** {}\n\n**Measured.** {}\n\n**Verdict.** {}{}\n",
            c.id,
            c.claim,
            capitalised(&c.criterion.fails_if()),
            c.measured,
            c.verdict.text(),
            fragile
        );
    }
    s
}

/// Write `CLAIMS.md` into the results folder the shelf holds.
pub fn write(shelf: &Shelf, roles: &Roles) -> Result<(), ClaimsError> {
    let c = claims(shelf, roles)?;
    let results = shelf.root();
    Ok(store::records::write_atomic(&results.join("CLAIMS.md"), markdown_for(&c, results).as_bytes())?)
}
