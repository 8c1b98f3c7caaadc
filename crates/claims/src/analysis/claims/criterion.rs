//! What would fail a row. A [`Criterion`] is the rule a CLAIMS row applies: the same object
//! judges the row's evidence ([`Criterion::judge`], [`Criterion::verdict`]) and states in words
//! the condition that fails it ([`Criterion::fails_if`]), both from the same numbers (the claimed
//! rate, [`verdict::RATE_BAND`], [`verdict::MAX_WIDTH`], [`verdict::MIN_DECADES`], a limit), so
//! the stated condition cannot drift from the code. A row that only reports a measurement has
//! [`Criterion::Reported`]: it says so and neither passes nor fails.

use super::Verdict;
use crate::analysis::verdict::{self, Abscissa, RateFit, RateVerdict, Trend};

/// What a criterion is judged on.
#[derive(Clone, Debug)]
pub enum Evidence {
    /// A fitted rate ([`Criterion::Rate`], [`Criterion::Decays`]) or trend ([`Criterion::Bounded`]:
    /// the slope of log(quantity) against log NDF, as [`verdict::growth`] gives it).
    Fit(RateFit),
    /// A number ([`Criterion::AtMost`]).
    Value(f64),
    /// A number known within [lo, hi] ([`Criterion::AtMost`]).
    Interval(f64, f64),
    /// A finding ([`Criterion::Test`]).
    Bool(bool),
    /// [`Criterion::FewerUnknowns`]: the upper end of the 95% interval of uniform refinement's
    /// rate in NDF, and (where a common window of a decade exists) the fitted lines' ln(error)
    /// with their 95% half-widths at its end, (adaptive, uniform).
    Unknowns { uniform_rate_hi: f64, lines: Option<((f64, f64), (f64, f64))> },
    /// One per part of [`Criterion::All`] or item of [`Criterion::Each`] (None: not measured).
    All(Vec<Option<Evidence>>),
}

impl Evidence {
    /// The main fit of a rate report.
    pub fn rate(rep: Option<&verdict::RateReport>) -> Option<Evidence> {
        rep.map(|r| Evidence::Fit(r.main))
    }
    /// A fit.
    pub fn fit(f: Option<&RateFit>) -> Option<Evidence> {
        f.map(|f| Evidence::Fit(*f))
    }
}

/// How a criterion came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    Pass,
    /// Fails: a rate slower than claimed.
    Slower,
    /// Fails: a rate faster than claimed.
    Faster,
    /// Fails otherwise (a value above its limit, a trend, a finding that is false).
    Fail,
    /// Not decided (an interval that straddles the limit, a window too short).
    Open,
    /// The criterion cannot tell anything on this evidence, and says why.
    NotApplicable,
    /// Measured without a claim ([`Criterion::Reported`]).
    Reported,
    NoData,
}

impl Outcome {
    pub fn failed(self) -> bool {
        matches!(self, Outcome::Slower | Outcome::Faster | Outcome::Fail)
    }
    /// "holds", "fails", "not decided", "not applicable"
    pub fn text(self) -> &'static str {
        match self {
            Outcome::Pass => "holds",
            Outcome::Slower | Outcome::Faster | Outcome::Fail => "fails",
            Outcome::Open | Outcome::NoData => "not decided",
            Outcome::NotApplicable => "not applicable",
            Outcome::Reported => "reported",
        }
    }
}

/// Whose claim a row judges: the paper's (reproduced / not reproduced) or one beyond it (holds / fails).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Paper,
    Beyond,
}

