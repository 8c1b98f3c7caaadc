//! The rows every problem shares, one builder per kind of claim ([`RowKind`]): a rate, the
//! efficiency index, refinement at the free boundary, and the efficiency up to l_h over every
//! problem. Each builder applies its kind's one criterion to the run of one contact term
//! ([`TermRun`]); the problem modules only choose which rows a problem has and what the paper says.

use super::terms::{self, TermRun};
use super::{
    Claim, Criterion, Ctx, Evidence, Kind, OPTIMAL, Q, REFERENCE_SHARE, RowKind, Summary, UNIFORM_H_RATE, fragility, growth_headline,
    growth_text, rate_headline, rate_text, slowest_headline, source,
};
use crate::analysis::problem_names;
use crate::analysis::roles::{self, Role};
use crate::analysis::verdict::{self, Abscissa, RateReport};
use std::collections::BTreeMap;
use store::records::RunRecord;

/// A problem's runs per contact term (eta_5 as written, without full-contact nodes, repaired)
/// and its uniform run, each in the study that runs it deepest, with the smaller study's run
/// where that one is not stored.
pub(super) struct Problem {
    pub name: &'static str,
    pub terms: [Option<Role>; 3],
    pub fallback: [Option<Role>; 3],
    pub uniform: Option<Role>,
    pub uniform_fallback: Option<Role>,
}

/// Every problem whose rows are judged per contact term.
pub(super) const PROBLEMS: [Problem; 5] = {
    use roles::*;
    [
        Problem {
            name: problem_names::EX71,
            terms: [Some(DEEP_EX71_AS_WRITTEN), Some(DEEP_EX71_WFC), Some(DEEP_EX71_REPAIRED)],
            fallback: [Some(EX71_AS_WRITTEN), Some(ABLATION_EX71_WFC), Some(REPAIR_EX71)],
            uniform: Some(DEEP_EX71_UNIFORM),
            uniform_fallback: Some(EX71_UNIFORM),
        },
        Problem {
            name: problem_names::EX72,
            terms: [Some(LARGE_AS_WRITTEN), Some(LARGE_WFC), Some(LARGE_REPAIRED)],
            fallback: [Some(EX72_AS_WRITTEN), Some(ABLATION_EX72_WFC), Some(REPAIR_EX72)],
            uniform: Some(LARGE_UNIFORM),
            uniform_fallback: Some(EX72_UNIFORM),
        },
        Problem {
            name: problem_names::EX72_ROLLERS,
            terms: [Some(ROLLERS_AS_WRITTEN), Some(ROLLERS_WFC), Some(ROLLERS_REPAIRED)],
            fallback: [None, None, None],
            uniform: Some(ROLLERS_UNIFORM),
            uniform_fallback: None,
        },
        Problem {
            name: problem_names::FB,
            terms: [Some(DEEP_FB_AS_WRITTEN), Some(DEEP_FB_WFC), Some(DEEP_FB_REPAIRED)],
            fallback: [Some(FB_AS_WRITTEN), Some(FB_WFC), Some(REPAIR_FB)],
            uniform: Some(DEEP_FB_UNIFORM),
            uniform_fallback: Some(FB_UNIFORM),
        },
        Problem {
            name: problem_names::HERTZ,
            terms: [Some(HERTZ_AS_WRITTEN), None, Some(HERTZ_REPAIRED)],
            fallback: [None, None, Some(REPAIR_HERTZ)],
            uniform: None,
            uniform_fallback: None,
        },
    ]
};

/// The problem of [`PROBLEMS`] named `name`.
pub(super) fn problem(name: &str) -> &'static Problem {
    PROBLEMS.iter().find(|p| p.name == name).expect("a problem of PROBLEMS")
}

/// The records of the studies the rows read, each study read once.
#[derive(Default)]
pub(super) struct Loaded {
    by_study: BTreeMap<&'static str, Vec<RunRecord>>,
}

impl Loaded {
    /// The studies of `problems`' roles, read from the shelf.
    pub fn read(ctx: &Ctx, problems: &[&Problem]) -> std::io::Result<Loaded> {
        let mut by_study = BTreeMap::new();
        for p in problems {
            for role in p.terms.iter().chain(&p.fallback).chain([&p.uniform, &p.uniform_fallback]).flatten() {
                if !by_study.contains_key(role.study) {
                    by_study.insert(role.study, ctx.shelf.runs(role.study)?);
                }
            }
        }
        Ok(Loaded { by_study })
    }

