//! The rows of Example 7.2 on rollers (study `ex72_rollers`, beyond the paper): the block, load
//! and wedge of Example 7.2 with the left side on rollers instead of clamped, so that the
//! corners which set 7.2's error are gone. Every Example 7.2 claim of the paper is judged on it
//! for each contact term (eta_5 as written, without full-contact nodes, repaired): the
//! estimator's rates (the row of [`super::ex72::rates`]), the true error's rate, refinement at
//! the free boundary and the efficiency; with the reference's own error (the row of
//! [`super::ex72::error`]) and the uniform rate that shows the corners gone.

use super::UNIFORM_H_RATE;
use super::ex72::{Errors, Labels, error, rates};
use super::{Claim, Criterion, Ctx, EX72_NU, Evidence, Kind, OPTIMAL, Q, Summary, c0_text, growth_text, rate_headline, rate_text, source};
use crate::analysis::roles::{self, Role};
use crate::analysis::verdict::{self, Abscissa, RateReport};
use crate::estimator::estimate::{C0_PAPER, c0_paper};
use crate::records::RunRecord;

/// The study.
const STUDY: &str = roles::ROLLERS_AS_WRITTEN.study;

/// One contact term: its run's role and its rows' labels (rates, error rate, refinement, efficiency).
struct Term {
    role: Role,
    name: &'static str,
    rows: [Labels; 4],
}

const TERMS: [Term; 3] = [
    Term {
        role: roles::ROLLERS_AS_WRITTEN,
        name: "eta_5 as written",
        rows: [
            Labels { id: "7.2r-rates (as written)", topic: "Ex. 7.2 on rollers, eta_5 as written: estimator rates" },
            Labels { id: "7.2r-error-rate (as written)", topic: "Ex. 7.2 on rollers, eta_5 as written: true error rate" },
            Labels { id: "7.2r-refinement (as written)", topic: "Ex. 7.2 on rollers, eta_5 as written: refinement at the free boundary" },
            Labels { id: "7.2r-efficiency (as written)", topic: "Ex. 7.2 on rollers, eta_5 as written: efficiency" },
        ],
    },
    Term {
        role: roles::ROLLERS_WFC,
        name: "without full-contact nodes",
        rows: [
            Labels {
                id: "7.2r-rates (without full-contact nodes)",
                topic: "Ex. 7.2 on rollers, without full-contact nodes: estimator rates",
            },
            Labels {
                id: "7.2r-error-rate (without full-contact nodes)",
                topic: "Ex. 7.2 on rollers, without full-contact nodes: true error rate",
            },
            Labels {
                id: "7.2r-refinement (without full-contact nodes)",
                topic: "Ex. 7.2 on rollers, without full-contact nodes: refinement at the free boundary",
            },
            Labels {
                id: "7.2r-efficiency (without full-contact nodes)",
                topic: "Ex. 7.2 on rollers, without full-contact nodes: efficiency",
            },
        ],
    },
    Term {
        role: roles::ROLLERS_REPAIRED,
        name: "repaired",
        rows: [
            Labels { id: "7.2r-rates (repaired)", topic: "Ex. 7.2 on rollers, repaired: estimator rates" },
            Labels { id: "7.2r-error-rate (repaired)", topic: "Ex. 7.2 on rollers, repaired: true error rate" },
            Labels { id: "7.2r-refinement (repaired)", topic: "Ex. 7.2 on rollers, repaired: refinement at the free boundary" },
            Labels { id: "7.2r-efficiency (repaired)", topic: "Ex. 7.2 on rollers, repaired: efficiency" },
        ],
    },
];

