//! Figures of the `fb` study (the free-boundary problem with an exact solution, beyond the paper),
//! from its records only.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `fb_error` | `fb`, all runs | like Fig. 2(a): `err_quadrature` (solid, filled circles) and `estimate` (dashed, hollow squares) vs NDF, one colour per run, log-log; NDF^-3/2 below the first run's error; the legend gives each run's last contact zone [`zone_min`, `zone_max`] against [a, 1] |
//! | `fb_mesh` | `fb`, the largest saved level of the run of role `without-full-contact` (else of `as-written`) | the mesh as in Fig. 3(b) (same drawing), with the free boundary x = a dashed |

use super::{
    Built, ERR, ESTIMATE, Figure, Marker, NDF_DESC, PALETTE, Panel, Slope, SlopeAnchor, Style, mesh_figure, runs, series, single, slope,
};
use crate::analysis::roles::{self, Roles};
use anyhow::Context;
use model::problems::Fb;
use store::study::store::Shelf;

const STUDY: &str = roles::FB_AS_WRITTEN.study;

pub(super) fn fb_error(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut p = Panel::new(
        "Free boundary (fb, exact solution): error and estimate vs NDF",
        NDF_DESC,
        format!("error {ERR} (solid) and {ESTIMATE} (dashed)"),
    );
    for (k, r) in runs.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let id = &r.run.id;
        if r.levels.iter().any(|l| l.err_quadrature.is_some()) {
            p.series.push(series(
                r,
                format!("error, {id}"),
                Style { color, marker: Marker::Circle, dashed: false, filled: true, large: false },
                |l| l.err_quadrature,
            ));
        }
        p.series.push(series(
            r,
            format!("estimate, {id}"),
            Style { color, marker: Marker::Square, dashed: true, filled: false, large: false },
            |l| Some(l.terms.estimate),
        ));
    }
    for r in &runs {
        if let Some(l) = r.levels.last() {
            let zone = match (l.zone_min, l.zone_max) {
                (Some(a), Some(b)) => format!("[{a:.5}, {b}]"),
                _ => "empty".to_string(),
            };
            p.notes.push(format!("{}: contact zone {zone} at NDF {}", r.run.id, l.ndof));
        }
    }
    p.notes.push(format!("exact contact zone [a, 1], a = √2 − 1 = {:.5}", Fb::A));
    p.slopes.push(Slope { anchor: SlopeAnchor::Below(0), ..slope() });
    if !p.has_data() {
        return Ok(Err(format!("study {STUDY} has no levels")));
    }
    Ok(Ok(single(p)))
}

/// The finest saved mesh of the run without full-contact nodes, else of the run with eta_5 as
/// written (the meshes the row `fb-refinement` reads).
pub(super) fn fb_mesh(shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    let ids: Vec<&str> = [roles::FB_WFC, roles::FB_AS_WRITTEN].into_iter().filter_map(|role| roles.id(role)).collect();
    let mut found = None;
    for &run in &ids {
        if let Some(&l) = shelf.saved_levels(STUDY, run)?.last() {
            found = Some((run, l));
            break;
        }
    }
    let Some((run, level)) = found else {
        return Ok(Err(format!("no mesh snapshot of runs {} in {}", ids.join(" or "), shelf.meshes_folder(STUDY)?.display())));
    };
    let snap = shelf.mesh(STUDY, run, level).with_context(|| format!("reading the mesh snapshot of {run} level {level}"))?;
    let mut fig = mesh_figure(&snap, "");
    fig.title = format!("Free boundary (fb): {run} mesh at level {level}, NDF = {}", snap.ndof);
    fig.vlines.push((Fb::A, "free boundary x = a = √2 − 1".to_string()));
    Ok(Ok(Figure::Mesh(fig)))
}