    /// The run of `role`, else of `fallback` (in the dense pass its twin, [`Ctx::pick`]).
    fn find<'a>(&'a self, ctx: &Ctx, role: Option<Role>, fallback: Option<Role>) -> Option<&'a RunRecord> {
        let get = |r: Role| self.by_study.get(r.study).map(Vec::as_slice).unwrap_or(&[]);
        role.and_then(|r| ctx.find(get(r), r)).or_else(|| fallback.and_then(|r| ctx.pick(get(r), r)))
    }

    /// `p`'s runs per contact term ([`terms::per_term`]).
    pub fn per_term<'a>(&'a self, ctx: &Ctx, p: &Problem) -> Vec<TermRun<'a>> {
        let run = |k: usize| self.find(ctx, p.terms[k], p.fallback[k]);
        terms::per_term(ctx, run(0), run(1), run(2))
    }

    /// `p`'s uniform run.
    pub fn uniform<'a>(&'a self, ctx: &Ctx, p: &Problem) -> Option<&'a RunRecord> {
        self.find(ctx, p.uniform, p.uniform_fallback)
    }
}

/// Whose rows a block is: the id prefix ("7.1"), the problem in words, and whose claims they are.
pub(super) struct Subject {
    pub prefix: &'static str,
    pub kind: Kind,
}

/// One row's words: its id's stem ("error-rate"), the topic, what the paper says, the claim, and
/// what the row's measured text adds after the criterion's evidence (other runs for comparison).
pub(super) struct Words {
    pub slug: &'static str,
    pub topic: &'static str,
    pub paper: &'static str,
    pub claim: String,
    pub extra: String,
}

/// The claim of a refinement row carried to `problem` ("Ex. 7.2 on rollers"): Fig. 3b's.
pub(super) fn refinement_claim(problem: &str) -> String {
    format!(
        "{problem}: the adaptive mesh is refined around the free boundary (Fig. 3b): the length h_fb of the contact edge straddling a free-boundary point decays faster than NDF^(-1/2) (what uniform refinement gives) beyond its interval"
    )
}

/// The claim of an efficiency row carried to `problem` ("fb"): 7.1-efficiency's.
pub(super) fn efficiency_claim(problem: &str) -> String {
    format!("{problem}: the efficiency index estimate / error stays bounded (the rule of 7.1-efficiency)")
}

/// The row's id and topic for term run `t`: "7.1-error-rate (without full-contact nodes = repaired)".
fn labels(s: &Subject, t: &TermRun, w: &Words) -> (String, String) {
    (format!("{}-{}{}", s.prefix, w.slug, t.suffix()), format!("{}{}", w.topic, t.suffix()))
}

/// A claim of `s` for term run `t`, with its criterion judging `evidence`.
#[allow(clippy::too_many_arguments)]
fn row(
    s: &Subject,
    t: &TermRun,
    w: Words,
    headline: String,
    measured: String,
    criterion: Criterion,
    evidence: Option<Evidence>,
    kind: RowKind,
    fragile: Option<String>,
) -> Claim {
    let (id, topic) = labels(s, t, &w);
    let claim = format!("{} (contact term: {})", w.claim, t.names());
    Claim {
        verdict: criterion.verdict(s.kind, t.run.and(evidence).as_ref()),
        id,
        summary: Summary { topic, paper: w.paper, headline },
        claim,
        measured: if t.run.is_none() { "no data".into() } else { format!("{measured}{}{}", w.extra, t.note_text()) },
        criterion,
        kind: s.kind,
        row: kind,
        terms: t.terms.clone(),
        fragile,
    }
}

/// A rate criterion on `what`, with the reference check where `r`'s errors are against a
/// reference solution (over `rep`'s window), and its evidence and text.
fn with_reference(
    ctx: &Ctx,
    r: Option<&RunRecord>,
    rate: Criterion,
    rep: Option<&RateReport>,
    of_error: bool,
) -> (Criterion, Option<Evidence>, String) {
    let fit = Evidence::rate(rep);
    let check = match (r, rep, of_error) {
        (Some(r), Some(rep), true) => ctx.reference_check(r, rep.main.first_level, rep.main.last_level),
        _ => None,
    };
    match check {
        None => (rate, fit, String::new()),
        Some((ratio, text)) => (
            Criterion::All(vec![rate, Criterion::Reference { share: REFERENCE_SHARE }]),
            fit.map(|f| Evidence::All(vec![Some(f), Some(Evidence::Value(ratio))])),
            format!("; {text}"),
        ),
    }
}

