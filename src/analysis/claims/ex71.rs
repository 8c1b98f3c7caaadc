//! The rows of Example 7.1 (the smooth manufactured solution): the error and estimator rates,
//! eta_1..eta_5, the efficiency index, eta_6 and eta_7. The runs of the study `deep` are used
//! where it is stored, else those of the studies `ex71` and `contact_term_ablation`.

use super::{
    Claim, Criterion, Ctx, Evidence, Kind, OPTIMAL, Q, Summary, VANISHING, estimator_text, fragility, growth_headline, growth_text,
    rate_headline, rate_text, slowest_headline, source,
};
use crate::analysis::roles;
use crate::analysis::verdict::{self, Abscissa};
use crate::estimator::estimate::C0_PAPER;
use crate::records::RunRecord;

/// The runs the rows judge: the paper's estimator as written, the variant without full-contact
/// nodes, uniform refinement, and uniform refinement with sigma-hat read in Cartesian components.
#[derive(Clone, Copy)]
struct Runs<'a> {
    a71: Option<&'a RunRecord>,
    wfc: Option<&'a RunRecord>,
    u71: Option<&'a RunRecord>,
    u71c: Option<&'a RunRecord>,
}

/// The claims of Example 7.1.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let load = |role: roles::Role| ctx.shelf.runs(role.study);
    let (ex71, ct, deep) = (load(roles::EX71_AS_WRITTEN)?, load(roles::ABLATION_EX71_WFC)?, load(roles::DEEP_EX71_AS_WRITTEN)?);
    let runs = Runs {
        a71: ctx.deep_or(&deep, roles::DEEP_EX71_AS_WRITTEN, ctx.pick(&ex71, roles::EX71_AS_WRITTEN)),
        u71: ctx.deep_or(&deep, roles::DEEP_EX71_UNIFORM, ctx.find(&ex71, roles::EX71_UNIFORM)),
        u71c: ctx.find(&ex71, roles::EX71_UNIFORM_CARTESIAN),
        wfc: ctx.deep_or(&deep, roles::DEEP_EX71_WFC, ctx.pick(&ct, roles::ABLATION_EX71_WFC)),
    };
    out.push(error_rate(ctx, runs));
    out.push(estimator_rate(ctx, runs));
    out.push(terms(ctx, runs));
    out.push(efficiency(ctx, runs));
    out.push(eta6_eta7(runs));
    Ok(())
}

