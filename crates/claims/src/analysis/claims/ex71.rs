//! The rows of Example 7.1 (the smooth manufactured solution), once per contact term: the error
//! and estimator rates, eta_1..eta_5, the efficiency index, eta_6 and eta_7. The runs of the
//! study `deep` are used where it is stored, else those of the studies `ex71`,
//! `contact_term_ablation` and `estimator_repair`.

use super::rows::{self, Loaded, Subject, Words};
use super::terms::TermRun;
use super::{Claim, Criterion, Ctx, Evidence, Kind, OPTIMAL, Q, RowKind, Summary, VANISHING, rate_text, source};
use crate::analysis::problem_names;
use crate::analysis::roles;
use crate::analysis::verdict;
use model::settings::estimator::{C0_PAPER, ContactTerm};
use store::records::RunRecord;

const SUBJECT: Subject = Subject { prefix: "7.1", kind: Kind::Paper };

/// The claims of Example 7.1.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let p = rows::problem(problem_names::EX71);
    let loaded = Loaded::read(ctx, &[p])?;
    let uniform = loaded.uniform(ctx, p);
    let ex71 = ctx.shelf.runs(roles::EX71_UNIFORM_CARTESIAN.study)?;
    let cartesian = ctx.find(&ex71, roles::EX71_UNIFORM_CARTESIAN);
    for t in loaded.per_term(ctx, p) {
        let first = t.terms == [ContactTerm::AsWritten];
        let uniform_error = |first: bool| {
            if first {
                let text =
                    rate_text(&format!(". Uniform refinement ({})", source(uniform)), ctx.rate(uniform, Q::Error).as_ref(), Some(OPTIMAL));
                uniform.map_or(text.clone(), |u| format!("{text}; {}", ctx.floor_text(u)))
            } else {
                String::new()
            }
        };
        out.push(rows::error_rate(
            ctx,
            &SUBJECT,
            &t,
            Q::Error,
            "the adaptive error",
            Words {
                slug: "error-rate",
                topic: "Ex. 7.1: error rate, adaptive",
                paper: "NDF^-1.5 (Fig. 2a)",
                claim: "Ex. 7.1: the error ||u - u_h||_Linf converges at the optimal rate NDF^(-3/2) under adaptive refinement (Fig. 2a)"
                    .into(),
                extra: uniform_error(first),
            },
        ));
        out.push(rows::estimator_rates(
            ctx,
            &SUBJECT,
            &t,
            &["eta_h"],
            Words {
                slug: "estimator-rate",
                topic: "Ex. 7.1: estimator rate",
                paper: "eta_h at NDF^-1.5 (Fig. 2a)",
                claim: "Ex. 7.1: the estimator eta_h converges at NDF^(-3/2) (Fig. 2a)".into(),
                extra: String::new(),
            },
        ));
        out.push(rows::estimator_rates(
            ctx,
            &SUBJECT,
            &t,
            &["eta1", "eta2", "eta3", "eta4", "eta5"],
            Words {
                slug: "eta5",
                topic: "Ex. 7.1: eta_1..eta_5",
                paper: "each at NDF^-1.5 (Fig. 4a)",
                claim: "Ex. 7.1: the individual estimators eta_1..eta_5 decay optimally (Fig. 4a); in particular eta_5 = max_p h_p |sigma-hat_1(u_h)|".into(),
                extra: if first { readings(ctx, uniform, cartesian) } else { String::new() },
            },
        ));
        out.push(rows::efficiency(
            ctx,
            &SUBJECT,
            &t,
            Words {
                slug: "efficiency",
                topic: "Ex. 7.1: efficiency index",
                paper: "bounded (Fig. 2b)",
                claim: format!(
                    "Ex. 7.1: the efficiency index estimate/error stays bounded (Fig. 2b), C_0 = {C0_PAPER}; bounded = the slope of log(efficiency) against log(NDF) has a 95% interval containing 0 no wider than {}",
                    verdict::MAX_WIDTH
                ),
                extra: String::new(),
            },
        ));
        out.push(eta6_eta7(&t));
    }
    Ok(())
}

/// The two readings of sigma-hat under uniform refinement, for the row on eta_1..eta_5.
fn readings(ctx: &Ctx, u71: Option<&RunRecord>, u71c: Option<&RunRecord>) -> String {
    let slower = |r: Option<&RunRecord>| -> String {
        let rates: Option<Vec<f64>> = ["eta4", "eta5"].iter().map(|n| ctx.rate(r, Q::Field(n)).map(|x| x.main.rate.slope)).collect();
        rates.map(|v| format!("NDF^(-{:.2})", v[0].min(v[1]))).unwrap_or("n/a".into())
    };
    format!(
        ". Reading of sigma-hat (sigma n in a frame whose e_1 is the normal), the rows above: sigma-hat_1 = n . sigma n (normal stress, eta_5), sigma-hat_2 = t . sigma n (eta_4); \
         |sigma_nn| is 3 to 6 on all of Gamma_C, so eta_5 ~ h. Uniform refinement ({}), this reading: {}; {}. \
         Read literally as Cartesian components (estimator.stress_frame = \"cartesian\", run {}), sigma-hat_1 = -sigma_12 (zero for the exact solution) and sigma-hat_2 = -sigma_22: {}; {}. \
         The slower of eta_4, eta_5 decays at {} (this reading) and {} (literal reading)",
        source(u71),
        rate_text("eta4", ctx.rate(u71, Q::Field("eta4")).as_ref(), Some(OPTIMAL)),
        rate_text("eta5", ctx.rate(u71, Q::Field("eta5")).as_ref(), Some(OPTIMAL)),
        ctx.roles.source(roles::EX71_UNIFORM_CARTESIAN),
        rate_text("eta4", ctx.rate(u71c, Q::Field("eta4")).as_ref(), Some(OPTIMAL)),
        rate_text("eta5", ctx.rate(u71c, Q::Field("eta5")).as_ref(), Some(OPTIMAL)),
        slower(u71),
        slower(u71c),
    )
}

/// 7.1-eta6-eta7: the two contact terms vanish.
fn eta6_eta7(t: &TermRun) -> Claim {
    let r = t.run;
    let eta67 = r.map(|r| r.levels.iter().map(|l| l.terms.eta6.max(l.terms.eta7)).fold(0.0, f64::max));
    let test =
        Criterion::AtMost { what: format!("the largest eta_6 or eta_7 at any level ({})", source(r)), limit: VANISHING, interval: false };
    Claim {
        fragile: None,
        id: format!("7.1-eta6-eta7{}", t.suffix()),
        summary: Summary {
            topic: format!("Ex. 7.1: eta_6, eta_7{}", t.suffix()),
            paper: "vanish",
            headline: eta67.map(|v| format!("largest {v:.1e} ({})", source(r))).unwrap_or("n/a".into()),
        },
        claim: format!(
            "Ex. 7.1: ||(chi + u_h2)^+||_Linf(Lambda) and ||(-u_h2 - chi)^+||_Linf(Gamma_C) vanish (contact term: {})",
            t.names()
        ),
        measured: eta67.map(|v| format!("max over levels of eta6, eta7: {v:.3e}{}", t.note_text())).unwrap_or("no data".into()),
        verdict: test.verdict(Kind::Paper, eta67.map(Evidence::Value).as_ref()),
        criterion: test,
        kind: Kind::Paper,
        row: RowKind::Vanishing,
        terms: t.terms.clone(),
    }
}
