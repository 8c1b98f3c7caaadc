//! The figure `estimator_repair`: a 2 x 2 grid with a panel per problem of the CLAIMS row
//! `estimator-repair`, drawing exactly the runs that row reads ([`Stored::fitted`]): the
//! repaired run, the run without full-contact nodes, eta_5 as written, uniform refinement and the
//! repaired run with l_h = 1. A series with the same values as another (the repaired run's error
//! and that of the run without full-contact nodes, where their meshes agree at every level) is
//! marked and named in the legend as in every figure ([`super::show_coincident`]).

use super::render::{LineFigure, MARKERS, Panel};
use super::{Built, ERR, ESTIMATE, Figure, NDF_DESC, PALETTE, Style, problem_title, series, slope};
use crate::analysis::claims::repair::{Fitted, PROBLEMS, Stored};
use crate::analysis::roles::Roles;
use anyhow::Context;
use store::records::RunRecord;
use store::study::store::Shelf;

/// "deep/ex71_repaired"
fn name(r: &RunRecord) -> String {
    format!("{}/{}", r.study, r.run.id)
}

/// One problem's panel.
fn panel(f: &Fitted) -> Option<Panel> {
    let repaired = f.repaired?;
    let mut p = Panel::new(
        format!("{} ({})", problem_title(f.problem), repaired.study),
        NDF_DESC,
        format!("error {ERR} (solid) and {ESTIMATE} (dashed)"),
    );
    let roles: Vec<(&str, &RunRecord)> = [
        ("repaired", Some(repaired)),
        ("without full-contact nodes", f.without_full_contact),
        ("η_{5} as written", f.as_written),
        ("uniform", f.uniform),
        ("repaired, l_{h} = 1", f.l1),
    ]
    .into_iter()
    .filter_map(|(n, r)| Some((n, r?)))
    .collect();
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