/// The rows of Example 7.2 on rollers: the reference and the uniform rate first, then each
/// contact term's four rows.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let runs = ctx.shelf.runs(STUDY)?;
    let errors = Errors {
        study: STUDY,
        adaptive: ctx.find(&runs, roles::ROLLERS_AS_WRITTEN),
        without_full_contact: ctx.find(&runs, roles::ROLLERS_WFC),
        uniform: ctx.find(&runs, roles::ROLLERS_UNIFORM),
    };
    let mut reference = error(
        ctx,
        &errors,
        errors.adaptive,
        errors.without_full_contact,
        Labels { id: "7.2r-error (beyond the paper)", topic: "Ex. 7.2 on rollers: true error and the reference's own" },
    );
    reference.claim = "Ex. 7.2 on rollers (beyond the paper): the true error against a finer reference solution, the reference's own error, the efficiency index, and whether eta_5 as written and without full-contact nodes still give the same error (on the clamped block the corners made them equal)".into();
    out.push(reference);
    out.push(uniform(ctx, errors.uniform));
    for term in &TERMS {
        let r = ctx.pick(&runs, term.role);
        out.push(rates(ctx, r, term.rows[0]));
        out.push(error_rate(ctx, r, term, term.rows[1]));
        out.push(refinement(ctx, r, term, term.rows[2]));
        out.push(efficiency(ctx, r, term, term.rows[3]));
    }
    Ok(())
}

