//! The rows of Example 7.2 (studies `ex72_large`, `ex72`, with the `contact_term_ablation` runs of
//! the same problem): per contact term the estimator's rates and where the adaptive mesh
//! refines (the free boundary, the corners); once, beyond the paper, the true error against a
//! reference, the corner singularity, the error away from the corners, eta_6 and eta_7 at the
//! free boundary.

use super::rows::{self, Loaded, Subject, Words};
use super::terms::TermRun;
use super::{
    Claim, Criterion, Ctx, EX72_NU, Evidence, Kind, OPTIMAL, Q, RowKind, Summary, fragility, growth_text, halving_exponents, latest_mesh,
    rate_headline, rate_text, source,
};
use crate::analysis::problem_names;
use crate::analysis::roles;
use crate::analysis::studies;
use crate::analysis::verdict::{self, Abscissa, refinement};
use store::records::RunRecord;

/// A corner is a refinement centre when its smallest element within this distance of it ...
const CORNER_NEAR: f64 = 0.02;
/// ... is smaller than every element between [`CORNER_NEAR`] and this distance.
const CORNER_RING: f64 = 0.1;

const SUBJECT: Subject = Subject { prefix: "7.2", kind: Kind::Paper };

/// The claims of Example 7.2.
pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let load = |s: &str| ctx.shelf.runs(s);
    let (ex72, ct, large) = (load(studies::EX72)?, load(studies::CONTACT_TERM_ABLATION)?, load(studies::EX72_LARGE)?);
    let a72 = ctx.pick(&ex72, roles::EX72_AS_WRITTEN);
    let u72 = ctx.find(&ex72, roles::EX72_UNIFORM);
    let wfc = ctx.pick(&ct, roles::ABLATION_EX72_WFC);
    let aw = ctx.find(&ct, roles::ABLATION_EX72_AS_WRITTEN);
    let errors = Errors::of(ctx, &large).unwrap_or(Errors {
        study: roles::EX72_AS_WRITTEN.study,
        adaptive: a72,
        without_full_contact: None,
        uniform: u72,
    });
    let p = rows::problem(problem_names::EX72);
    let loaded = Loaded::read(ctx, &[p])?;
    for t in loaded.per_term(ctx, p) {
        out.push(rates(ctx, &SUBJECT, &t, "Ex. 7.2: estimator rates"));
        out.push(rows::refinement(
            ctx,
            &SUBJECT,
            &t,
            Words {
                slug: "refinement",
                topic: "Ex. 7.2: refinement at the free boundary",
                paper: "refined at the free boundary (Fig. 3b)",
                claim: rows::refinement_claim("Ex. 7.2"),
                extra: String::new(),
            },
        ));
        out.push(corner_refinement(ctx, &t)?);
    }
    out.push(error(ctx, &errors, aw, wfc, Labels { id: "7.2-error (beyond the paper)", topic: "Ex. 7.2: true error" }));
    out.push(corners(ctx, a72, &errors));
    for t in loaded.per_term(ctx, p) {
        out.push(rows::error_rate(
            ctx,
            &Subject { prefix: "7.2", kind: Kind::Beyond },
            &t,
            Q::Field("err_contact"),
            "the adaptive error on Gamma_C",
            Words {
                slug: "error-away-from-corners",
                topic: "Ex. 7.2 (beyond the paper): error on Gamma_C",
                paper: "NDF^-1.5, carried over",
                claim: "Ex. 7.2: the error where the contact discretisation acts, away from the corners of x = 0: ||u - u_h||_Linf on Gamma_C (13 equally spaced points per contact edge), against the reference solution, at NDF^(-3/2) under adaptive refinement".into(),
                extra: format!(
                    "; {}",
                    rate_text("on x >= 1/2", ctx.rate(t.run, Q::Field("err_right_half")).as_ref(), Some(OPTIMAL))
                ),
            },
        ));
    }
    out.push(eta6_eta7(a72));
    Ok(())
}