/// A rate row: the error `q` (the error, or an `err_*` field) of term run `t` at NDF^-1.5.
pub(super) fn error_rate(ctx: &Ctx, s: &Subject, t: &TermRun, q: Q, what: &str, w: Words) -> Claim {
    let r = t.run;
    let rep = ctx.rate(r, q);
    let (test, evidence, reference) =
        with_reference(ctx, r, Criterion::rate(format!("{what} ({})", source(r)), OPTIMAL, Abscissa::Ndof), rep.as_ref(), true);
    let measured = r.map(|r| {
        format!("{}; {}{reference}", rate_text(&format!("{what} ({})", source(Some(r))), rep.as_ref(), Some(OPTIMAL)), ctx.floor_text(r))
    });
    row(
        s,
        t,
        w,
        rate_headline("", rep.as_ref(), r),
        measured.unwrap_or_default(),
        test,
        evidence,
        RowKind::Rate,
        fragility(rep.as_ref(), OPTIMAL),
    )
}

/// A rate row on estimator quantities `names` (eta_h, eta1, ...) of term run `t`, each at
/// NDF^-1.5; with eta_h, Psi and the log factor's share beside it.
pub(super) fn estimator_rates(ctx: &Ctx, s: &Subject, t: &TermRun, names: &[&str], w: Words) -> Claim {
    let r = t.run;
    let reps: Vec<Option<RateReport>> = names.iter().map(|n| ctx.rate(r, Q::Field(n))).collect();
    let what = |n: &str| format!("{n} ({})", source(r));
    let (test, evidence) = match names {
        [one] => (Criterion::rate(what(one), OPTIMAL, Abscissa::Ndof), Evidence::rate(reps[0].as_ref())),
        _ => (
            Criterion::Each {
                of: names.iter().map(|n| n.to_string()).collect(),
                each: Box::new(Criterion::rate(format!("the term ({})", source(r)), OPTIMAL, Abscissa::Ndof)),
            },
            Some(Evidence::All(reps.iter().map(|x| Evidence::rate(x.as_ref())).collect())),
        ),
    };
    let fragile: Vec<String> =
        names.iter().zip(&reps).filter_map(|(n, x)| fragility(x.as_ref(), OPTIMAL).map(|f| format!("{n}: {f}"))).collect();
    let terms_only: Vec<&str> = names.iter().copied().filter(|n| *n != "eta_h").collect();
    let headline = match (names.contains(&"eta_h"), terms_only.is_empty()) {
        (true, true) => rate_headline("eta_h ", reps[0].as_ref(), r),
        (true, false) => format!("{}; {}", rate_headline("eta_h ", reps[0].as_ref(), r), slowest_headline(ctx, r, &terms_only)),
        (false, _) => slowest_headline(ctx, r, &terms_only),
    };
    let measured = format!(
        "{}: {}; {}",
        source(r),
        names.iter().zip(&reps).map(|(n, x)| rate_text(n, x.as_ref(), Some(OPTIMAL))).collect::<Vec<_>>().join("; "),
        super::estimator_text(ctx, r)
    );
    row(s, t, w, headline, measured, test, evidence, RowKind::Rate, (!fragile.is_empty()).then(|| fragile.join("; ")))
}

/// The efficiency row of term run `t`: the trend of estimate / error bounded (two-sided), with
/// the trends up to l_h and with l_h = 1 beside it.
pub(super) fn efficiency(ctx: &Ctx, s: &Subject, t: &TermRun, w: Words) -> Claim {
    let r = t.run;
    let g = ctx.growth(r, Q::Efficiency);
    let bounded = Criterion::Bounded { what: format!("estimate / error ({})", source(r)) };
    let reference = match (r, g.as_ref()) {
        (Some(r), Some(g)) => ctx.reference_check(r, g.first_level, g.last_level),
        _ => None,
    };
    let (test, evidence) = match &reference {
        Some((ratio, _)) => (
            Criterion::All(vec![bounded, Criterion::Reference { share: REFERENCE_SHARE }]),
            Evidence::fit(g.as_ref()).map(|f| Evidence::All(vec![Some(f), Some(Evidence::Value(*ratio))])),
        ),
        None => (bounded, Evidence::fit(g.as_ref())),
    };
    let measured = format!(
        "{}: {}; {}; {}{}",
        source(r),
        growth_text("estimate / error", g.as_ref()),
        growth_text("estimate / error / l_h", ctx.growth(r, Q::EfficiencyOverLh).as_ref()),
        growth_text("with l_h = 1, C_0 (Psi + eta_6 + eta_7) / error", ctx.growth(r, Q::EfficiencyL1).as_ref()),
        reference.map(|(_, t)| format!("; {t}")).unwrap_or_default()
    );
    row(s, t, w, growth_headline("log efficiency: ", g.as_ref(), r), measured, test, evidence, RowKind::Efficiency, None)
}

