//! The figure `estimator_repair`: a 2 x 2 grid with a panel per problem of the CLAIMS row
//! `estimator-repair`, drawing exactly the runs that row reads ([`Stored::fitted`]): the
//! repaired run, eta_5 as written, uniform refinement and the repaired run with l_h = 1. The run
//! without full-contact nodes is drawn only where it differs from the repaired run; where the two
//! coincide (same NDF and errors at every common level) a note says so instead of hiding one
//! curve under the other.

use super::render::{LineFigure, MARKERS, Panel};
use super::{Built, ERR, ESTIMATE, Figure, NDF_DESC, PALETTE, Style, problem_title, series, slope};
use crate::analysis::claims::COINCIDE_REL;
use crate::analysis::claims::repair::{Fitted, PROBLEMS, Stored};
use crate::analysis::roles::Roles;
use crate::records::RunRecord;
use crate::study::store::Shelf;
use anyhow::Context;

/// "deep/ex71_repaired"
fn name(r: &RunRecord) -> String {
    format!("{}/{}", r.study, r.run.id)
}

/// Same NDF and errors at every common level (to [`COINCIDE_REL`] relative, as the CLAIMS row
/// compares them), and at least one level.
fn coincide(a: &RunRecord, b: &RunRecord) -> bool {
    let n = a.levels.len().min(b.levels.len());
    n > 0
        && a.levels.iter().zip(&b.levels).all(|(x, y)| {
            x.ndof == y.ndof
                && match (x.err_quadrature, y.err_quadrature) {
                    (Some(p), Some(q)) => (p - q).abs() <= COINCIDE_REL * p.abs().max(q.abs()),
                    (p, q) => p.is_none() && q.is_none(),
                }
        })
}

/// One problem's panel.
fn panel(f: &Fitted) -> Option<Panel> {
    let repaired = f.repaired?;
    let mut p = Panel::new(
        format!("{} ({})", problem_title(f.problem), repaired.study),
        NDF_DESC,
        format!("error {ERR} (solid) and {ESTIMATE} (dashed)"),
    );
    let mut roles: Vec<(&str, &RunRecord)> = vec![("repaired", repaired)];
    match f.without_full_contact {
        Some(w) if coincide(repaired, w) => {
            p.notes.push(format!("{} = {} at every level (not drawn)", name(w), name(repaired)));
        }
        Some(w) => roles.push(("without full-contact nodes", w)),
        None => {}
    }
    roles.extend(
        [("η_{5} as written", f.as_written), ("uniform", f.uniform), ("repaired, l_{h} = 1", f.l1)]
            .into_iter()
            .filter_map(|(n, r)| Some((n, r?))),
    );
    for (k, (role, r)) in roles.iter().enumerate() {
        let st = Style { color: PALETTE[k % PALETTE.len()], marker: MARKERS[k % MARKERS.len()], dashed: false, filled: true, large: false };
        if r.levels.iter().any(|l| l.err_quadrature.is_some()) {
            p.series.push(series(r, format!("error, {role} ({})", name(r)), st, |l| l.err_quadrature));
        }
        p.series.push(series(r, format!("estimate, {role}"), st.dashed(true), |l| Some(l.terms.estimate)));
    }
    if !repaired.levels.iter().any(|l| l.err_quadrature.is_some()) {
        p.notes.push("no error measured: the row does not judge this problem".into());
    } else {
        p.slopes.push(slope());
    }
    Some(p)
}

pub(super) fn estimator_repair(shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    let stored = Stored::read(shelf, roles)
        .with_context(|| format!("reading the runs of the estimator-repair row under {}", shelf.root().display()))?;
    let panels: Vec<Panel> = PROBLEMS.iter().filter_map(|p| panel(&stored.fitted(p))).collect();
    if panels.is_empty() {
        return Ok(Err("no repaired run stored (studies estimator_repair, deep, ex72_large)".to_string()));
    }
    Ok(Ok(Figure::Lines(LineFigure {
        title: Some("The repaired estimator: the runs of the CLAIMS row estimator-repair".to_string()),
        panels,
        columns: Some(2),
    })))
}