/// The rule a row applies.
#[derive(Clone, Debug, PartialEq)]
pub enum Criterion {
    /// `what` decays at NDF^-claim: [`verdict::judge_rate`] on its fit (against `abscissa`).
    Rate { what: String, claim: f64, abscissa: Abscissa },
    /// The trend of `what` is bounded: [`verdict::judge_trend`].
    Bounded { what: String },
    /// The trend of `what` does not grow: bounded or falling ([`verdict::judge_trend`]), as an
    /// upper bound (an efficiency up to a factor) claims.
    NotGrowing { what: String },
    /// `what` decays faster than NDF^-than beyond its interval (a rate against a limit, not a
    /// band): fitted against `abscissa`, the limit converted to it as for [`Criterion::Rate`].
    FasterThan { what: String, than: f64, abscissa: Abscissa },
    /// `what` decays at all: the 95% interval of its rate in NDF above 0 (an interval reaching 0
    /// over two decades shows no decay: it fails).
    Decays { what: String },
    /// `what` is at most `limit`; `interval`: it is known within an interval.
    AtMost { what: String, limit: f64, interval: bool },
    /// A finding: fails (or, with `open_if_not`, is not decided) unless `passes_if` is true.
    Test { passes_if: String, open_if_not: bool },
    /// Fewer unknowns than uniform refinement for the same error, where uniform refinement is
    /// slower than `claim` beyond its band (see `claims::repair::unknowns`).
    FewerUnknowns { claim: f64 },
    /// The reference solution a row's errors are measured against is fine enough: its own error
    /// (estimated) at most `share` of the smallest error the row judges (evidence: that ratio).
    /// A coarser reference leaves the row undecided; it does not fail the claim.
    Reference { share: f64 },
    /// The same criterion for each of `of` (evidence: one per item).
    Each { of: Vec<String>, each: Box<Criterion> },
    /// Every part (evidence: one per part).
    All(Vec<Criterion>),
    /// No claim: measured and reported only.
    Reported { why: String },
}

/// A limit as the rows print it: "0.45", "1e-12", "0".
fn number(v: f64) -> String {
    let plain = format!("{v}");
    if v != 0.0 && v.abs() < 1e-3 {
        format!("{v:.0e}")
    } else if plain.len() > 6 {
        format!("{v:.4}")
    } else {
        plain
    }
}

/// The outcome of several parts: a failure first (slower, then otherwise, then faster), then
/// anything undecided or missing; it passes when every part passes or is not applicable and one passes.
pub fn combine(outs: &[Outcome]) -> Outcome {
    use Outcome::*;
    if outs.iter().all(|o| *o == NoData) {
        return NoData;
    }
    for o in [Slower, Fail, Faster] {
        if outs.contains(&o) {
            return o;
        }
    }
    if outs.iter().any(|o| matches!(o, Open | NoData | Reported)) {
        Open
    } else if outs.contains(&Pass) {
        Pass
    } else {
        NotApplicable
    }
}

impl Criterion {
    /// A rate claim of NDF^-claim on `what`, fitted against `abscissa`.
    pub fn rate(what: impl Into<String>, claim: f64, abscissa: Abscissa) -> Criterion {
        Criterion::Rate { what: what.into(), claim, abscissa }
    }

