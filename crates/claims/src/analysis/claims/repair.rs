//! The `estimator-repair` row: the repaired contact terms (`estimate::repair`, study
//! `estimator_repair`) judged per problem against four criteria, each with its own verdict:
//!
//! 1. error rate: the 95% interval of the adaptive error rate lies inside 1.5 ± 0.1 (the rule of
//!    [`verdict::judge_rate`]: no wider than 0.2, so within the 0.3 the issue allows);
//! 2. efficiency up to l_h: the trend of estimate / error / l_h is bounded ([`verdict::judge_trend`]),
//!    the rule of the row `efficiency-up-to-l_h`;
//! 3. reliability: C_0 = [`C0_PAPER`] gives estimate >= error over the error-rate fit window, the
//!    rule of the rows c0;
//! 4. unknowns: fewer unknowns than uniform refinement for the same error (`unknowns`), decided
//!    from the fitted error lines only where uniform refinement is slower than the claimed rate;
//!    not applied to a problem without a uniform run (Hertz), and the row says so.
//!
//! Each criterion is applied to eta_5 as written too: a criterion both variants pass is said to
//! be no evidence for the repair, and the verdict holds only if some criterion separates them.
//! The repaired runs are compared with the runs without full-contact nodes (`coincidence`).
//!
//! Example 7.1 and fb are judged on the deep study's runs (`deep/{ex71,fb}_repaired` and their
//! uniform companions, to at least 1e7 NDF), Example 7.2 on `ex72_large/repaired` (to 1e6, errors
//! against the 4e6 reference) and Hertz on `hertz/repaired` (errors against the study's reference)
//! where they are stored; otherwise on the runs of `estimator_repair`.

use super::criterion::Outcome;
use super::terms::{coincidence, coincidence_text};
use super::{
    Claim, Criterion, Ctx, Evidence, Kind, OPTIMAL, Q, REFERENCE_SHARE, RowKind, Summary, growth_text, rate_text, reliability_criterion,
    short_range, source,
};
use crate::analysis::roles::{self, Role, Roles};
use crate::analysis::verdict::{self, Abscissa};
use crate::analysis::{problem_names, studies};
use model::base::stats::line_value_at;
use model::settings::estimator::c0_paper;
use store::records::RunRecord;

/// (ln NDF, ln error) at the levels of `r`'s error-rate fit (every other level of its window).
fn fit_points(ctx: &Ctx, r: &RunRecord) -> Option<Vec<(f64, f64)>> {
    let rep = ctx.rate(Some(r), Q::Error)?;
    let fitted = ctx.fitted(r, Q::Error);
    let err = ctx.values(&fitted, Q::Error);
    let pts: Vec<(f64, f64)> = (rep.main.first_level..=rep.main.last_level)
        .step_by(2)
        .filter_map(|l| Some(((fitted.levels.get(l)?.ndof as f64).ln(), err.get(l).copied().flatten()?.ln())))
        .collect();
    (pts.len() >= 3).then_some(pts)
}