/// The refinement row of term run `t`: the contact edge straddling a free-boundary point (its
/// length h_fb) shrinks faster than uniform refinement's NDF^(-1/2), beyond its interval.
pub(super) fn refinement(ctx: &Ctx, s: &Subject, t: &TermRun, w: Words) -> Claim {
    let r = t.run;
    let rep = ctx.rate(r, Q::Field("h_free_boundary"));
    let last = r.and_then(|r| r.levels.iter().rev().find_map(|l| l.h_free_boundary.map(|h| (h, l.h_min, l.ndof))));
    let test = Criterion::FasterThan { what: format!("h_fb ({})", source(r)), than: UNIFORM_H_RATE, abscissa: Abscissa::Ndof };
    let measured = format!(
        "{}: {}{}",
        source(r),
        rate_text("h_fb decay", rep.as_ref(), Some(UNIFORM_H_RATE)),
        last.map(|(h, hmin, n)| format!("; last level: h_fb {h:.1e}, h_min {hmin:.1e} (NDF {n})")).unwrap_or_default()
    );
    let evidence = Evidence::rate(rep.as_ref());
    row(
        s,
        t,
        w,
        rate_headline("h_fb ", rep.as_ref(), r),
        measured,
        test,
        evidence,
        RowKind::Refinement,
        fragility(rep.as_ref(), UNIFORM_H_RATE),
    )
}

/// The efficiency up to the log factor, one row over every problem and contact term: the trend
/// of estimate / error / l_h bounded (two-sided) on each run (Section 6's efficiency, eq. 6.3,
/// carried to the measurement; beyond Section 7's claims).
pub(super) fn efficiency_up_to_lh(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let all: Vec<&Problem> = PROBLEMS.iter().collect();
    let loaded = Loaded::read(ctx, &all)?;
    let (mut of, mut evidence, mut texts) = (Vec::new(), Vec::new(), Vec::new());
    for p in &all {
        for t in loaded.per_term(ctx, p) {
            let Some(r) = t.run else { continue };
            if ctx.values(r, Q::Error).iter().all(Option::is_none) {
                continue;
            }
            let g = ctx.growth(Some(r), Q::EfficiencyOverLh);
            let check = g.as_ref().and_then(|g| ctx.reference_check(r, g.first_level, g.last_level));
            let name =
                format!("{} ({}{})", problem_names::label(p.name), t.names(), if t.terms.len() > 1 { ", runs coincide" } else { "" });
            texts.push(format!(
                "{name}, {}: {}{}",
                source(Some(r)),
                growth_text("estimate / error / l_h", g.as_ref()),
                check.as_ref().map(|c| format!("; {}", c.1)).unwrap_or_default()
            ));
            evidence.push(match check {
                Some((ratio, _)) => g.map(|g| Evidence::All(vec![Some(Evidence::Fit(g)), Some(Evidence::Value(ratio))])),
                // an exact solution: no reference error
                None => g.map(|g| Evidence::All(vec![Some(Evidence::Fit(g)), Some(Evidence::Value(0.0))])),
            });
            of.push(name);
        }
    }
    let test = Criterion::Each {
        of: of.clone(),
        each: Box::new(Criterion::All(vec![
            Criterion::Bounded { what: "estimate / error / l_h (each run)".into() },
            Criterion::Reference { share: REFERENCE_SHARE },
        ])),
    };
    let n_bounded = evidence
        .iter()
        .filter(|e| {
            matches!(e, Some(Evidence::All(parts)) if matches!(&parts[0], Some(Evidence::Fit(f)) if verdict::judge_trend(f) == verdict::Trend::Bounded))
        })
        .count();
    out.push(Claim {
        fragile: None,
        id: "efficiency-up-to-l_h (beyond the paper)".into(),
        summary: Summary {
            topic: "Efficiency up to the log factor l_h".into(),
            paper: "efficient up to l_h (eq. 6.3); Section 7 does not test it",
            headline: if of.is_empty() { "n/a".into() } else { format!("estimate / error / l_h bounded on {n_bounded} of {} runs", of.len()) },
        },
        claim: "Section 6's efficiency carried to the measurement: the efficiency index up to the log factor, estimate / error / l_h, stays bounded (the same two-sided rule as the efficiency rows), on every problem and contact term with an error".into(),
        measured: if texts.is_empty() { "no data".into() } else { texts.join("; ") },
        verdict: test.verdict(Kind::Beyond, (!of.is_empty()).then_some(Evidence::All(evidence)).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
        row: RowKind::EfficiencyUpToLh,
        terms: vec![],
    });
    Ok(())
}