    /// How the criterion comes out on `e` (None: nothing measured).
    pub fn judge(&self, e: Option<&Evidence>) -> Outcome {
        let Some(e) = e else { return Outcome::NoData };
        match (self, e) {
            (Criterion::Rate { abscissa, claim, .. }, Evidence::Fit(f)) if f.abscissa == *abscissa => {
                match verdict::judge_rate(f, *claim) {
                    RateVerdict::Reproduced => Outcome::Pass,
                    RateVerdict::NotReproduced => Outcome::Slower,
                    RateVerdict::Different => Outcome::Faster,
                    RateVerdict::Inconclusive => Outcome::Open,
                }
            }
            (Criterion::Bounded { .. }, Evidence::Fit(f)) => match verdict::judge_trend(f) {
                Trend::Bounded => Outcome::Pass,
                Trend::Growing | Trend::Falling => Outcome::Fail,
                Trend::Inconclusive | Trend::Short => Outcome::Open,
            },
            (Criterion::NotGrowing { .. }, Evidence::Fit(f)) => match verdict::judge_trend(f) {
                Trend::Bounded | Trend::Falling => Outcome::Pass,
                Trend::Growing => Outcome::Fail,
                Trend::Inconclusive | Trend::Short => Outcome::Open,
            },
            (Criterion::FasterThan { than, abscissa, .. }, Evidence::Fit(f)) if f.abscissa == *abscissa => {
                let limit = f.claim_in_abscissa(*than).0;
                if !f.spans_enough() {
                    Outcome::Open
                } else if f.rate.lo() > limit {
                    Outcome::Pass
                } else if f.rate.hi() < limit {
                    Outcome::Slower
                } else {
                    Outcome::Open
                }
            }
            (Criterion::Decays { .. }, Evidence::Fit(f)) => {
                if !f.spans_enough() {
                    Outcome::Open
                } else if f.rate.lo() > 0.0 {
                    Outcome::Pass
                } else {
                    Outcome::Fail
                }
            }
            (Criterion::AtMost { limit, .. }, Evidence::Value(v)) => {
                if *v <= *limit {
                    Outcome::Pass
                } else if *v > *limit {
                    Outcome::Fail
                } else {
                    Outcome::Open // NaN
                }
            }
            (Criterion::AtMost { limit, interval: true, .. }, Evidence::Interval(lo, hi)) => {
                if *hi <= *limit {
                    Outcome::Pass
                } else if *lo > *limit {
                    Outcome::Fail
                } else {
                    Outcome::Open
                }
            }
            (Criterion::Test { open_if_not, .. }, Evidence::Bool(b)) => match (b, open_if_not) {
                (true, _) => Outcome::Pass,
                (false, true) => Outcome::Open,
                (false, false) => Outcome::Fail,
            },
            (Criterion::FewerUnknowns { claim }, Evidence::Unknowns { uniform_rate_hi, lines }) => {
                if *uniform_rate_hi >= claim - verdict::RATE_BAND {
                    Outcome::NotApplicable
                } else {
                    match lines {
                        None => Outcome::Open,
                        Some(((ya, wa), (yu, wu))) if ya + wa < yu - wu => Outcome::Pass,
                        Some(((ya, wa), (yu, wu))) if ya - wa > yu + wu => Outcome::Fail,
                        Some(_) => Outcome::Open,
                    }
                }
            }
            (Criterion::Reference { share }, Evidence::Value(v)) => {
                if *v <= *share {
                    Outcome::Pass
                } else {
                    Outcome::Open
                }
            }
            (Criterion::Each { of, each }, Evidence::All(es)) if es.len() == of.len() => {
                combine(&es.iter().map(|e| each.judge(e.as_ref())).collect::<Vec<_>>())
            }
            (Criterion::All(parts), Evidence::All(es)) if es.len() == parts.len() => {
                let outs: Vec<Outcome> = parts.iter().zip(es).map(|(p, e)| p.judge(e.as_ref())).collect();
                // errors against a reference too coarse decide nothing, a failure included
                let coarse = parts.iter().zip(&outs).any(|(p, o)| matches!(p, Criterion::Reference { .. }) && *o != Outcome::Pass);
                if coarse { Outcome::Open } else { combine(&outs) }
            }
            (Criterion::Reported { .. }, _) => Outcome::Reported,
            // evidence of another kind than the criterion judges: decides nothing
            _ => Outcome::Open,
        }
    }

    /// The rule a row of some kind applies, without the runs it names: "rate 1.5 in NDF of the
    /// adaptive error", "bounded estimate / error". A reference check and the items of
    /// [`Criterion::Each`] are the rule of their principal part.
    pub fn rule(&self) -> String {
        // `what` names the runs last, in parentheses: "estimate / error (deep/ex71_as_written)"
        let bare = |w: &str| w.rsplit_once(" (").map_or(w, |(head, _)| head).to_string();
        match self {
            Criterion::Rate { claim, abscissa, .. } => format!("rate {claim} against {abscissa:?}"),
            Criterion::Bounded { what } => format!("bounded {}", bare(what)),
            Criterion::NotGrowing { what } => format!("not growing {}", bare(what)),
            Criterion::FasterThan { what, than, abscissa } => format!("{} faster than {than} against {abscissa:?}", bare(what)),
            Criterion::Decays { what } => format!("decays {}", bare(what)),
            Criterion::AtMost { what, limit, .. } => format!("{} at most {limit}", bare(what)),
            Criterion::Test { passes_if, .. } => format!("test: {passes_if}"),
            Criterion::FewerUnknowns { claim } => format!("fewer unknowns than uniform, claim {claim}"),
            Criterion::Reference { share } => format!("reference within {share}"),
            Criterion::Each { each, .. } => each.rule(),
            Criterion::All(parts) => {
                parts.iter().filter(|p| !matches!(p, Criterion::Reference { .. })).map(Criterion::rule).collect::<Vec<_>>().join(" and ")
            }
            Criterion::Reported { .. } => "reported".into(),
        }
    }