/// Fewer unknowns than uniform refinement for the same error, decided where it can be: only
/// where uniform refinement is slower than the claimed adaptive rate beyond its band (its
/// NDF-rate interval below 1.5 - 0.1; elsewhere uniform attains the rate and the criterion is
/// not applicable), from the fitted lines of ln error against ln NDF of both runs at the end of
/// their common window (at least a decade of NDF, no extrapolation): the adaptive error's 95%
/// interval below the uniform one's holds, above fails, overlapping is not decided. The decision
/// is [`Criterion::FewerUnknowns`]'s on the evidence returned (None: no uniform error rate).
pub(super) fn unknowns(ctx: &Ctx, ad: &RunRecord, un: &RunRecord) -> (String, Option<Evidence>) {
    let Some(ur) = ctx.rate(Some(un), Q::Error) else { return (format!("{}: no error rate", source(Some(un))), None) };
    let scale = ur.main.claim_in_abscissa(OPTIMAL).0 / OPTIMAL; // 2 for a fit in h_min
    let (rate, half, hi) = (ur.main.rate.slope / scale, ur.main.rate.half_width / scale, ur.main.rate.hi() / scale);
    let uniform = format!("uniform refinement's error at NDF^-({rate:.3} ± {half:.3}) ({}, {})", short_range(&ur.main), source(Some(un)));
    let needed = OPTIMAL - verdict::RATE_BAND;
    let test = Criterion::FewerUnknowns { claim: OPTIMAL };
    let open = Some(Evidence::Unknowns { uniform_rate_hi: hi, lines: None });
    if test.judge(open.as_ref()) == Outcome::NotApplicable {
        return (
            format!(
                "unknowns for the same error: not applicable, {uniform} reaches the claimed rate's band (its interval up to {hi:.3} >= {needed}): adaptive refinement cannot be faster than claimed, so equal unknowns is all it can show"
            ),
            open,
        );
    }
    let (Some(pa), Some(pu)) = (fit_points(ctx, ad), fit_points(ctx, un)) else {
        return (format!("unknowns for the same error: not decided, no fitted error lines; {uniform}"), open);
    };
    let (lo_x, hi_x) = (pa[0].0.max(pu[0].0), pa[pa.len() - 1].0.min(pu[pu.len() - 1].0));
    if hi_x - lo_x < std::f64::consts::LN_10 {
        return (
            format!(
                "unknowns for the same error: not decided, the fit windows share less than a decade of NDF ({:.1e}–{:.1e}); {uniform}",
                lo_x.exp(),
                hi_x.exp()
            ),
            open,
        );
    }
    let (Some((ya, wa)), Some((yu, wu))) = (line_value_at(&pa, hi_x), line_value_at(&pu, hi_x)) else {
        return (format!("unknowns for the same error: not decided, too few levels; {uniform}"), open);
    };
    let evidence = Some(Evidence::Unknowns { uniform_rate_hi: hi, lines: Some(((ya, wa), (yu, wu))) });
    let outcome = test.judge(evidence.as_ref());
    let interval = |y: f64, w: f64| format!("{:.2e} [{:.2e}, {:.2e}]", y.exp(), (y - w).exp(), (y + w).exp());
    (
        format!(
            "unknowns for the same error: at NDF {:.1e}, the end of the fits' common window ({:.1e}–{:.1e}), the fitted adaptive error {} against uniform {} (95% intervals of the fitted lines) → {}; {uniform}",
            hi_x.exp(),
            lo_x.exp(),
            hi_x.exp(),
            interval(ya, wa),
            interval(yu, wu),
            match outcome {
                Outcome::Pass => "adaptive needs fewer unknowns",
                o if o.failed() => "adaptive needs more unknowns",
                _ => "not told apart",
            }
        ),
        evidence,
    )
}

/// The criteria of one problem, each applied to its adaptive run: (1) the error rate, (2) the
/// efficiency up to l_h bounded, (3) C_0 = [`C0_PAPER`] reliable over the fit window, (4) with a
/// uniform run, fewer unknowns than uniform refinement.
fn criteria_parts(with_uniform: bool) -> Vec<Criterion> {
    let mut parts = vec![
        Criterion::rate("the adaptive run's error", OPTIMAL, Abscissa::Ndof),
        Criterion::Reference { share: REFERENCE_SHARE },
        Criterion::Bounded { what: "estimate / error / l_h (the efficiency up to l_h)".into() },
        reliability_criterion("the run"),
    ];
    if with_uniform {
        parts.push(Criterion::FewerUnknowns { claim: OPTIMAL });
    }
    parts
}

