//! The figure of the `ex72_large` study (Example 7.2 to about 1e6 unknowns, errors against a
//! reference solution of 4.5e6), from its records only.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `ex72_large_error` | `ex72_large`, all runs | two panels against NDF: the error `err_quadrature` on the whole square, and `err_contact` on Gamma_C, for eta_5 as written, without full-contact nodes, repaired (adaptive) and uniform refinement, NDF^-3/2 below all; the rows `7.2-error` and `7.2-error-away-from-corners` of CLAIMS fit them |

use super::render::{LineFigure, MARKERS, Panel};
use super::{Built, ERR, Figure, NDF_DESC, PALETTE, Style, runs, series, slope};
use std::path::Path;

const STUDY: &str = "ex72_large";

pub(super) fn ex72_large_error(results: &Path) -> anyhow::Result<Built> {
    let runs = match runs(results, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    type Field = fn(&crate::records::LevelRecord) -> Option<f64>;
    let panels_of: [(&str, &str, Field); 2] =
        [("the whole square", "", |l| l.err_quadrature), ("Gamma_C, away from the corners", " on Γ_{C}", |l| l.err_contact)];
    let mut panels = Vec::new();
    for (title, axis, field) in panels_of {
        let mut p = Panel::new(format!("Example 7.2, error on {title}"), NDF_DESC, format!("error {ERR}{axis}"));
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
        return Ok(Err(format!("study {STUDY} has no errors")));
    }
    Ok(Ok(Figure::Lines(LineFigure {
        title: Some("Example 7.2 deep: the error against a reference of 4.5e6 unknowns".to_string()),
        panels,
        columns: None,
    })))
}
