//! The rows of the free-boundary example `fb` (beyond the paper: an exact solution with contact
//! on [a, 1], a = sqrt(2) - 1): the error rate carried over from 7.1, reliability and efficiency,
//! refinement at the free boundary and the discrete contact zone. Example 7.1's runs of the
//! study `deep` are used where it is stored, else those of the study `fb`.

use super::{
    Claim, Criterion, Ctx, Evidence, Kind, OPTIMAL, Q, REFINE_REACH, Summary, c0_text, fb_free_boundary, fragility, growth_headline,
    growth_text, latest_mesh, rate_headline, rate_text, repair, short_range, source,
};
use crate::analysis::roles;
use crate::analysis::verdict::{self, Abscissa, refinement};
use crate::estimator::estimate::{C0_PAPER, c0_paper};
use crate::records::RunRecord;

/// The runs the rows judge: the paper's estimator as written, the variant without full-contact
/// nodes, uniform refinement.
#[derive(Clone, Copy)]
struct Runs<'a> {
    ad: Option<&'a RunRecord>,
    wfc: Option<&'a RunRecord>,
    un: Option<&'a RunRecord>,
}

/// The claims of the free-boundary example.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let fb = ctx.shelf.runs(roles::FB_AS_WRITTEN.study)?;
    let deep = ctx.shelf.runs(roles::DEEP_FB_AS_WRITTEN.study)?;
    let runs = Runs {
        ad: ctx.deep_or(&deep, roles::DEEP_FB_AS_WRITTEN, ctx.find(&fb, roles::FB_AS_WRITTEN)),
        wfc: ctx.deep_or(&deep, roles::DEEP_FB_WFC, ctx.find(&fb, roles::FB_WFC)),
        un: ctx.deep_or(&deep, roles::DEEP_FB_UNIFORM, ctx.find(&fb, roles::FB_UNIFORM)),
    };
    out.push(error_rate(ctx, runs));
    out.push(reliability(ctx, runs));
    out.push(efficiency(ctx, runs));
    out.push(refinement_at_a(ctx)?);
    out.push(contact_zone(runs));
    Ok(())
}

