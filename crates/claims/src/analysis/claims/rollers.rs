//! The rows of Example 7.2 on rollers (study `ex72_rollers`, beyond the paper): the block, load
//! and wedge of Example 7.2 with the left side on rollers instead of clamped, so that the
//! corners which set 7.2's error are gone. Every Example 7.2 claim of the paper is judged on it
//! for each contact term (eta_5 as written, without full-contact nodes, repaired; one row for
//! two whose runs coincide): the estimator's rates (the row of [`super::ex72::rates`]), the true
//! error's rate, refinement at the free boundary and the efficiency, each by its kind's one
//! criterion ([`super::rows`]); with the reference's own error (the row of [`super::ex72::error`])
//! and the uniform rate that shows the corners gone. A problem the paper never ran: its rows are
//! beyond the paper and counted apart in the headline.

use super::ex72::{Errors, Labels, error, rates};
use super::rows::{self, Loaded, Subject, Words};
use super::{
    Claim, Criterion, Ctx, EX72_NU, Evidence, Kind, OPTIMAL, Q, RowKind, Summary, halving_exponents, rate_headline, rate_text, source,
};
use crate::analysis::problem_names;
use crate::analysis::roles;
use crate::analysis::verdict::{self, Abscissa};
use store::records::RunRecord;

/// The study.
const STUDY: &str = roles::ROLLERS_AS_WRITTEN.study;

const SUBJECT: Subject = Subject { prefix: "7.2r", kind: Kind::Beyond };

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
    let p = rows::problem(problem_names::EX72_ROLLERS);
    let loaded = Loaded::read(ctx, &[p])?;
    for t in loaded.per_term(ctx, p) {
        out.push(rates(ctx, &SUBJECT, &t, "Ex. 7.2 on rollers: estimator rates"));
        out.push(rows::error_rate(
            ctx,
            &SUBJECT,
            &t,
            Q::Error,
            "the true error",
            Words {
                slug: "error-rate",
                topic: "Ex. 7.2 on rollers: true error rate",
                paper: "optimal, NDF^-1.5 (carried over from 7.1)",
                claim: "Ex. 7.2 on rollers: the true error ||u - u_h||_Linf against the reference converges at the paper's optimal NDF^(-3/2), no longer masked by the corners".into(),
                extra: [("on Gamma_C", "err_contact"), ("on x >= 1/2", "err_right_half")]
                    .iter()
                    .map(|(n, f)| format!("; {}", rate_text(n, ctx.rate(t.run, Q::Field(f)).as_ref(), Some(OPTIMAL))))
                    .collect(),
            },
        ));
        out.push(rows::refinement(
            ctx,
            &SUBJECT,
            &t,
            Words {
                slug: "refinement",
                topic: "Ex. 7.2 on rollers: refinement at the free boundary",
                paper: "refined at the free boundary (Fig. 3b)",
                claim: rows::refinement_claim(problem_names::label(problem_names::EX72_ROLLERS)),
                extra: String::new(),
            },
        ));
        out.push(rows::efficiency(
            ctx,
            &SUBJECT,
            &t,
            Words {
                slug: "efficiency",
                topic: "Ex. 7.2 on rollers: efficiency index",
                paper: "bounded (Fig. 2b, carried over)",
                claim: rows::efficiency_claim(problem_names::label(problem_names::EX72_ROLLERS)),
                extra: String::new(),
            },
        ));
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
        id: "7.2r-uniform (beyond the paper)".into(),
        summary: Summary {
            topic: "Ex. 7.2 on rollers: the corners are gone".into(),
            paper: "not in the paper; clamped: h^0.711 (row 7.2-corners)",
            headline: rate_headline("uniform: ", rep.as_ref(), u),
        },
        claim: format!(
            "Ex. 7.2 on rollers: reflected across x = 0 the rollers side is an interior line, so the singularity of the clamped / traction-free corners (u ~ r^{lambda:.4}, uniform refinement h^{lambda:.4} = NDF^-{:.3}) is gone: uniform refinement converges faster than NDF^-{:.3} beyond its interval",
            lambda / 2.0,
            lambda / 2.0
        ),
        measured: match (&rep, u) {
            (Some(r), Some(run)) => format!(
                "{}: {}. What limits it to about h^1 (not P2's h^3): the kink of the obstacle chi at the wedge tip (1, 1/2), inside the contact zone; {}; local exponent of the error on Gamma_C (where its maximum lies) per halving of h over the last halvings {}",
                source(u),
                rate_text("uniform error rate", Some(r), Some(lambda / 2.0)),
                super::peak_text(run, "the wedge tip", [1.0, 0.5]),
                halving_exponents(run, "err_contact", 3)
            ),
            _ => String::new(),
        },
        verdict: test.verdict(Kind::Beyond, Evidence::rate(rep.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
        row: RowKind::Finding,
        terms: vec![],
    }
}
