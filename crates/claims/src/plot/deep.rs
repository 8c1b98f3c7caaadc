//! Figures of the `deep` study (Example 7.1 and fb to about 1e7 unknowns), from its records only.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `deep_error` | `deep`, all runs | one panel per problem (7.1, fb): `err_quadrature` vs NDF for eta_5 as written, without full-contact nodes, repaired (adaptive) and uniform refinement, a style per run, log-log, NDF^-3/2 below all; the rows `7.1-error-rate`, `fb-error-rate` of CLAIMS fit the last two decades |
//! | `deep_floor` | `deep`, `*_as_written` and `*_uniform` | one panel per problem: the error, the estimate C_0 eta_h and the round-off floor of u_h (`roundoff_floor`, dotted: 10x it, below which CLAIMS fits no error) against NDF |

use super::render::{LineFigure, MARKERS, Panel};
use super::{Built, ERR, ESTIMATE, Figure, NDF_DESC, PALETTE, Style, runs, series, slope};
use crate::analysis::problem_names;
use crate::analysis::roles::{self, Roles};
use crate::analysis::verdict::FLOOR_MARGIN;
use store::study::store::Shelf;

const STUDY: &str = roles::DEEP_EX71_AS_WRITTEN.study;

pub(super) fn deep_error(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut panels = Vec::new();
    for (problem, title) in [(problem_names::EX71, "Example 7.1"), (problem_names::FB, "free boundary (fb)")] {
        let mut p = Panel::new(format!("{title}: error vs NDF to 1e7"), NDF_DESC, format!("error {ERR}"));
        for (k, r) in runs.iter().filter(|r| r.run.problem == problem).enumerate() {
            let style = Style {
                color: PALETTE[k % PALETTE.len()],
                marker: MARKERS[k % MARKERS.len()],
                dashed: k % 2 == 1,
                filled: true,
                large: false,
            };
            let label = r.run.id.strip_prefix(&format!("{problem}_")).unwrap_or(&r.run.id).replace('_', " ");
            p.series.push(series(r, label, style, |l| l.err_quadrature));
        }
        p.slopes.push(slope());
        if p.has_data() {
            panels.push(p);
        }
    }
    if panels.is_empty() {
        return Ok(Err(format!("study {STUDY} has no levels")));
    }
    Ok(Ok(Figure::Lines(LineFigure { title: Some("Deep runs: the error over two decades and more".to_string()), panels, columns: None })))
}

/// Error, estimate and round-off floor together: where the error of a deep run would meet
/// [`FLOOR_MARGIN`] x the floor, its fits end.
pub(super) fn deep_floor(shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    let runs = match runs(shelf, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut panels = Vec::new();
    let problems = [
        ("Example 7.1", [(roles::DEEP_EX71_AS_WRITTEN, "as written"), (roles::DEEP_EX71_UNIFORM, "uniform")]),
        ("free boundary (fb)", [(roles::DEEP_FB_AS_WRITTEN, "as written"), (roles::DEEP_FB_UNIFORM, "uniform")]),
    ];
    for (title, variants) in problems {
        let mut p =
            Panel::new(format!("{title}: error, estimate and round-off floor"), NDF_DESC, "sup-norm of the displacement".to_string());
        for (k, (role, label)) in variants.into_iter().enumerate() {
            let Some(r) = roles.find(&runs, role) else { continue };
            let style = |i: usize, dashed: bool, filled: bool| Style {
                color: PALETTE[(3 * k + i) % PALETTE.len()],
                marker: MARKERS[(3 * k + i) % MARKERS.len()],
                dashed,
                filled,
                large: false,
            };
            p.series.push(series(r, format!("{label}: error {ERR}"), style(0, false, true), |l| l.err_quadrature));
            if r.run.refine != model::settings::adapt::Refine::Uniform {
                p.series.push(series(r, format!("{label}: {ESTIMATE}"), style(1, false, false), |l| Some(l.terms.estimate)));
            }
            p.series.push(series(r, format!("{label}: {FLOOR_MARGIN} × round-off floor"), style(2, true, false), |l| {
                Some(FLOOR_MARGIN * l.roundoff_floor).filter(|f| *f > 0.0)
            }));
        }
        if p.has_data() {
            panels.push(p);
        }
    }
    if panels.is_empty() {
        return Ok(Err(format!("study {STUDY} has no levels")));
    }
    Ok(Ok(Figure::Lines(LineFigure {
        title: Some("Deep runs: error, estimate and the round-off floor of u_h".to_string()),
        panels,
        columns: None,
    })))
}