/// The runs the true-error rows (and the estimator's rates) fit: the deep study `ex72_large`
/// (reference of at least 4e6 unknowns, runs to about 1e6) where it holds errors, else `ex72`
/// (reference 2.5e5).
pub(super) struct Errors<'a> {
    pub(super) study: &'static str,
    pub(super) adaptive: Option<&'a RunRecord>,
    /// eta_5 without full-contact nodes (only in `ex72_large` and `ex72_rollers`)
    pub(super) without_full_contact: Option<&'a RunRecord>,
    pub(super) uniform: Option<&'a RunRecord>,
}

/// The id and summary topic of a row written for more than one study (Example 7.2 clamped and
/// on rollers).
#[derive(Clone, Copy)]
pub(super) struct Labels {
    pub(super) id: &'static str,
    pub(super) topic: &'static str,
}

impl<'a> Errors<'a> {
    fn of(ctx: &Ctx, large: &'a [RunRecord]) -> Option<Errors<'a>> {
        let adaptive = ctx.find(large, roles::LARGE_AS_WRITTEN).filter(|r| r.levels.iter().any(|l| l.err_quadrature.is_some()))?;
        Some(Errors {
            study: roles::LARGE_AS_WRITTEN.study,
            adaptive: Some(adaptive),
            without_full_contact: ctx.find(large, roles::LARGE_WFC),
            uniform: ctx.find(large, roles::LARGE_UNIFORM),
        })
    }

    /// "study ex72_large, reference NDF 4485286"
    fn source(&self) -> String {
        format!(
            "study {}, reference NDF {}",
            self.study,
            self.adaptive.and_then(|r| r.reference_ndof).map(|n| n.to_string()).unwrap_or("none".into()),
        )
    }
}

/// Row of Example 7.2 (and on rollers): the estimator and its terms against NDF^(-3/2) (Fig. 3a, 4b).
pub(super) fn rates(ctx: &Ctx, s: &Subject, t: &TermRun, topic: &'static str) -> Claim {
    rows::estimator_rates(
        ctx,
        s,
        t,
        &["eta_h", "eta1", "eta2", "eta3", "eta4", "eta5", "eta6", "eta7"],
        Words {
            slug: "rates",
            topic,
            paper: "eta_h and eta_1..eta_7 at NDF^-1.5 (Fig. 3a, 4b)",
            claim:
                "Ex. 7.2: the full estimator eta_h and the individual estimators eta_1..eta_7 converge optimally, NDF^(-3/2) (Fig. 3a, 4b)"
                    .into(),
            extra: String::new(),
        },
    )
}

/// Row of Example 7.2: the true error against the reference, and eta_5 as written against without full-contact nodes.
pub(super) fn error(ctx: &Ctx, errors: &Errors, aw: Option<&RunRecord>, wfc: Option<&RunRecord>, labels: Labels) -> Claim {
    // the true error against the reference, whose own error is estimated from the measured rate
    let a72 = errors.adaptive;
    let err = ctx.rate(a72, Q::Error);
    let deep_wfc = errors.without_full_contact.map(|w| {
        let e = ctx.values(w, Q::Error).last().copied().flatten().unwrap_or(f64::NAN);
        format!(
            "{} (to NDF {}, last error {e:.1e})",
            rate_text("without full-contact nodes: error rate", ctx.rate(Some(w), Q::Error).as_ref(), Some(OPTIMAL)),
            w.levels.last().map_or(0, |l| l.ndof)
        )
    });
    // the reference's own error, as every row with a reference estimates it
    let reference_error = a72.and_then(|r| ctx.reference_error(r));
    let a_last = a72.and_then(|r| ctx.values(r, Q::Error).last().copied().flatten()).unwrap_or(f64::NAN);
    // same error with and without full-contact nodes although the meshes differ
    let same = aw.zip(wfc).map(|(a, w)| {
        let (ea, ew) = (ctx.values(a, Q::Error), ctx.values(w, Q::Error));
        let n = ea.len().min(ew.len());
        let rel = (0..n).filter_map(|i| Some(((ea[i]? - ew[i]?) / ea[i]?).abs())).skip(8).fold(0.0, f64::max);
        let ndf = (8..n).map(|i| a.levels[i].ndof as f64 / w.levels[i].ndof as f64).fold(1.0, f64::max);
        (rel, ndf, n)
    });
    let reported = Criterion::Reported { why: "the paper does not measure Example 7.2's error".into() };
    Claim {
        fragile: None,
        id: labels.id.into(),
        summary: Summary { topic: labels.topic.into(), paper: "not measured in the paper", headline: rate_headline("", err.as_ref(), a72) },
        claim: "Ex. 7.2 (not in the paper): the true error against a finer reference solution, and the efficiency index".into(),
        measured: a72
            .map(|_| {
                format!(
                    "{}: {}; {}{}; {}; {}; {}",
                    errors.source(),
                    rate_text("error rate", err.as_ref(), Some(OPTIMAL)),
                    deep_wfc.map(|t| format!("{t}; ")).unwrap_or_default(),
                    ctx.floor_text(a72.expect("checked")),
                    reference_error
                        .map(|re| format!("{} ({:.1}% of eta_5 as written's last error)", re.text, 100.0 * re.error / a_last))
                        .unwrap_or("no reference".into()),
                    growth_text("efficiency", ctx.growth(a72, Q::Efficiency).as_ref()),
                    same.map(|(rel, ndf, n)| {
                        format!(
                            "eta_5 as written vs without full-contact nodes ({}): errors differ by at most {rel:.1e} (relative) at levels 8–{} while the NDF differ by up to {ndf:.2}x{}",
                            source(aw).split('/').next().unwrap_or_default(),
                            n - 1,
                            if rel < 1e-3 && ndf > 1.2 { ": the error does not see the contact refinement (next rows)" } else { "" }
                        )
                    })
                    .unwrap_or_default()
                )
            })
            .unwrap_or_default(),
        verdict: reported.verdict(Kind::Beyond, a72.map(|_| Evidence::Bool(true)).as_ref()),
        criterion: reported,
        kind: Kind::Beyond,
        row: RowKind::Measured,
        terms: vec![],
    }
}

/// Row of Example 7.2: the corner singularity under uniform refinement.
fn corners(ctx: &Ctx, a72: Option<&RunRecord>, errors: &Errors) -> Claim {
    let u72 = errors.uniform;
    // the corner singularity
    let lambda = verdict::clamped_free_corner_exponent(EX72_NU);
    // where the largest element indicator sits (records from before it was stored have (0, 0) everywhere)
    let peaks = a72
        .filter(|r| r.levels.iter().any(|l| l.max_indicator_x != 0.0 || l.max_indicator_y != 0.0))
        .map(|r| {
            let near = |l: &model::level::record::LevelRecord| {
                [[0.0, 0.0], [0.0, 1.0]].iter().any(|c| model::mesh::dist(*c, [l.max_indicator_x, l.max_indicator_y]) <= 0.05)
            };
            let n = r.levels.iter().filter(|l| near(l)).count();
            let at = |k: usize| {
                r.levels.get(k).map(|l| format!("level {k} at ({:.3}, {:.3})", l.max_indicator_x, l.max_indicator_y)).unwrap_or_default()
            };
            format!(
                "Adaptive run: the largest element indicator lies within 0.05 of a corner (0, 0) or (0, 1) at {n} of {} levels ({}; {})",
                r.levels.len(),
                at(20),
                at(r.levels.len() - 1)
            )
        })
        .unwrap_or_default();
    let eu = ctx.rate(u72, Q::Error);
    let test = Criterion::rate(
        format!("the uniform error ({})", source(u72)),
        lambda / 2.0,
        u72.map_or(Abscissa::InverseHMin, verdict::abscissa_of),
    );
    Claim {
        fragile: fragility(eu.as_ref(), lambda / 2.0),
        id: "7.2-corners (beyond the paper)".into(),
        summary: Summary {
            topic: "Ex. 7.2: the corners set the error".into(),
            paper: "not in the paper; h^0.711 expected under uniform refinement",
            headline: rate_headline("uniform: ", eu.as_ref(), u72),
        },
        claim: format!(
            "Ex. 7.2: the error is set by the corners where the clamped side x = 0 meets the traction-free sides: u ~ r^lambda with lambda = {lambda:.4} the root in (1/2, 1) of 4 lambda^2 = 1 + kappa^2 + 2 kappa cos(lambda pi), kappa = 3 - 4 nu, nu = {EX72_NU}; uniform refinement then gives h^lambda (NDF^(-{:.3})), judged as a rate in h_min",
            lambda / 2.0
        ),
        measured: match &eu {
            Some(r) => format!(
                "{}: uniform: {}; measured exponent lambda = {:.4} ± {:.4}; error reduction per halving of h {:.3} (2^-lambda = {:.3}); local exponent -log2(reduction) over the last halvings {}. {}",
                errors.source(),
                rate_text("error rate", Some(r), Some(lambda / 2.0)),
                r.main.rate.slope,
                r.main.rate.half_width,
                0.5f64.powf(r.main.rate.slope),
                0.5f64.powf(lambda),
                u72.map(|u| halving_exponents(u, ctx.err_field(), 4)).unwrap_or_default(),
                peaks
            ),
            None => String::new(),
        },
        verdict: test.verdict(Kind::Beyond, Evidence::rate(eu.as_ref()).as_ref()),
        criterion: test,
        kind: Kind::Beyond,
        row: RowKind::Finding,
        terms: vec![],
    }
}

/// Row of Example 7.2: eta_6 and eta_7 against the length of the contact edge straddling the free boundary.
fn eta6_eta7(a72: Option<&RunRecord>) -> Claim {
    // eta_6, eta_7 against the length of the contact edge straddling the free boundary
    let fb_edge = a72.map(|r| {
        // one point per plateau of h_free_boundary (its last level), where eta_6, eta_7 are above round-off
        let mut plateaus: Vec<(f64, usize, usize)> = Vec::new();
        for (i, l) in r.levels.iter().enumerate() {
            let Some(h) = l.h_free_boundary else { continue };
            match plateaus.last_mut() {
                Some(p) if p.0 == h => p.2 = i,
                _ => plateaus.push((h, i, i)),
            }
        }
        let fit = |f: fn(&model::level::record::LevelRecord) -> f64| {
            let pts: Vec<(f64, f64)> =
                plateaus.iter().map(|p| (p.0, f(&r.levels[p.2]))).filter(|p| p.1 > 1e-14).map(|p| (p.0.ln(), p.1.ln())).collect();
            model::base::stats::fit_line(&pts)
        };
        // largest change of eta_6 + eta_7 within a plateau of at least two levels
        let within = plateaus
            .iter()
            .filter(|p| p.2 > p.1)
            .map(|p| {
                let v: Vec<f64> = (p.1..=p.2).map(|i| r.levels[i].terms.eta6 + r.levels[i].terms.eta7).collect();
                v.iter().cloned().fold(0.0, f64::max) / v.iter().cloned().fold(f64::INFINITY, f64::min)
            })
            .fold(1.0, f64::max);
        (fit(|l| l.terms.eta6), fit(|l| l.terms.eta7), plateaus, within)
    });
    let reported = Criterion::Reported { why: "the paper claims NDF^-1.5 for eta_6, eta_7 (Fig. 4b); this row measures them against h_fb instead, which is no test of that claim (7.2-rates judges it)".into() };
    let measured = matches!(&fb_edge, Some((_, _, p, _)) if !p.is_empty());
    Claim {
        fragile: None,
        id: "7.2-eta6-eta7 (beyond the paper)".into(),
        summary: Summary {
            topic: "Ex. 7.2: eta_6, eta_7 at the free boundary".into(),
            paper: "at NDF^-1.5 (Fig. 4b); here against h_fb",
            headline: match &fb_edge {
                Some((Some(e6), Some(e7), p, _)) if !p.is_empty() => format!(
                    "eta6 ~ h_fb^({:.2} ± {:.2}), eta7 ~ h_fb^({:.2} ± {:.2}) ({})",
                    e6.slope,
                    e6.half_width,
                    e7.slope,
                    e7.half_width,
                    source(a72)
                ),
                _ => "n/a".into(),
            },
        },
        claim: "Ex. 7.2: eta_6 and eta_7 live on the contact edge straddling each free-boundary point (nodes neither all active nor all inactive; its length h_fb): slope of log eta against log h_fb, one point per plateau of h_fb".into(),
        measured: match &fb_edge {
            Some((e6, e7, plateaus, within)) if !plateaus.is_empty() => format!(
                "h_fb over the levels: {}; eta6 ~ h_fb^({}); eta7 ~ h_fb^({}); while h_fb stays constant eta6 + eta7 change by at most a factor {within:.2}: they plateau with it, and stagnate in NDF",
                plateaus.iter().map(|p| format!("{:.1e} (levels {}–{})", p.0, p.1, p.2)).collect::<Vec<_>>().join(", "),
                e6.map(|f| format!("{:.2} ± {:.2}", f.slope, f.half_width)).unwrap_or("n/a".into()),
                e7.map(|f| format!("{:.2} ± {:.2}", f.slope, f.half_width)).unwrap_or("n/a".into()),
            ),
            _ => "no data (records without h_free_boundary: rerun ex72)".into(),
        },
        verdict: reported.verdict(Kind::Beyond, measured.then_some(Evidence::Bool(true)).as_ref()),
        criterion: reported,
        kind: Kind::Beyond,
        row: RowKind::Measured,
        terms: vec![],
    }
}

/// Row of Example 7.2, per contact term: the adaptive mesh is refined near the corners where the
/// clamped side meets the free sides (Fig. 3b), on the last saved mesh of the term's run of the
/// study `ex72` (or `contact_term_ablation`; `ex72_large` saves no meshes).
fn corner_refinement(ctx: &Ctx, t: &TermRun) -> std::io::Result<Claim> {
    let p = rows::problem(problem_names::EX72);
    let k = crate::analysis::claims::terms::ALL.iter().position(|x| *x == t.terms[0]).expect("a contact term");
    let mesh_role = p.fallback[k];
    let mut judged: Option<bool> = None;
    let mut parts = Vec::new();
    if let Some(role) = mesh_role {
        let id = ctx.roles.id(role).unwrap_or(role.name);
        if let Some(m) = latest_mesh(ctx.shelf, role.study, id)? {
            let mut all = true;
            for (name, pt) in [("corner (0, 0)", [0.0, 0.0]), ("corner (0, 1)", [0.0, 1.0])] {
                let (inner, ring) = refinement::corner(&m, pt, CORNER_NEAR, CORNER_RING);
                all &= inner < ring;
                parts.push(format!(
                    "{name}: h_min {inner:.1e} within {CORNER_NEAR}, {ring:.1e} at {CORNER_NEAR}–{CORNER_RING} → {}",
                    if inner < ring { "refinement centre" } else { "no refinement centre" }
                ));
            }
            judged = Some(all);
            parts.insert(0, format!("{}/{id} level {} (NDF {})", role.study, m.level, m.ndof));
        }
    }
    let mesh = mesh_role.map_or("no run with saved meshes".into(), |r| ctx.roles.source(r));
    let test = Criterion::Test {
        passes_if: format!(
            "at both corners (0, 0) and (0, 1) of the last saved mesh of {mesh} the smallest element within {CORNER_NEAR} is smaller than every element at {CORNER_NEAR}–{CORNER_RING}"
        ),
        open_if_not: false,
    };
    Ok(Claim {
        fragile: None,
        id: format!("7.2-refinement-corners{}", t.suffix()),
        summary: Summary {
            topic: format!("Ex. 7.2: refinement at the corners{}", t.suffix()),
            paper: "refined at the Dirichlet/Neumann corners (Fig. 3b)",
            headline: match judged {
                Some(true) => format!("both corners refinement centres ({mesh})"),
                Some(false) => format!("not both corners refinement centres ({mesh})"),
                None => "n/a".into(),
            },
        },
        claim: format!(
            "Ex. 7.2: the adaptive mesh is refined near the corners where Dirichlet meets Neumann (Fig. 3b): at each corner, smaller elements within {CORNER_NEAR} than at {CORNER_NEAR}–{CORNER_RING} (contact term: {})",
            t.names()
        ),
        measured: if parts.is_empty() { "no data".into() } else { format!("{}{}", parts.join("; "), t.note_text()) },
        verdict: test.verdict(Kind::Paper, judged.map(Evidence::Bool).as_ref()),
        criterion: test,
        kind: Kind::Paper,
        row: RowKind::Finding,
        terms: t.terms.clone(),
    })
}