/// The evidence of the criteria ([`criteria_parts`]) for one adaptive run, with their texts and
/// outcomes; the unknowns criterion only with a uniform run `un`.
fn criteria(ctx: &Ctx, ad: Option<&RunRecord>, un: Option<&RunRecord>) -> (Vec<String>, Vec<Option<Evidence>>, Vec<Outcome>) {
    let (mut texts, mut evidence) = (Vec::new(), Vec::new());
    let rate = ctx.rate(ad, Q::Error);
    texts.push(rate_text(&format!("error rate ({})", source(ad)), rate.as_ref(), Some(OPTIMAL)));
    evidence.push(Evidence::rate(rate.as_ref()));
    // the reference's own error against the errors the rate fits (an exact solution: none)
    let check = ad.zip(rate.as_ref()).and_then(|(r, rep)| ctx.reference_check(r, rep.main.first_level, rep.main.last_level));
    texts.push(check.as_ref().map_or("exact solution: no reference".into(), |c| c.1.clone()));
    evidence.push(Some(Evidence::Value(check.map_or(0.0, |c| c.0))));
    let g = ctx.growth(ad, Q::EfficiencyOverLh);
    texts.push(format!(
        "{}; {}",
        growth_text("efficiency up to l_h", g.as_ref()),
        growth_text("efficiency with l_h = 1", ctx.growth(ad, Q::EfficiencyL1).as_ref())
    ));
    evidence.push(Evidence::fit(g.as_ref()));
    let rel = ad.and_then(|r| ctx.reliability(r));
    texts.push(match (ad, rel) {
        (Some(r), Some(rel)) => rel.text(&source(Some(r))),
        _ => "reliability: no error-rate fit".into(),
    });
    evidence.push(rel.map(|r| Evidence::Value(r.c0)));
    if let (Some(a), Some(u)) = (ad, un) {
        let (t, e) = unknowns(ctx, a, u);
        texts.push(t);
        evidence.push(e);
    } else {
        texts.push("unknowns for the same error: not applied, no uniform run of this problem".into());
    }
    let oks = criteria_parts(un.is_some()).iter().zip(&evidence).map(|(c, e)| c.judge(e.as_ref())).collect();
    (texts, evidence, oks)
}

/// The problems of the row, in its order.
pub const PROBLEMS: [&str; 4] = [problem_names::EX71, problem_names::FB, problem_names::EX72, problem_names::HERTZ];

/// The runs the row reads for one problem (the figure `estimator_repair` draws the same).
#[derive(Clone, Copy, Debug)]
pub struct Fitted<'a> {
    pub problem: &'static str,
    /// The repaired estimator's adaptive run: every criterion is judged on it.
    pub repaired: Option<&'a RunRecord>,
    /// eta_5 as written on the same problem: each criterion applied to it too.
    pub as_written: Option<&'a RunRecord>,
    /// Without full-contact nodes: compared level by level with the repaired run.
    pub without_full_contact: Option<&'a RunRecord>,
    /// Uniform refinement: the unknowns criterion.
    pub uniform: Option<&'a RunRecord>,
    /// The repaired estimator with l_h = 1: its reliability.
    pub l1: Option<&'a RunRecord>,
}

/// The studies the row reads: `estimator_repair`, `deep`, `ex72_large` and `hertz`, with the
/// roles their runs declare.
pub struct Stored {
    pub estimator_repair: Vec<RunRecord>,
    pub deep: Vec<RunRecord>,
    pub ex72_large: Vec<RunRecord>,
    pub hertz: Vec<RunRecord>,
    roles: Roles,
}

/// The roles one problem's runs are found by: in the deep study (`deep`, `ex72_large` or
/// `hertz`) and in `estimator_repair` (`small_*`), each where the problem has one.
struct ProblemRoles {
    repaired: Role,
    as_written: Role,
    without_full_contact: Option<Role>,
    uniform: Option<Role>,
    small_repaired: Role,
    small_l1: Option<Role>,
    small_uniform: Option<Role>,
}