    /// The row's verdict on `e`.
    pub fn verdict(&self, kind: Kind, e: Option<&Evidence>) -> Verdict {
        match (self.judge(e), kind) {
            (Outcome::NoData, _) => Verdict::NoData,
            (Outcome::Reported, _) => Verdict::NoClaim,
            (Outcome::Open | Outcome::NotApplicable, _) => Verdict::Inconclusive,
            (Outcome::Pass, Kind::Paper) => Verdict::Reproduced,
            (Outcome::Slower | Outcome::Fail, Kind::Paper) => Verdict::NotReproduced,
            (Outcome::Faster, Kind::Paper) => Verdict::Different,
            (Outcome::Pass, Kind::Beyond) => Verdict::Holds,
            (Outcome::Slower | Outcome::Faster | Outcome::Fail, Kind::Beyond) => Verdict::Fails,
        }
    }

    /// The condition that fails the row, in words, from the numbers [`Self::judge`] uses.
    pub fn fails_if(&self) -> String {
        let d = verdict::MIN_DECADES;
        match self {
            Criterion::Rate { what, claim, abscissa } => {
                let (c, band, var) = match abscissa {
                    Abscissa::Ndof => (*claim, verdict::RATE_BAND, "its rate in NDF (NDF^-rate)".to_string()),
                    Abscissa::InverseHMin => (
                        2.0 * claim,
                        2.0 * verdict::RATE_BAND,
                        format!("its exponent in h_min (h_min^rate; NDF^-{} is h^{}, band doubled)", number(*claim), number(2.0 * claim)),
                    ),
                };
                let (lo, hi) = (c - band, c + band);
                format!(
                    "fails if the 95% interval of {what}: {var} over the window lies below {lo:.3} (slower) or above {hi:.3} (faster); not decided if it reaches outside [{lo:.3}, {hi:.3}] or the window spans less than {d} decades of NDF"
                )
            }
            Criterion::Bounded { what } => format!(
                "fails if the 95% interval of the slope of log({what}) against log NDF over the window excludes 0 (growing or falling); not decided if it contains 0 but is wider than {} or the window spans less than {d} decades of NDF",
                verdict::MAX_WIDTH
            ),
            Criterion::NotGrowing { what } => format!(
                "fails if the 95% interval of the slope of log({what}) against log NDF over the window lies above 0 (growing); not decided if it contains 0 but is wider than {} or the window spans less than {d} decades of NDF",
                verdict::MAX_WIDTH
            ),
            Criterion::FasterThan { what, than, abscissa } => {
                let (limit, var) = match abscissa {
                    Abscissa::Ndof => (*than, "its rate in NDF (NDF^-rate)".to_string()),
                    Abscissa::InverseHMin => {
                        (2.0 * than, format!("its exponent in h_min (h_min^rate; NDF^-{} is h^{})", number(*than), number(2.0 * than)))
                    }
                };
                format!(
                    "fails if the 95% interval of {what}: {var} over the window lies below {limit:.3} (not faster); not decided if it contains {limit:.3} or the window spans less than {d} decades of NDF"
                )
            }
            Criterion::Decays { what } => format!(
                "fails unless the 95% interval of the rate of {what} in NDF lies above 0 (a decay); not decided if the window spans less than {d} decades of NDF"
            ),
            Criterion::AtMost { what, limit, interval: false } => format!("fails if {what} exceeds {}", number(*limit)),
            Criterion::AtMost { what, limit, interval: true } => {
                format!("fails if the whole interval of {what} lies above {0}; not decided if it straddles {0}", number(*limit))
            }
            Criterion::Test { passes_if, open_if_not: false } => format!("fails unless {passes_if}"),
            Criterion::Test { passes_if, open_if_not: true } => format!("not decided unless {passes_if}"),
            Criterion::FewerUnknowns { claim } => format!(
                "not applicable where the 95% interval of uniform refinement's error rate in NDF reaches {:.1} (uniform attains the claimed rate's band); elsewhere fails if, at the end of the common window of both fitted error lines (a decade of NDF at least, no extrapolation), the 95% interval of the adaptive line's error lies above the uniform line's (adaptive needs more unknowns); not decided if they overlap",
                claim - verdict::RATE_BAND
            ),
            Criterion::Reference { share } => format!(
                "not decided while the reference solution's own error (estimated by extrapolating the fitted error rate of the run marked as the reference is to the reference's NDF) exceeds {:.0}% of the smallest error judged",
                100.0 * share
            ),
            Criterion::Each { of, each } => format!("for each of {}: {}", of.join(", "), each.fails_if()),
            Criterion::All(parts) => parts.iter().map(|p| p.fails_if()).collect::<Vec<_>>().join("; "),
            Criterion::Reported { why } => format!("nothing can fail it: {why}; reported, it neither passes nor fails"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model::base::stats::LineFit;

    fn fit(slope: f64, half_width: f64, decades: f64, abscissa: Abscissa) -> RateFit {
        RateFit {
            rate: LineFit { slope, half_width, points: 6 },
            abscissa,
            first_level: 0,
            last_level: 10,
            first_ndof: 1000,
            last_ndof: (1000.0 * 10f64.powf(decades)).round() as usize,
        }
    }

    #[test]
    fn a_rate_fails_beyond_the_stated_bounds() {
        let c = Criterion::rate("the error", 1.5, Abscissa::Ndof);
        assert!(c.fails_if().contains("below 1.400") && c.fails_if().contains("above 1.600"), "{}", c.fails_if());
        let v = |s, w| c.verdict(Kind::Paper, Some(&Evidence::Fit(fit(s, w, 2.5, Abscissa::Ndof))));
        assert_eq!(v(1.35, 0.04), Verdict::NotReproduced);
        assert_eq!(v(1.65, 0.04), Verdict::Different);
        assert_eq!(v(1.5, 0.05), Verdict::Reproduced);
        assert_eq!(v(1.42, 0.04), Verdict::Inconclusive);
        // in h_min the stated bounds are doubled, and so is the judgement
        let h = Criterion::rate("the error", 0.3556, Abscissa::InverseHMin);
        assert!(h.fails_if().contains("below 0.511"), "{}", h.fails_if());
        assert_eq!(h.verdict(Kind::Beyond, Some(&Evidence::Fit(fit(0.49, 0.01, 2.5, Abscissa::InverseHMin)))), Verdict::Fails);
        assert_eq!(h.verdict(Kind::Beyond, Some(&Evidence::Fit(fit(0.71, 0.01, 2.5, Abscissa::InverseHMin)))), Verdict::Holds);
        // a fit against the other variable decides nothing
        assert_eq!(h.judge(Some(&Evidence::Fit(fit(0.71, 0.01, 2.5, Abscissa::Ndof)))), Outcome::Open);
    }

    #[test]
    fn bounded_at_most_decays_and_tests_fail_as_stated() {
        let b = Criterion::Bounded { what: "efficiency".into() };
        assert_eq!(b.verdict(Kind::Beyond, Some(&Evidence::Fit(fit(0.2, 0.04, 2.5, Abscissa::Ndof)))), Verdict::Fails);
        assert_eq!(b.verdict(Kind::Beyond, Some(&Evidence::Fit(fit(0.0, 0.04, 2.5, Abscissa::Ndof)))), Verdict::Holds);
        let m = Criterion::AtMost { what: "C".into(), limit: 0.45, interval: false };
        assert_eq!(m.fails_if(), "fails if C exceeds 0.45");
        assert_eq!(m.verdict(Kind::Paper, Some(&Evidence::Value(0.46))), Verdict::NotReproduced);
        assert_eq!(m.verdict(Kind::Paper, Some(&Evidence::Value(0.45))), Verdict::Reproduced);
        let i = Criterion::AtMost { what: "d".into(), limit: 0.02, interval: true };
        assert_eq!(i.judge(Some(&Evidence::Interval(0.021, 0.03))), Outcome::Fail);
        assert_eq!(i.judge(Some(&Evidence::Interval(0.01, 0.03))), Outcome::Open);
        let z = Criterion::Decays { what: "z".into() };
        assert_eq!(z.judge(Some(&Evidence::Fit(fit(-0.3, 0.1, 2.5, Abscissa::Ndof)))), Outcome::Fail);
        assert_eq!(z.judge(Some(&Evidence::Fit(fit(0.0, 0.0, 2.5, Abscissa::Ndof)))), Outcome::Fail, "a zone that stalls");
        assert_eq!(z.judge(Some(&Evidence::Fit(fit(0.5, 0.1, 1.5, Abscissa::Ndof)))), Outcome::Open, "a short window");
        assert_eq!(z.judge(Some(&Evidence::Fit(fit(0.3, 0.1, 2.5, Abscissa::Ndof)))), Outcome::Pass);
        let t = Criterion::Test { passes_if: "it is".into(), open_if_not: false };
        assert_eq!(t.judge(Some(&Evidence::Bool(false))), Outcome::Fail);
        let f = Criterion::FewerUnknowns { claim: 1.5 };
        let u = |hi, l| f.judge(Some(&Evidence::Unknowns { uniform_rate_hi: hi, lines: l }));
        assert_eq!(u(1.45, Some(((0.0, 0.1), (5.0, 0.1)))), Outcome::NotApplicable);
        assert_eq!(u(0.4, Some(((0.0, 0.1), (5.0, 0.1)))), Outcome::Pass);
        assert_eq!(u(0.4, Some(((5.0, 0.1), (0.0, 0.1)))), Outcome::Fail);
        assert_eq!(u(0.4, Some(((0.0, 0.1), (0.1, 0.1)))), Outcome::Open);
    }

    #[test]
    fn faster_than_and_not_growing_fail_as_stated() {
        let f = Criterion::FasterThan { what: "h_fb".into(), than: 0.5, abscissa: Abscissa::Ndof };
        assert!(f.fails_if().contains("below 0.500"), "{}", f.fails_if());
        let j = |s, w, dec| f.judge(Some(&Evidence::Fit(fit(s, w, dec, Abscissa::Ndof))));
        assert_eq!(j(0.7, 0.1, 2.5), Outcome::Pass);
        assert_eq!(j(0.3, 0.1, 2.5), Outcome::Slower);
        assert_eq!(j(0.55, 0.1, 2.5), Outcome::Open, "an interval containing the limit");
        assert_eq!(j(0.7, 0.1, 1.5), Outcome::Open, "a short window");
        // in h_min the limit doubles: h^0.711 is NDF^-0.356
        let h = Criterion::FasterThan { what: "e".into(), than: 0.3556, abscissa: Abscissa::InverseHMin };
        assert!(h.fails_if().contains("below 0.711"), "{}", h.fails_if());
        assert_eq!(h.judge(Some(&Evidence::Fit(fit(0.9, 0.05, 2.5, Abscissa::InverseHMin)))), Outcome::Pass);
        assert_eq!(h.judge(Some(&Evidence::Fit(fit(0.6, 0.05, 2.5, Abscissa::InverseHMin)))), Outcome::Slower);
        assert_eq!(h.judge(Some(&Evidence::Fit(fit(0.9, 0.05, 2.5, Abscissa::Ndof)))), Outcome::Open, "another variable");
        let g = Criterion::NotGrowing { what: "e".into() };
        assert!(g.fails_if().contains("lies above 0"), "{}", g.fails_if());
        assert_eq!(g.judge(Some(&Evidence::Fit(fit(0.2, 0.04, 2.5, Abscissa::Ndof)))), Outcome::Fail);
        assert_eq!(g.judge(Some(&Evidence::Fit(fit(-0.2, 0.04, 2.5, Abscissa::Ndof)))), Outcome::Pass, "falling");
        assert_eq!(g.judge(Some(&Evidence::Fit(fit(0.0, 0.04, 2.5, Abscissa::Ndof)))), Outcome::Pass);
        assert_eq!(g.judge(Some(&Evidence::Fit(fit(0.0, 0.04, 1.5, Abscissa::Ndof)))), Outcome::Open, "a short window");
    }

    #[test]
    fn parts_fail_when_one_fails() {
        let each = Criterion::Each { of: vec!["a".into(), "b".into()], each: Box::new(Criterion::rate("the term", 1.5, Abscissa::Ndof)) };
        let e = |s: f64| Some(Evidence::Fit(fit(s, 0.02, 2.5, Abscissa::Ndof)));
        assert_eq!(each.verdict(Kind::Paper, Some(&Evidence::All(vec![e(1.5), e(1.0)]))), Verdict::NotReproduced);
        assert_eq!(each.verdict(Kind::Paper, Some(&Evidence::All(vec![e(1.5), e(1.5)]))), Verdict::Reproduced);
        assert_eq!(each.verdict(Kind::Paper, Some(&Evidence::All(vec![e(1.5), None]))), Verdict::Inconclusive);
        assert_eq!(each.verdict(Kind::Paper, Some(&Evidence::All(vec![None, None]))), Verdict::NoData);
        assert!(each.fails_if().starts_with("for each of a, b: fails if"), "{}", each.fails_if());
        assert_eq!(combine(&[Outcome::NotApplicable, Outcome::Pass]), Outcome::Pass);
        assert_eq!(combine(&[Outcome::NotApplicable]), Outcome::NotApplicable);
    }
}
