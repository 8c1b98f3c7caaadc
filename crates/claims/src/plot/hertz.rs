//! Figures of the `hertz` study (an elastic cylinder on a rigid flat, against Hertz's solution),
//! from its records and mesh snapshots only.
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `hertz_pressure` | `hertz`, the largest saved level of every run | the contact pressure p_h at the contact nodes (`ContactSample::pressure`) against Hertz's p(x) = p0 sqrt(1 - x^2/a^2) at the run's own contact force F, in the units x / a and p / p0 so that both loads lie on one curve, and beside it the deviation (p_h - p) / p0 at the active nodes, vertices (solid) and edge midpoints (dashed) as separate lines; the legend gives F, a and p0 with their deviations from Hertz's |
//! | `hertz_mesh` | `hertz`, the largest saved level of run `adaptive` | the mesh near the contact, |x| <= 1.5a, 0 <= y <= 0.75a at equal scale (edges clipped at the window; contact nodes denser than the pixels as red (active) and blue (inactive) bands, the ends of the active set marked), with Hertz's half-width dashed |

use super::render::{LineFigure, Series};
use super::{Built, Figure, Marker, PALETTE, Panel, Style, YScale, mesh_figure, runs};
use crate::analysis::hertz::{self, Hertz};
use crate::analysis::roles::{self, Roles};
use anyhow::Context;
use plotters::style::RGBColor;
use store::records::{MeshSnapshot, RunRecord};
use store::study::store::Shelf;

const STUDY: &str = roles::HERTZ_AS_WRITTEN.study;

/// A run's Hertz solution (from its problem) and its finest saved snapshot.
fn finest(shelf: &Shelf, r: &RunRecord) -> anyhow::Result<Option<(Hertz, MeshSnapshot)>> {
    let Some(&level) = shelf.saved_levels(STUDY, &r.run.id)?.last() else {
        return Ok(None);
    };
    let problem = shelf.problem(STUDY, &r.run)?;
    let h = hertz::for_problem(problem.as_ref())
        .with_context(|| format!("problem {} has no circular contact group '{}'", r.run.problem, hertz::CONTACT_GROUP))?;
    let snap = shelf.mesh(STUDY, &r.run.id, level).with_context(|| format!("reading the mesh snapshot of {} level {level}", r.run.id))?;
    Ok(Some((h, snap)))
}

fn pct(v: f64) -> String {
    format!("{:+.2}%", 100.0 * v)
}