/// The roles of `problem` (one of [`PROBLEMS`]).
fn problem_roles(problem: &str) -> ProblemRoles {
    use roles::*;
    match problem {
        problem_names::EX72 => ProblemRoles {
            repaired: LARGE_REPAIRED,
            as_written: LARGE_AS_WRITTEN,
            without_full_contact: Some(LARGE_WFC),
            uniform: Some(LARGE_UNIFORM),
            small_repaired: REPAIR_EX72,
            small_l1: None,
            small_uniform: None,
        },
        problem_names::HERTZ => ProblemRoles {
            repaired: HERTZ_REPAIRED,
            as_written: HERTZ_AS_WRITTEN,
            without_full_contact: None,
            uniform: None,
            small_repaired: REPAIR_HERTZ,
            small_l1: None,
            small_uniform: None,
        },
        problem_names::FB => ProblemRoles {
            repaired: DEEP_FB_REPAIRED,
            as_written: DEEP_FB_AS_WRITTEN,
            without_full_contact: Some(DEEP_FB_WFC),
            uniform: Some(DEEP_FB_UNIFORM),
            small_repaired: REPAIR_FB,
            small_l1: Some(REPAIR_FB_L1),
            small_uniform: Some(REPAIR_FB_UNIFORM),
        },
        _ => ProblemRoles {
            repaired: DEEP_EX71_REPAIRED,
            as_written: DEEP_EX71_AS_WRITTEN,
            without_full_contact: Some(DEEP_EX71_WFC),
            uniform: Some(DEEP_EX71_UNIFORM),
            small_repaired: REPAIR_EX71,
            small_l1: Some(REPAIR_EX71_L1),
            small_uniform: Some(REPAIR_EX71_UNIFORM),
        },
    }
}

impl Stored {
    pub fn read(shelf: &store::study::store::Shelf, roles: &Roles) -> std::io::Result<Stored> {
        let load = |s: &str| shelf.runs(s);
        Ok(Stored {
            estimator_repair: load(studies::ESTIMATOR_REPAIR)?,
            deep: load(studies::DEEP)?,
            ex72_large: load(studies::EX72_LARGE)?,
            hertz: load(studies::HERTZ)?,
            roles: roles.clone(),
        })
    }

    /// The stored runs of `role`'s study.
    fn runs_of(&self, role: Role) -> &[RunRecord] {
        match role.study {
            studies::ESTIMATOR_REPAIR => &self.estimator_repair,
            studies::DEEP => &self.deep,
            studies::EX72_LARGE => &self.ex72_large,
            studies::HERTZ => &self.hertz,
            _ => &[],
        }
    }

    /// The run of `role` ([`Roles::find`]); none for no role.
    fn find(&self, role: Option<Role>) -> Option<&RunRecord> {
        role.and_then(|role| self.roles.find(self.runs_of(role), role))
    }

