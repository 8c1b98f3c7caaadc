//! Figures of the `hertz` study (an elastic cylinder on a rigid flat, against Hertz's solution),
//! from its records and mesh snapshots only.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `hertz_pressure` | `hertz`, the largest saved level of every run | the contact pressure p_h at the contact nodes (`ContactSample::pressure`) against Hertz's p(x) = p0 sqrt(1 - x^2/a^2) at the run's own contact force F, in the units x / a and p / p0 so that both loads lie on one curve; the legend gives F, a and p0 with their deviations from Hertz's |
//! | `hertz_mesh` | `hertz`, the largest saved level of run `adaptive` | the mesh near the contact, |x| <= 3a, 0 <= y <= 2a (active nodes red), with the Hertz half-width dashed |

use super::{Built, Figure, Marker, PALETTE, Panel, Style, YScale, mesh_figure, runs, saved_levels, single};
use crate::hertz::{self, Hertz};
use crate::records::{MeshSnapshot, RunRecord, StudyDir};
use anyhow::Context;
use plotters::style::RGBColor;
use std::path::Path;

const STUDY: &str = "hertz";

/// A run's Hertz solution (from its problem) and its finest saved snapshot.
fn finest(results: &Path, r: &RunRecord) -> anyhow::Result<Option<(Hertz, MeshSnapshot)>> {
    let dir = StudyDir::new(results, STUDY);
    let Some(level) = saved_levels(&dir, &r.run.id).into_iter().max() else {
        return Ok(None);
    };
    let problem = crate::study::stored_problem(results, STUDY, &r.run)?;
    let h = hertz::for_problem(problem.as_ref())
        .with_context(|| format!("problem {} has no circular contact group '{}'", r.run.problem, hertz::CONTACT_GROUP))?;
    let snap = dir.read_mesh(&r.run.id, level).with_context(|| format!("reading the mesh snapshot of {} level {level}", r.run.id))?;
    Ok(Some((h, snap)))
}

fn pct(v: f64) -> String {
    format!("{:+.2}%", 100.0 * v)
}

pub(super) fn hertz_pressure(results: &Path) -> anyhow::Result<Built> {
    let runs = match runs(results, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut p = Panel::new(
        "Hertz: contact pressure of a cylinder on a rigid flat (plane strain)",
        "x / a  (a: Hertz's half-width at the computed force F)",
        "p / p_{0}  (p_{0} = 2F / πa)",
    );
    p.x_log = false;
    p.y_scale = YScale::Auto;
    let curve: Vec<(f64, Option<f64>)> = (0..=240).map(|k| -1.5 + 3.0 * k as f64 / 240.0).map(|s| (s, Some((1.0 - s * s).max(0.0).sqrt()))).collect();
    p.series.push(super::render::Series {
        label: "Hertz: √(1 − x²/a²)".to_string(),
        points: curve,
        style: Style { color: RGBColor(0, 0, 0), marker: Marker::None, dashed: true, filled: false },
        roundoff: false,
    });
    for (k, r) in runs.iter().enumerate() {
        let Some((h, snap)) = finest(results, r)? else { continue };
        let Some(c) = hertz::compare(&h, &snap.contact_nodes) else {
            p.notes.push(format!("{}: contact zone not resolved at level {}", r.run.id, snap.level));
            continue;
        };
        let (a, p0) = (c.hertz_half_width, c.hertz_peak_pressure);
        let mut pts: Vec<(f64, f64)> =
            snap.contact_nodes.iter().map(|n| ((n.x[0] - c.centre) / a, n.pressure / p0)).filter(|q| q.0.abs() <= 1.5).collect();
        pts.sort_by(|u, v| u.0.total_cmp(&v.0));
        p.series.push(super::render::Series {
            label: format!("{}, level {}, NDF {}: F = {:.4}, a_{{h}} = {:.5} ({}), p_{{0,h}} = {:.3} ({})", r.run.id, snap.level, snap.ndof, c.force, c.half_width, pct(c.half_width_deviation()), c.peak_pressure, pct(c.peak_deviation())),
            points: pts.into_iter().map(|(x, y)| (x, Some(y))).collect(),
            style: Style { color: PALETTE[k % PALETTE.len()], marker: super::render::MARKERS[k % super::render::MARKERS.len()], dashed: false, filled: true },
            roundoff: false,
        });
        p.notes.push(format!("{}: Hertz a = {:.5}, p_{{0}} = {:.3}; max |p_{{h}} − p| / p_{{0}} = {:.3}", r.run.id, a, p0, c.profile_deviation));
    }
    if p.series.len() < 2 {
        return Ok(Err(format!("no mesh snapshot of a run of study {STUDY}")));
    }
    Ok(Ok(single(p)))
}

pub(super) fn hertz_mesh(results: &Path) -> anyhow::Result<Built> {
    let runs = match runs(results, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let Some(r) = runs.iter().find(|r| r.run.id == "adaptive").or(runs.first()) else {
        return Ok(Err(format!("study {STUDY} has no runs")));
    };
    let Some((h, mut snap)) = finest(results, r)? else {
        return Ok(Err(format!("no mesh snapshot of run {} of study {STUDY}", r.run.id)));
    };
    let Some(c) = hertz::compare(&h, &snap.contact_nodes) else {
        return Ok(Err(format!("run {}: the contact zone is not resolved at level {}", r.run.id, snap.level)));
    };
    let a = c.hertz_half_width;
    let inside = |v: [f64; 2]| (v[0] - c.centre).abs() <= 3.0 * a && v[1] <= 2.0 * a;
    let (n_t, n_v, level, ndof) = (snap.triangles.len(), snap.vertices.len(), snap.level, snap.ndof);
    snap.triangles.retain(|t| t.iter().any(|&v| inside(snap.vertices[v])));
    snap.contact_nodes.retain(|n| inside(n.x));
    let mut fig = mesh_figure(&snap, "");
    fig.bbox = [c.centre - 3.0 * a, 0.0, c.centre + 3.0 * a, 2.0 * a];
    fig.title = format!("Hertz: {} mesh near the contact, level {level}, NDF = {ndof} ({n_t} triangles, {n_v} vertices in all)", r.run.id);
    fig.n_triangles = n_t;
    fig.n_vertices = n_v;
    fig.vlines.push((c.centre - a, format!("Hertz half-width a = {a:.5} at F = {:.4}", c.force)));
    fig.vlines.push((c.centre + a, String::new()));
    Ok(Ok(Figure::Mesh(fig)))
}
