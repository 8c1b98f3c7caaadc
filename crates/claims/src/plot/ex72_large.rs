//! The error figures of the Example 7.2 studies with a reference solution: `ex72_large` (to about
//! 1e6 unknowns) and `ex72_rollers` (the left side on rollers, to about 3.7e5), from their
//! records only; the title gives the reference's size as the records store it.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `ex72_large_error` | `ex72_large`, all runs | two panels against NDF: the error `err_quadrature` on the whole square, and `err_contact` on Gamma_C, for eta_5 as written, without full-contact nodes, repaired (adaptive) and uniform refinement, NDF^-3/2 below all; the rows `7.2-error` and `7.2-error-away-from-corners` of CLAIMS fit them; the runs repaired and without full-contact nodes, with the same errors at every level, are drawn and named as every coinciding pair is ([`super::show_coincident`]) |
//! | `ex72_rollers_error` | `ex72_rollers`, all runs | the same two panels on rollers (no corners); the rows `7.2r-*` fit them |

use super::render::{LineFigure, MARKERS, Panel};
use super::{Built, ERR, Figure, NDF_DESC, PALETTE, Style, runs, series, slope};
use crate::analysis::studies::{self, Study};
use store::study::store::Shelf;

/// One Example 7.2 study's error figure: its study, the problem's name in the panels and the title.
struct Labels {
    study: Study,
    problem: &'static str,
    /// The second panel's region: Gamma_C ("away from the corners" where there are corners).
    contact: &'static str,
    title: &'static str,
}

pub(super) fn ex72_large_error(shelf: &Shelf) -> anyhow::Result<Built> {
    error_figure(
        shelf,
        Labels {
            study: studies::EX72_LARGE,
            problem: "Example 7.2",
            contact: "Gamma_C, away from the corners",
            title: "Example 7.2 deep: the error against a reference",
        },
    )
}

pub(super) fn ex72_rollers_error(shelf: &Shelf) -> anyhow::Result<Built> {
    error_figure(
        shelf,
        Labels {
            study: studies::EX72_ROLLERS,
            problem: "Example 7.2 on rollers",
            contact: "Gamma_C",
            title: "Example 7.2 on rollers: the error against a reference",
        },
    )
}

fn error_figure(shelf: &Shelf, labels: Labels) -> anyhow::Result<Built> {
    let runs = match runs(shelf, labels.study)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    type Field = fn(&model::level::record::LevelRecord) -> Option<f64>;
    let panels_of: [(&str, &str, Field); 2] =
        [("the whole square", "", |l| l.err_quadrature), (labels.contact, " on Γ_{C}", |l| l.err_contact)];
    let mut panels = Vec::new();
    for (title, axis, field) in panels_of {
        let mut p = Panel::new(format!("{}, error on {title}", labels.problem), NDF_DESC, format!("error {ERR}{axis}"));
        for (k, r) in runs.iter().enumerate() {
            let style = Style {
                color: PALETTE[k % PALETTE.len()],
                marker: MARKERS[k % MARKERS.len()],
                dashed: k % 2 == 1,
                filled: true,
                large: false,
            };
            p.series.push(series(r, r.run.id.replace('_', " "), style, field));
        }
        p.slopes.push(slope());
        if p.has_data() {
            panels.push(p);
        }
    }
    if panels.is_empty() {
        return Ok(Err(format!("study {} has no errors", labels.study)));
    }
    let title = match runs.iter().filter_map(|r| r.reference_ndof).max() {
        Some(n) => format!("{} of {:.1e} unknowns", labels.title, n as f64),
        None => labels.title.to_string(),
    };
    Ok(Ok(Figure::Lines(LineFigure { title: Some(title), panels, columns: None })))
}