    /// The runs of `problem`: Examples 7.1 and fb from `deep`, 7.2 from `ex72_large`, where
    /// stored, Hertz from `hertz` (its repaired run; eta_5 as written: its adaptive run); else
    /// those of `estimator_repair`.
    pub fn fitted(&self, problem: &'static str) -> Fitted<'_> {
        let p = problem_roles(problem);
        Fitted {
            problem,
            repaired: self.find(Some(p.repaired)).or(self.find(Some(p.small_repaired))),
            as_written: self.find(Some(p.as_written)),
            without_full_contact: self.find(p.without_full_contact),
            uniform: self.find(p.uniform).or(self.find(p.small_uniform)),
            l1: self.find(p.small_l1),
        }
    }
}

pub(super) fn estimator_repair_claim(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let stored = Stored::read(ctx.shelf, ctx.roles)?;
    let names = ["error rate", "reference", "efficiency", "reliability", "unknowns"];
    let (mut parts, mut headline) = (Vec::new(), Vec::new());
    let (mut judged_problems, mut per_problem, mut separating) = (Vec::new(), Vec::new(), 0usize);
    let (mut coinciding, mut compared) = (0usize, 0usize);
    for problem in PROBLEMS {
        let f = stored.fitted(problem);
        let (ad, aw, wfc, un) = (f.repaired, f.as_written, f.without_full_contact, f.uniform);
        let Some(a) = ad else { continue };
        if ctx.values(a, Q::Error).iter().all(Option::is_none) {
            parts.push(format!("{problem} ({}): not judged, no error measured (no exact or reference solution)", source(ad)));
            headline.push(format!("{problem}: not judged (no error)"));
            continue;
        }
        let (texts, evidence, oks) = criteria(ctx, ad, un);
        // the same criteria for eta_5 as written: a criterion both pass does not separate them
        let written = aw.map(|w| criteria(ctx, Some(w), un).2);
        let judged: Vec<String> = names[..oks.len()]
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let also = match (oks[i], written.as_ref().map(|w| w[i])) {
                    (Outcome::Pass, Some(Outcome::Pass)) => " (holds for eta_5 as written too: does not separate the variants)",
                    (Outcome::Pass, Some(_)) => {
                        separating += 1;
                        " (eta_5 as written does not pass it: separates)"
                    }
                    _ => "",
                };
                format!("{n} {}{also}", oks[i].text())
            })
            .collect();
        let same = wfc.map(|w| (coincidence(a, &ctx.values(a, Q::Error), w, &ctx.values(w, Q::Error)), w));
        coinciding += usize::from(same.is_some_and(|(c, _)| c.parts_at.is_none()));
        compared += usize::from(same.is_some());
        let same = same.map(|(c, w)| format!("; {}", coincidence_text(a, w, c))).unwrap_or_default();
        parts.push(format!("{problem}: {} [{}]{same}", texts.join("; "), judged.join(", ")));
        let failed: Vec<&str> = names.iter().zip(&oks).filter(|(_, o)| o.failed()).map(|(n, _)| *n).collect();
        let open: Vec<&str> =
            names.iter().zip(&oks).filter(|(_, o)| matches!(o, Outcome::Open | Outcome::NoData)).map(|(n, _)| *n).collect();
        headline.push(match (failed.is_empty(), open.is_empty()) {
            (false, _) => format!("{problem}: fails {}", failed.join(", ")),
            (true, false) => format!("{problem}: not decided {}", open.join(", ")),
            (true, true) => format!("{problem}: every applicable criterion holds"),
        });
        judged_problems.push((problem.to_string(), un.is_some()));
        per_problem.push(Some(Evidence::All(evidence)));
    }
    let test = Criterion::All(vec![
        Criterion::All(judged_problems.iter().map(|(_, uniform)| Criterion::All(criteria_parts(*uniform))).collect()),
        Criterion::Test {
            passes_if: "some criterion passes for the repair and not for eta_5 as written on the same problem (a criterion both pass is no evidence for the repair)".into(),
            open_if_not: true,
        },
    ]);
    let evidence =
        (!judged_problems.is_empty()).then(|| Evidence::All(vec![Some(Evidence::All(per_problem)), Some(Evidence::Bool(separating > 0))]));
    out.push(Claim {
        fragile: None,
        id: "estimator-repair (beyond the paper)".into(),
        summary: Summary {
            topic: "The repaired estimator".into(),
            paper: "beyond the paper: four criteria per problem (three without a uniform run)",
            headline: if headline.is_empty() { "n/a".into() } else { format!(
                "{}; {separating} criteria separate it from eta_5 as written; its runs coincide with those without full-contact nodes on {coinciding} of {compared} problems",
                headline.join("; ")
            ) },
        },
        claim: concat!("The repaired estimator (contact_term = \"tensile_on_full_contact\": only the tensile normal stress at full-contact nodes in eta_5, eta_7 on full-contact edges and the edges of isolated active nodes), per problem (Examples 7.1 and fb: study deep; 7.2: ex72_large; Hertz: study hertz, errors against its reference): (1) the adaptive error rate's interval inside 1.5 ± 0.1; (2) the efficiency up to l_h bounded (the rule of row efficiency-up-to-l_h); (3) C_0 = ", c0_paper!(), " reliable over the error-rate fit window (the rule of rows c0); (4) fewer unknowns than uniform refinement for the same error, from the fitted error lines at the end of their common window, only where uniform refinement is slower than the claimed rate beyond its band, and only on a problem with a uniform run (Hertz has none: not applied there). Each criterion is also applied to eta_5 as written: one that both pass is no evidence for the repair. The repaired runs are compared with the runs without full-contact nodes: where they coincide (same meshes, same errors), the evidence is that variant's; they would part only where the tensile normal stress at a full-contact node is the largest indicator. Holds when no criterion fails, none is undecided and at least one separates the repair from eta_5 as written").into(),
        measured: if parts.is_empty() { "no data".into() } else { parts.join(". ") },
        verdict: test.verdict(Kind::Beyond, evidence.as_ref()),
        criterion: test,
        kind: Kind::Beyond,
        row: RowKind::Finding,
        terms: vec![],
    });
    Ok(())
}