/// fb-error-rate: the paper's claim carried over, judged for its estimator as written (the
/// variant beside it).
fn error_rate(ctx: &Ctx, Runs { ad, wfc, un }: Runs) -> Claim {
    let none = ad.is_none();
    let (e_ad, e_wfc, e_un) = (ctx.rate(ad, Q::Error), ctx.rate(wfc, Q::Error), ctx.rate(un, Q::Error));
    let test = Criterion::rate(format!("the adaptive error ({})", source(ad)), OPTIMAL, Abscissa::Ndof);
    Claim {
        fragile: fragility(e_ad.as_ref(), OPTIMAL),
        id: "fb-error-rate",
        summary: Summary { topic: "fb: error rate, adaptive", paper: "NDF^-1.5, carried over (beyond the paper)", headline: rate_headline("", e_ad.as_ref(), ad) },
        claim: "fb (beyond the paper): with a free boundary at x = a = sqrt(2) - 1 and a known solution, adaptive refinement with the paper's estimator (eta_5 as written) converges at NDF^(-3/2); the variant without full-contact nodes and uniform refinement for comparison".into(),
        measured: if none {
            "no data".into()
        } else {
            let against_uniform = |r: Option<&RunRecord>| match (r, un) {
                (Some(r), Some(u)) => format!("{}: {}", r.run.id, repair::unknowns(ctx, r, u).0),
                _ => String::new(),
            };
            let floor = |r: Option<&RunRecord>| r.map(|r| format!("; {}", ctx.floor_text(r))).unwrap_or_default();
            format!(
                "{}{}. {}{}. {}{}. Unknowns for the same error: {}; {}",
                rate_text(&format!("adaptive, eta_5 as written ({})", source(ad)), e_ad.as_ref(), Some(OPTIMAL)),
                floor(ad),
                rate_text(&format!("adaptive without full-contact nodes ({})", source(wfc)), e_wfc.as_ref(), Some(OPTIMAL)),
                floor(wfc),
                rate_text(&format!("uniform ({})", source(un)), e_un.as_ref(), None),
                floor(un),
                against_uniform(ad),
                against_uniform(wfc)
            )
        },
        verdict: test.verdict(Kind::Paper, Evidence::rate(e_ad.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Paper,
    }
}

/// fb-reliability: the smallest reliable C_0 of each run against the paper's.
fn reliability(ctx: &Ctx, Runs { ad, wfc, un }: Runs) -> Claim {
    let rows: Vec<(String, f64)> = [ad, wfc, un].into_iter().filter_map(|r| c0_text(&source(r), r?, ctx.err_field())).collect();
    let test = Criterion::AtMost {
        what: format!("the smallest reliable C_0 (the largest error / eta_h at any level of {})", [ad, wfc, un].map(source).join(", ")),
        limit: C0_PAPER,
        interval: false,
    };
    Claim {
        fragile: None,
        id: "fb-reliability",
        summary: Summary {
            topic: "fb: reliability",
            paper: concat!("C_0 = ", c0_paper!(), " reliable, carried over"),
            headline: rows
                .iter()
                .map(|r| r.1)
                .reduce(f64::max)
                .map_or("n/a".into(), |c| format!("smallest reliable C_0 {c:.1e} over {} runs", rows.len())),
        },
        claim: concat!("fb: C_0 = ", c0_paper!(), " is reliable, C_0 eta_h >= ||u - u_h||_Linf at every level; the smallest reliable C_0")
            .into(),
        measured: if rows.is_empty() { "no data".into() } else { rows.iter().map(|r| r.0.clone()).collect::<Vec<_>>().join("; ") },
        verdict: test.verdict(Kind::Beyond, rows.iter().map(|r| r.1).reduce(f64::max).map(Evidence::Value).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
    }
}

/// fb-efficiency: judged for the paper's estimator as written, like 7.1-efficiency.
fn efficiency(ctx: &Ctx, Runs { ad, wfc, .. }: Runs) -> Claim {
    let none = ad.is_none();
    let g = ctx.growth(ad, Q::Efficiency);
    let test = Criterion::Bounded { what: format!("estimate / error ({})", source(ad)) };
    Claim {
        fragile: None,
        id: "fb-efficiency",
        summary: Summary {
            topic: "fb: efficiency index",
            paper: "bounded, carried over",
            headline: growth_headline("log efficiency: ", g.as_ref(), ad),
        },
        claim: "fb: the efficiency index of the paper's estimator (eta_5 as written) stays bounded (same rule as 7.1-efficiency)".into(),
        measured: if none {
            "no data".into()
        } else {
            format!(
                "adaptive ({}): {}; {}; adaptive without full-contact nodes ({}): {}; {}",
                source(ad),
                growth_text("efficiency", ctx.growth(ad, Q::Efficiency).as_ref()),
                growth_text("efficiency / l_h", ctx.growth(ad, Q::EfficiencyOverLh).as_ref()),
                source(wfc),
                growth_text("efficiency", ctx.growth(wfc, Q::Efficiency).as_ref()),
                growth_text("efficiency / l_h", ctx.growth(wfc, Q::EfficiencyOverLh).as_ref())
            )
        },
        verdict: test.verdict(Kind::Beyond, Evidence::fit(g.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
    }
}

/// fb-refinement: the edge length along Gamma_C = (0, 1) x {0} has a local minimum at x = a on
/// the last saved mesh (the first run whose mesh is stored decides).
fn refinement_at_a(ctx: &Ctx) -> std::io::Result<Claim> {
    let a = fb_free_boundary();
    let mut parts = Vec::new();
    // the first mesh found decides
    let mut decides: Option<(String, bool)> = None;
    let meshes = [roles::FB_WFC, roles::FB_AS_WRITTEN];
    for id in meshes.iter().filter_map(|&role| ctx.roles.id(role)) {
        let Some(m) = latest_mesh(ctx.shelf, roles::FB_WFC.study, id)? else { continue };
        let prof = refinement::profile(&m, [0.0, 0.0], [1.0, 0.0]);
        match refinement::local_minimum(&prof, a, REFINE_REACH) {
            Some(lm) => {
                if decides.is_none() {
                    decides = Some((format!("{}/{id} level {}", roles::FB_WFC.study, m.level), lm.holds));
                }
                parts.push(format!(
                    "{id} level {} (NDF {}): at x = a {} → {}",
                    m.level,
                    m.ndof,
                    lm.text(),
                    if lm.holds { "local minimum" } else { "no local minimum" }
                ));
            }
            None => parts.push(format!("{id} level {}: no mesh edge on Gamma_C contains x = a", m.level)),
        }
    }
    let test = Criterion::Test {
        passes_if: format!(
            "the edge length along Gamma_C on the last saved mesh of {} has a local minimum (or a plateau of its own) at x = a: no edge within {REFINE_REACH} of a on either side is smaller than the edges at a, and one on each side is larger",
            decides.as_ref().map_or(format!("{} (else {})", ctx.roles.source(meshes[0]), ctx.roles.source(meshes[1])), |d| d.0.clone())
        ),
        open_if_not: false,
    };
    Ok(Claim {
        fragile: None,
        id: "fb-refinement",
        summary: Summary {
            topic: "fb: refinement at the free boundary",
            paper: "the mesh concentrates at free boundaries (beyond the paper)",
            headline: parts.first().cloned().unwrap_or("n/a".into()),
        },
        claim: format!(
            "fb: the adaptive mesh concentrates at the free boundary x = a: a local minimum (or plateau of its own) of the edge length along Gamma_C within {REFINE_REACH} of a"
        ),
        measured: if parts.is_empty() { "no data".into() } else { parts.join("; ") },
        verdict: test.verdict(Kind::Beyond, decides.map(|d| Evidence::Bool(d.1)).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
    })
}

/// |zone start - a| at each level of `r` (the zone's first contact node against a), fitted
/// against NDF over every level.
fn zone_start_fit(r: &RunRecord) -> Option<verdict::RateFit> {
    let a = fb_free_boundary();
    let ndof: Vec<usize> = r.levels.iter().map(|l| l.ndof).collect();
    let d0: Vec<Option<f64>> = r.levels.iter().map(|l| l.zone_min.map(|z| (z - a).abs())).collect();
    verdict::rate_over(&ndof, &d0, ndof.len() - 1)
}

/// fb-contact-zone: the discrete contact zone [zone_min, zone_max] tends to [a, 1].
fn contact_zone(Runs { ad, wfc, un }: Runs) -> Claim {
    let a = fb_free_boundary();
    let zone = |r: Option<&RunRecord>| -> Option<(String, String, Evidence)> {
        let r = r?;
        let last = r.levels.last()?;
        let fit = zone_start_fit(r)?;
        let end_ok = last.zone_max.is_some_and(|z| (z - 1.0).abs() <= 1e-12);
        Some((
            source(Some(r)),
            format!(
                "{}/{}: last level zone [{:.6}, {:.6}], |zone start - a| {:.1e} (h_min {:.1e}), decays at NDF^-({}) ({})",
                r.study,
                r.run.id,
                last.zone_min.unwrap_or(f64::NAN),
                last.zone_max.unwrap_or(f64::NAN),
                last.zone_min.map_or(f64::NAN, |z| (z - a).abs()),
                last.h_min,
                fit.text(),
                fit.range()
            ),
            Evidence::All(vec![Some(Evidence::Fit(fit)), Some(Evidence::Bool(end_ok))]),
        ))
    };
    let zs: Vec<(String, String, Evidence)> = [ad, wfc, un].into_iter().filter_map(zone).collect();
    let test = Criterion::Each {
        of: zs.iter().map(|z| z.0.clone()).collect(),
        each: Box::new(Criterion::All(vec![
            Criterion::Decays { what: "|zone start - a| (the zone's first contact node against a, per level)".into() },
            Criterion::Test { passes_if: "the last level's zone ends at x = 1 (within 1e-12)".into(), open_if_not: false },
        ])),
    };
    let zone_decay = ad.and_then(|r| {
        let fit = zone_start_fit(r)?;
        Some(format!("|zone start - a| at NDF^-({}) ({}, {})", fit.text(), short_range(&fit), source(Some(r))))
    });
    Claim {
        fragile: None,
        id: "fb-contact-zone",
        summary: Summary {
            topic: "fb: the discrete contact zone",
            paper: "tends to [a, 1] (beyond the paper)",
            headline: zone_decay.unwrap_or("n/a".into()),
        },
        claim: "fb: the discrete contact zone tends to [a, 1]: |zone start - a| decays (rate interval above 0) and the zone ends at x = 1"
            .into(),
        measured: if zs.is_empty() { "no data".into() } else { zs.iter().map(|z| z.1.clone()).collect::<Vec<_>>().join("; ") },
        verdict: test
            .verdict(Kind::Beyond, (!zs.is_empty()).then(|| Evidence::All(zs.iter().map(|z| Some(z.2.clone())).collect())).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
    }
}