pub(super) fn hertz_pressure(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let x_desc = "x / a  (a: Hertz's half-width at the computed force F)";
    let mut profile = Panel::new("pressure p_{h} at the contact nodes and Hertz's", x_desc, "p / p_{0}  (p_{0} = 2F / πa)");
    let mut deviation = Panel::new("deviation from Hertz's pressure", x_desc, "(p_{h} − p) / p_{0}");
    for p in [&mut profile, &mut deviation] {
        p.x_log = false;
        p.y_scale = YScale::Auto;
    }
    let curve: Vec<(f64, Option<f64>)> =
        (0..=240).map(|k| -1.5 + 3.0 * k as f64 / 240.0).map(|s| (s, Some((1.0 - s * s).max(0.0).sqrt()))).collect();
    profile.series.push(Series {
        label: "Hertz: √(1 − x²/a²)".to_string(),
        points: curve,
        style: Style { color: RGBColor(0, 0, 0), marker: Marker::None, dashed: true, filled: false, large: false },
        roundoff: false,
    });
    for (k, r) in runs.iter().enumerate() {
        let Some((h, snap)) = finest(shelf, r)? else { continue };
        let Some(c) = hertz::compare(&h, &snap.contact_nodes) else {
            profile.notes.push(format!("{}: contact zone not resolved at level {}", r.run.id, snap.level));
            continue;
        };
        let (a, p0) = (c.hertz_half_width, c.hertz_peak_pressure);
        let mut nodes: Vec<_> = snap.contact_nodes.iter().filter(|n| ((n.x[0] - c.centre) / a).abs() <= 1.5).collect();
        nodes.sort_by(|u, v| u.x[0].total_cmp(&v.x[0]));
        // thousands of nodes: a line, no markers
        let style = Style { color: PALETTE[k % PALETTE.len()], marker: Marker::None, dashed: false, filled: true, large: false };
        let s = |n: &&model::level::sample::ContactSample| (n.x[0] - c.centre) / a;
        profile.series.push(Series {
            label: format!(
                "{}, NDF {}: F = {:.4}, a_{{h}} = {:.5} ({}), p_{{0,h}} = {:.3} ({})",
                r.run.id,
                snap.ndof,
                c.force,
                c.half_width,
                pct(c.half_width_deviation()),
                c.peak_pressure,
                pct(c.peak_deviation())
            ),
            points: nodes.iter().map(|n| (s(n), Some(n.pressure / p0))).collect(),
            style,
            roundoff: false,
        });
        // vertices and edge midpoints apart: their nodal pressures lambda_p / int psi_p carry
        // different errors (the P2 basis functions of the two kinds differ), and one line through
        // both zigzags between them
        let vertices: std::collections::HashSet<[u64; 2]> = snap.vertices.iter().map(|v| v.map(f64::to_bits)).collect();
        for (vertex, kind, dashed) in [(true, "vertices", false), (false, "midpoints", true)] {
            deviation.series.push(Series {
                label: if vertex {
                    format!("{} (a/R = {:.3}), {kind}: max {:.3}", r.run.id, a / h.radius, c.profile_deviation)
                } else {
                    format!("{}, {kind}", r.run.id)
                },
                points: nodes
                    .iter()
                    .filter(|n| n.active && vertices.contains(&n.x.map(f64::to_bits)) == vertex)
                    .map(|n| (s(n), Some((n.pressure - h.pressure(c.force, n.x[0] - c.centre)) / p0)))
                    .collect(),
                style: style.dashed(dashed),
                roundoff: false,
            });
        }
    }
    if profile.series.len() < 2 {
        return Ok(Err(format!("no mesh snapshot of a run of study {STUDY}")));
    }
    Ok(Ok(Figure::Lines(LineFigure {
        title: Some("Hertz: an elastic cylinder on a rigid flat (plane strain), finest adaptive meshes".to_string()),
        panels: vec![profile, deviation],
        columns: None,
    })))
}

pub(super) fn hertz_mesh(shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    let runs = match runs(shelf, STUDY)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let Some(r) = roles.find(&runs, roles::HERTZ_AS_WRITTEN) else {
        return Ok(Err(format!("study {STUDY} has no run {}", roles.source(roles::HERTZ_AS_WRITTEN))));
    };
    let Some((h, mut snap)) = finest(shelf, r)? else {
        return Ok(Err(format!("no mesh snapshot of run {} of study {STUDY}", r.run.id)));
    };
    let Some(c) = hertz::compare(&h, &snap.contact_nodes) else {
        return Ok(Err(format!("run {}: the contact zone is not resolved at level {}", r.run.id, snap.level)));
    };
    let a = c.hertz_half_width;
    // the contact and its ends: |x| <= 1.5 a, y <= 0.75 a
    let (x0, x1, y1) = (c.centre - 1.5 * a, c.centre + 1.5 * a, 0.75 * a);
    let (n_t, n_v, level, ndof) = (snap.triangles.len(), snap.vertices.len(), snap.level, snap.ndof);
    // the triangles that reach into the window (the figure clips their edges at its border)
    let reaches = |t: &[usize; 3]| {
        let v = t.map(|k| snap.vertices[k]);
        let (lo, hi) = (
            |i: usize| v.iter().map(|p| p[i]).fold(f64::INFINITY, f64::min),
            |i: usize| v.iter().map(|p| p[i]).fold(f64::NEG_INFINITY, f64::max),
        );
        hi(0) >= x0 && lo(0) <= x1 && lo(1) <= y1
    };
    snap.triangles.retain(|t| reaches(t));
    let mut fig = mesh_figure(&snap, "");
    fig.bbox = [x0, 0.0, x1, y1];
    fig.title = format!("Hertz: {} mesh near the contact, level {level}, NDF = {ndof}", r.run.id);
    fig.n_triangles = n_t;
    fig.n_vertices = n_v;
    fig.vlines.push((c.centre - a, format!("Hertz's a = {a:.4}")));
    fig.vlines.push((c.centre + a, String::new()));
    Ok(Ok(Figure::Mesh(fig)))
}