/// 7.1-error-rate (Fig. 2a).
fn error_rate(ctx: &Ctx, Runs { a71, wfc, u71, .. }: Runs) -> Claim {
    let err = ctx.rate(a71, Q::Error);
    let with_floor = |name: &str, r: Option<&RunRecord>| {
        let text = rate_text(&format!("{name} ({})", source(r)), ctx.rate(r, Q::Error).as_ref(), Some(OPTIMAL));
        r.map_or(text.clone(), |r| format!("{text}; {}", ctx.floor_text(r)))
    };
    let test = Criterion::rate(format!("the adaptive error ({})", source(a71)), OPTIMAL, Abscissa::Ndof);
    Claim {
        fragile: fragility(err.as_ref(), OPTIMAL),
        id: "7.1-error-rate",
        summary: Summary {
            topic: "Ex. 7.1: error rate, adaptive",
            paper: "NDF^-1.5 (Fig. 2a)",
            headline: rate_headline("", err.as_ref(), a71),
        },
        claim: "Ex. 7.1: the error ||u - u_h||_Linf converges at the optimal rate NDF^(-3/2) under adaptive refinement (Fig. 2a)".into(),
        measured: format!(
            "{}. {}. {}",
            with_floor("marking by eta_5 as written", a71),
            with_floor("without full-contact nodes", wfc),
            with_floor("uniform", u71)
        ),
        verdict: test.verdict(Kind::Paper, Evidence::rate(err.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// 7.1-estimator-rate (Fig. 2a).
fn estimator_rate(ctx: &Ctx, Runs { a71, wfc, .. }: Runs) -> Claim {
    let est = ctx.rate(a71, Q::Field("eta_h"));
    let test = Criterion::rate(format!("eta_h ({})", source(a71)), OPTIMAL, Abscissa::Ndof);
    Claim {
        fragile: fragility(est.as_ref(), OPTIMAL),
        id: "7.1-estimator-rate",
        summary: Summary {
            topic: "Ex. 7.1: estimator rate",
            paper: "eta_h at NDF^-1.5 (Fig. 2a)",
            headline: rate_headline("eta_h ", est.as_ref(), a71),
        },
        claim: "Ex. 7.1: the estimator eta_h converges at NDF^(-3/2) (Fig. 2a)".into(),
        measured: format!(
            "as written ({}): {}. Without full-contact nodes ({}): {}",
            source(a71),
            estimator_text(ctx, a71),
            source(wfc),
            estimator_text(ctx, wfc)
        ),
        verdict: test.verdict(Kind::Paper, Evidence::rate(est.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// 7.1-eta5: eta_1..eta_5 each at the optimal rate (Fig. 4a), with both readings of sigma-hat.
fn terms(ctx: &Ctx, Runs { a71, u71, u71c, .. }: Runs) -> Claim {
    let terms: Vec<String> =
        ["eta1", "eta2", "eta3", "eta4", "eta5"].iter().map(|n| rate_text(n, ctx.rate(a71, Q::Field(n)).as_ref(), Some(OPTIMAL))).collect();
    let slower = |r: Option<&RunRecord>| -> String {
        let rates: Option<Vec<f64>> = ["eta4", "eta5"].iter().map(|n| ctx.rate(r, Q::Field(n)).map(|x| x.main.rate.slope)).collect();
        rates.map(|v| format!("NDF^(-{:.2})", v[0].min(v[1]))).unwrap_or("n/a".into())
    };
    let names = ["eta1", "eta2", "eta3", "eta4", "eta5"];
    let test = Criterion::Each {
        of: names.iter().map(|n| n.to_string()).collect(),
        each: Box::new(Criterion::rate(format!("the term ({})", source(a71)), OPTIMAL, Abscissa::Ndof)),
    };
    let ev = a71.map(|_| Evidence::All(names.iter().map(|n| Evidence::rate(ctx.rate(a71, Q::Field(n)).as_ref())).collect()));
    Claim {
        fragile: None,
        id: "7.1-eta5",
        summary: Summary {
            topic: "Ex. 7.1: eta_1..eta_5",
            paper: "each at NDF^-1.5 (Fig. 4a)",
            headline: slowest_headline(ctx, a71, &["eta1", "eta2", "eta3", "eta4", "eta5"]),
        },
        claim:
            "Ex. 7.1: the individual estimators eta_1..eta_5 decay optimally (Fig. 4a); in particular eta_5 = max_p h_p |sigma-hat_1(u_h)|"
                .into(),
        measured: format!(
            "adaptive ({}): {}. Reading of sigma-hat (sigma n in a frame whose e_1 is the normal), the rows above: sigma-hat_1 = n . sigma n (normal stress, eta_5), sigma-hat_2 = t . sigma n (eta_4); \
             |sigma_nn| is 3 to 6 on all of Gamma_C, so eta_5 ~ h. Uniform refinement ({}), this reading: {}; {}. \
             Read literally as Cartesian components (estimator.stress_frame = \"cartesian\", run {}), sigma-hat_1 = -sigma_12 (zero for the exact solution) and sigma-hat_2 = -sigma_22: {}; {}. \
             The slower of eta_4, eta_5 decays at {} (this reading) and {} (literal reading)",
            source(a71),
            terms.join("; "),
            source(u71),
            rate_text("eta4", ctx.rate(u71, Q::Field("eta4")).as_ref(), Some(OPTIMAL)),
            rate_text("eta5", ctx.rate(u71, Q::Field("eta5")).as_ref(), Some(OPTIMAL)),
            ctx.roles.source(roles::EX71_UNIFORM_CARTESIAN),
            rate_text("eta4", ctx.rate(u71c, Q::Field("eta4")).as_ref(), Some(OPTIMAL)),
            rate_text("eta5", ctx.rate(u71c, Q::Field("eta5")).as_ref(), Some(OPTIMAL)),
            slower(u71),
            slower(u71c),
        ),
        verdict: test.verdict(Kind::Paper, ev.as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// 7.1-efficiency (Fig. 2b).
fn efficiency(ctx: &Ctx, Runs { a71, wfc, .. }: Runs) -> Claim {
    let g = ctx.growth(a71, Q::Efficiency);
    let test = Criterion::Bounded { what: format!("estimate / error ({})", source(a71)) };
    Claim {
        fragile: None,
        id: "7.1-efficiency",
        summary: Summary {
            topic: "Ex. 7.1: efficiency index",
            paper: "bounded (Fig. 2b)",
            headline: growth_headline("log efficiency: ", g.as_ref(), a71),
        },
        claim: format!(
            "Ex. 7.1: the efficiency index estimate/error stays bounded (Fig. 2b), C_0 = {C0_PAPER}; bounded = the slope of log(efficiency) against log(NDF) has a 95% interval containing 0 no wider than {}",
            verdict::MAX_WIDTH,
        ),
        measured: format!(
            "as written ({}): {}; {}; {}. Without full-contact nodes ({}): {}; {}",
            source(a71),
            growth_text("efficiency", g.as_ref()),
            growth_text("efficiency / l_h", ctx.growth(a71, Q::EfficiencyOverLh).as_ref()),
            growth_text("efficiency with l_h = 1, C_0 (Psi + eta_6 + eta_7) / error", ctx.growth(a71, Q::EfficiencyL1).as_ref()),
            source(wfc),
            growth_text("efficiency", ctx.growth(wfc, Q::Efficiency).as_ref()),
            growth_text("efficiency / l_h", ctx.growth(wfc, Q::EfficiencyOverLh).as_ref()),
        ),
        verdict: test.verdict(Kind::Paper, Evidence::fit(g.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// 7.1-eta6-eta7: the two contact terms vanish.
fn eta6_eta7(Runs { a71, .. }: Runs) -> Claim {
    let eta67 = a71.map(|r| r.levels.iter().map(|l| l.terms.eta6.max(l.terms.eta7)).fold(0.0, f64::max));
    let test =
        Criterion::AtMost { what: format!("the largest eta_6 or eta_7 at any level ({})", source(a71)), limit: VANISHING, interval: false };
    Claim {
        fragile: None,
        id: "7.1-eta6-eta7",
        summary: Summary {
            topic: "Ex. 7.1: eta_6, eta_7",
            paper: "vanish",
            headline: eta67.map(|v| format!("largest {v:.1e} ({})", source(a71))).unwrap_or("n/a".into()),
        },
        claim: "Ex. 7.1: ||(chi + u_h2)^+||_Linf(Lambda) and ||(-u_h2 - chi)^+||_Linf(Gamma_C) vanish".into(),
        measured: eta67.map(|v| format!("max over levels of eta6, eta7: {v:.3e}")).unwrap_or_default(),
        verdict: test.verdict(Kind::Paper, eta67.map(Evidence::Value).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}
