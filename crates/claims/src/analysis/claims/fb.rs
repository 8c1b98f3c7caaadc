//! The rows of the free-boundary example `fb` (beyond the paper: an exact solution with contact
//! on [a, 1], a = sqrt(2) - 1), per contact term: the error rate carried over from 7.1, the
//! efficiency and refinement at the free boundary, each by its kind's one criterion
//! ([`super::rows`]); once, the discrete contact zone. Its runs' reliability is in the rows c0.
//! The runs of the study `deep` are used where it is stored, else those of the studies `fb` and
//! `estimator_repair`.

use super::rows::{self, Loaded, Subject, Words};
use super::{Claim, Criterion, Ctx, Evidence, Kind, Q, RowKind, Summary, fb_free_boundary, rate_text, repair, short_range, source};
use crate::analysis::problem_names;
use crate::analysis::verdict;
use model::settings::estimator::ContactTerm;
use store::records::RunRecord;

const SUBJECT: Subject = Subject { prefix: problem_names::FB, kind: Kind::Beyond };

/// The claims of the free-boundary example.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let p = rows::problem(problem_names::FB);
    let loaded = Loaded::read(ctx, &[p])?;
    let un = loaded.uniform(ctx, p);
    let per_term = loaded.per_term(ctx, p);
    for t in &per_term {
        let against_uniform = match (t.run, un) {
            (Some(r), Some(u)) => format!(". Unknowns for the same error: {}", repair::unknowns(ctx, r, u).0),
            _ => String::new(),
        };
        let uniform = if t.terms == [ContactTerm::AsWritten] {
            format!(". {}", rate_text(&format!("uniform ({})", source(un)), ctx.rate(un, Q::Error).as_ref(), None))
        } else {
            String::new()
        };
        out.push(rows::error_rate(
            ctx,
            &SUBJECT,
            t,
            Q::Error,
            "the adaptive error",
            Words {
                slug: "error-rate",
                topic: "fb: error rate, adaptive",
                paper: "NDF^-1.5, carried over",
                claim: "fb (beyond the paper): with a free boundary at x = a = sqrt(2) - 1 and a known solution, adaptive refinement converges at NDF^(-3/2)".into(),
                extra: format!("{uniform}{against_uniform}"),
            },
        ));
        out.push(rows::efficiency(
            ctx,
            &SUBJECT,
            t,
            Words {
                slug: "efficiency",
                topic: "fb: efficiency index",
                paper: "bounded, carried over",
                claim: rows::efficiency_claim(problem_names::FB),
                extra: String::new(),
            },
        ));
        out.push(rows::refinement(
            ctx,
            &SUBJECT,
            t,
            Words {
                slug: "refinement",
                topic: "fb: refinement at the free boundary",
                paper: "the mesh concentrates at free boundaries, carried over",
                claim: "fb: the adaptive mesh concentrates at the free boundary x = a: the length h_fb of the contact edge straddling it decays faster than NDF^(-1/2) (what uniform refinement gives) beyond its interval".into(),
                extra: String::new(),
            },
        ));
    }
    let runs: Vec<Option<&RunRecord>> = per_term.iter().map(|t| t.run).chain([un]).collect();
    out.push(contact_zone(&runs));
    Ok(())
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
fn contact_zone(runs: &[Option<&RunRecord>]) -> Claim {
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
    let zs: Vec<(String, String, Evidence)> = runs.iter().copied().filter_map(zone).collect();
    let test = Criterion::Each {
        of: zs.iter().map(|z| z.0.clone()).collect(),
        each: Box::new(Criterion::All(vec![
            Criterion::Decays { what: "|zone start - a| (the zone's first contact node against a, per level)".into() },
            Criterion::Test { passes_if: "the last level's zone ends at x = 1 (within 1e-12)".into(), open_if_not: false },
        ])),
    };
    let zone_decay = runs[0].and_then(|r| {
        let fit = zone_start_fit(r)?;
        Some(format!("|zone start - a| at NDF^-({}) ({}, {})", fit.text(), short_range(&fit), source(Some(r))))
    });
    Claim {
        fragile: None,
        id: "fb-contact-zone".into(),
        summary: Summary {
            topic: "fb: the discrete contact zone".into(),
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
        row: RowKind::Finding,
        terms: vec![],
    }
}