/// Uniform refinement on rollers: its error rate in h_min against the clamped corners' exponent
/// (Example 7.2's h^0.711): the corners are gone if it is faster beyond its interval.
fn uniform(ctx: &Ctx, u: Option<&RunRecord>) -> Claim {
    let lambda = verdict::clamped_free_corner_exponent(EX72_NU);
    let rep = ctx.rate(u, Q::Error);
    // the fit is in h_min (uniform): the corners' NDF^-(lambda/2) is h^-lambda there
    let test = Criterion::FasterThan {
        what: format!("the uniform error ({})", source(u)),
        than: lambda / 2.0,
        abscissa: u.map_or(Abscissa::InverseHMin, verdict::abscissa_of),
    };
    Claim {
        fragile: None,
        id: "7.2r-uniform (beyond the paper)",
        summary: Summary {
            topic: "Ex. 7.2 on rollers: the corners are gone",
            paper: "not in the paper; clamped: h^0.711 (row 7.2-corners)",
            headline: rate_headline("uniform: ", rep.as_ref(), u),
        },
        claim: format!(
            "Ex. 7.2 on rollers: reflected across x = 0 the rollers side is an interior line, so the singularity of the clamped / traction-free corners (u ~ r^{lambda:.4}, uniform refinement h^{lambda:.4} = NDF^-{:.3}) is gone: uniform refinement converges faster than NDF^-{:.3} beyond its interval",
            lambda / 2.0,
            lambda / 2.0
        ),
        measured: rep
            .as_ref()
            .map(|r| format!("{}: {}", source(u), rate_text("uniform error rate", Some(r), Some(lambda / 2.0))))
            .unwrap_or_default(),
        verdict: test.verdict(Kind::Beyond, Evidence::rate(rep.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
    }
}

/// The true error's rate of one contact term against NDF^(-3/2), on Gamma_C and on x >= 1/2
/// beside it.
fn error_rate(ctx: &Ctx, r: Option<&RunRecord>, term: &Term, labels: Labels) -> Claim {
    let rep = ctx.rate(r, Q::Error);
    let beside: Vec<String> = [("on Gamma_C", "err_contact"), ("on x >= 1/2", "err_right_half")]
        .iter()
        .map(|(n, f)| rate_text(n, ctx.rate(r, Q::Field(f)).as_ref(), Some(OPTIMAL)))
        .collect();
    let test = Criterion::rate(format!("the true error ({})", source(r)), OPTIMAL, Abscissa::Ndof);
    Claim {
        fragile: super::fragility(rep.as_ref(), OPTIMAL),
        id: labels.id,
        summary: Summary {
            topic: labels.topic,
            paper: "optimal, NDF^-1.5 (carried over from 7.1)",
            headline: rate_headline("", rep.as_ref(), r),
        },
        claim: format!(
            "Ex. 7.2 on rollers, {}: the true error ||u - u_h||_Linf against the reference converges at the paper's optimal NDF^(-3/2), no longer masked by the corners",
            term.name
        ),
        measured: r
            .map(|r| {
                format!(
                    "{}: {}; {}; {}",
                    source(Some(r)),
                    rate_text("error rate", rep.as_ref(), Some(OPTIMAL)),
                    beside.join("; "),
                    ctx.floor_text(r)
                )
            })
            .unwrap_or_default(),
        verdict: test.verdict(Kind::Paper, r.and(Evidence::rate(rep.as_ref())).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// Refinement at the free boundary: the contact edge straddling a free-boundary point (its
/// length h_fb) shrinks faster than uniform refinement's NDF^(-1/2), beyond the interval.
fn refinement(ctx: &Ctx, r: Option<&RunRecord>, term: &Term, labels: Labels) -> Claim {
    let rep: Option<RateReport> = ctx.rate(r, Q::Field("h_free_boundary"));
    let last = r.and_then(|r| r.levels.iter().rev().find_map(|l| l.h_free_boundary.map(|h| (h, l.h_min, l.ndof))));
    let test = Criterion::FasterThan { what: format!("h_fb ({})", source(r)), than: UNIFORM_H_RATE, abscissa: Abscissa::Ndof };
    Claim {
        fragile: super::fragility(rep.as_ref(), UNIFORM_H_RATE),
        id: labels.id,
        summary: Summary {
            topic: labels.topic,
            paper: "refined around the free boundary (Fig. 3b)",
            headline: rate_headline("h_fb ", rep.as_ref(), r),
        },
        claim: format!(
            "Ex. 7.2 on rollers, {}: the adaptive mesh is refined around the free boundary (Fig. 3b): the length h_fb of the contact edge straddling a free-boundary point decays faster than NDF^(-1/2) (what uniform refinement gives) beyond its interval",
            term.name
        ),
        measured: r
            .map(|r| {
                format!(
                    "{}: {}{}",
                    source(Some(r)),
                    rate_text("h_fb decay", rep.as_ref(), Some(UNIFORM_H_RATE)),
                    last.map(|(h, hmin, n)| format!("; last level: h_fb {h:.1e}, h_min {hmin:.1e} (NDF {n})")).unwrap_or_default()
                )
            })
            .unwrap_or_default(),
        verdict: test.verdict(Kind::Paper, r.and(Evidence::rate(rep.as_ref())).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// Efficiency: estimate / error grows at most like l_h (eq. 6.3's factor): the trend of
/// estimate / error / l_h bounded (or falling); with l_h = 1 and the reliability beside it.
fn efficiency(ctx: &Ctx, r: Option<&RunRecord>, term: &Term, labels: Labels) -> Claim {
    let over_lh = ctx.growth(r, Q::EfficiencyOverLh);
    let test = Criterion::NotGrowing { what: format!("estimate / error / l_h ({})", source(r)) };
    Claim {
        fragile: None,
        id: labels.id,
        summary: Summary {
            topic: labels.topic,
            paper: concat!("efficient up to l_h (eq. 6.3), reliable with C_0 = ", c0_paper!()),
            headline: over_lh
                .as_ref()
                .map(|g| format!("estimate/error/l_h slope {:.2} ± {:.2} ({})", g.rate.slope, g.rate.half_width, source(r)))
                .unwrap_or("n/a".into()),
        },
        claim: format!(
            "Ex. 7.2 on rollers, {}: the estimator is efficient up to the factor l_h of eq. 6.3: estimate / error / l_h does not grow with NDF (its trend bounded or falling); reliability with C_0 = {C0_PAPER} beside it",
            term.name
        ),
        measured: r
            .map(|r| {
                format!(
                    "{}: {}; {}; {}; {}",
                    source(Some(r)),
                    growth_text("estimate / error / l_h", over_lh.as_ref()),
                    growth_text("estimate / error", ctx.growth(Some(r), Q::Efficiency).as_ref()),
                    growth_text("efficiency with l_h = 1", ctx.growth(Some(r), Q::EfficiencyL1).as_ref()),
                    c0_text(&source(Some(r)), r, ctx.err_field()).map(|c| c.0).unwrap_or("reliability: no error measured".into())
                )
            })
            .unwrap_or_default(),
        verdict: test.verdict(Kind::Paper, r.and(Evidence::fit(over_lh.as_ref())).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}
