//! Mesh figures: the triangles inside a window at equal scale on both axes, the contact nodes by
//! state, the obstacle's kinks and vertical marks (a free boundary, Hertz's half-width), and a
//! legend beside the plot (a window about as tall as wide) or under it (a wide window).

use super::{FS_DESC, FS_LEGEND, FS_TICK, FS_TITLE};
use super::{Marker, PALETTE, Style, draw_marker, titled};
use crate::plot::axis::Axis;
use crate::plot::font::{DrawResult, font};
use crate::plot::rich::{self, Metrics};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

#[derive(Clone, Debug)]
pub(crate) struct MeshFigure {
    pub title: String,
    /// Mesh edges joined into polylines (fewer SVG elements than one per edge); drawn clipped to
    /// `bbox`.
    pub edges: Vec<Vec<(f64, f64)>>,
    pub active: Vec<(f64, f64)>,
    pub inactive: Vec<(f64, f64)>,
    pub kinks: Vec<(f64, f64)>,
    /// Vertical lines x = c across the mesh, dashed, with their legend text (a free boundary).
    pub vlines: Vec<(f64, String)>,
    /// The window drawn: the vertices' bounding box, or a part of it.
    pub bbox: [f64; 4],
    pub n_triangles: usize,
    pub n_vertices: usize,
}

impl MeshFigure {
    /// The axes' ranges: `bbox` and a margin of 2.5% of its larger side.
    fn window(&self) -> [f64; 4] {
        let [x0, y0, x1, y1] = self.bbox;
        let pad = 0.025 * (x1 - x0).max(y1 - y0).max(1e-12);
        [x0 - pad, y0 - pad, x1 + pad, y1 + pad]
    }

    /// The legend beside a window about as tall as wide, under a wide one.
    fn legend_beside(&self) -> bool {
        let w = self.window();
        w[2] - w[0] <= 1.6 * (w[3] - w[1])
    }

    /// Legend rows at most (the actual rows depend on how densely the nodes are drawn).
    fn legend_rows(&self) -> i32 {
        4 + self.vlines.iter().filter(|v| !v.1.is_empty()).count() as i32
    }

    /// The picture's size for `width` pixels: a wide window with its legend under it is only as
    /// tall as it needs, anything else is `width` x 650.
    pub fn size(&self, width: u32) -> (u32, u32) {
        if self.legend_beside() {
            return (width, 650);
        }
        let w = self.window();
        let plot = f64::from(width as i32 - 2 * MARGIN - Y_LABELS) * (w[3] - w[1]) / (w[2] - w[0]);
        let title = 50;
        (width, (title + plot as i32 + 2 * MARGIN + X_LABELS + self.legend_rows() * ROW + 20).clamp(300, 650) as u32)
    }
}

/// What a legend row shows before its text.
enum Mark {
    Marker(Style, i32),
    Band(RGBColor),
    Dashes,
    Nothing,
}

const MARGIN: i32 = 14;
const X_LABELS: i32 = 50;
const Y_LABELS: i32 = 62;
const LEGEND_W: i32 = 270;
const ROW: i32 = 26;
/// Contact nodes closer than this (pixels, median) are drawn as bands instead of markers.
const DENSE_PX: f64 = 7.0;
const VERTEX_R: i32 = 3;

const INACTIVE: Style = Style { color: RGBColor(31, 119, 180), marker: Marker::Circle, dashed: false, filled: true, large: false };
const ACTIVE: Style = Style { color: RGBColor(214, 39, 40), marker: Marker::Circle, dashed: false, filled: true, large: false };
const KINK: Style = Style { color: BLACK, marker: Marker::Diamond, dashed: false, filled: false, large: false };

pub(super) fn render_mesh<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, m: &MeshFigure, metrics: Metrics) -> anyhow::Result<()> {
    let body = titled(root, root, &m.title, FS_TITLE + 2.0, metrics)?;
    let (w, h) = body.dim_in_pixel();
    let [_, y0, _, y1] = m.bbox;
    let (window, beside, n_rows) = (m.window(), m.legend_beside(), m.legend_rows());
    let (dx, dy) = (window[2] - window[0], window[3] - window[1]);
    let (avail_w, avail_h) = if beside {
        (w as i32 - 2 * MARGIN - Y_LABELS - LEGEND_W, h as i32 - 2 * MARGIN - X_LABELS)
    } else {
        (w as i32 - 2 * MARGIN - Y_LABELS, h as i32 - 2 * MARGIN - X_LABELS - n_rows * ROW - 10)
    };
    // equal scale on both axes
    let scale = (f64::from(avail_w.max(50)) / dx).min(f64::from(avail_h.max(50)) / dy);
    let plot_w = (dx * scale) as i32 + 2 * MARGIN + Y_LABELS;
    let plot_h = (dy * scale) as i32 + 2 * MARGIN + X_LABELS;
    let left = if beside { 0 } else { (w as i32 - plot_w) / 2 };
    let (bx, by) = body.get_base_pixel();
    let area = body.shrink((left, 0), (plot_w, plot_h));
    let mut chart = ChartBuilder::on(&area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(Axis::linear(window[0], window[2]), Axis::linear(window[1], window[3]))
        .drawn()?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x")
        .y_desc("y")
        .label_style(font(FS_TICK))
        .axis_desc_style(font(FS_DESC))
        .set_all_tick_mark_size(6)
        .draw()
        .drawn()?;
    let edge = RGBColor(40, 40, 40).mix(0.85).stroke_width(1);
    let clipped = m.edges.iter().flat_map(|c| clip_polyline(c, window));
    chart.draw_series(clipped.map(|c| PathElement::new(c, edge))).drawn()?;

    let at = |p: &(f64, f64)| chart.backend_coord(p);
    let contact = contact_nodes(m, window);
    let dense = median_gap(&contact.iter().map(|(p, _)| at(p)).collect::<Vec<_>>()) < DENSE_PX;
    if dense {
        draw_bands(root, &contact, &at)?;
    } else {
        for (p, active) in &contact {
            draw_marker(root, at(p), if *active { ACTIVE } else { INACTIVE }, VERTEX_R)?;
        }
    }
    for p in &m.kinks {
        draw_marker(root, at(p), KINK, 7)?;
    }
    let vline = PALETTE[3].stroke_width(2);
    for (x, _) in &m.vlines {
        chart.draw_series(DashedLineSeries::new(vec![(*x, y0), (*x, y1)], 8, 5, vline)).drawn()?;
    }

    let origin = if beside { (bx + plot_w + 10, by + MARGIN + 10) } else { (bx + left + MARGIN + Y_LABELS, by + plot_h + 4) };
    let n_active = contact.iter().filter(|c| c.1).count();
    draw_legend(root, &legend(m, dense, n_active, contact.len() - n_active), origin, metrics)
}

/// The contact nodes inside `window` in order along the contact boundary (by x, or by y where
/// the nodes spread further in y), each with its state.
fn contact_nodes(m: &MeshFigure, window: [f64; 4]) -> Vec<((f64, f64), bool)> {
    let inside = |p: &(f64, f64)| p.0 >= window[0] && p.0 <= window[2] && p.1 >= window[1] && p.1 <= window[3];
    let mut nodes: Vec<_> =
        m.active.iter().map(|p| (*p, true)).chain(m.inactive.iter().map(|p| (*p, false))).filter(|(p, _)| inside(p)).collect();
    let spread = |f: fn(&(f64, f64)) -> f64| {
        let v = nodes.iter().map(|(p, _)| f(p));
        v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
    };
    let by_x = spread(|p| p.0) >= spread(|p| p.1);
    nodes.sort_by(|(a, _), (b, _)| if by_x { a.0.total_cmp(&b.0) } else { a.1.total_cmp(&b.1) });
    nodes
}

/// The median distance in pixels between consecutive points (infinite for fewer than two).
fn median_gap(px: &[(i32, i32)]) -> f64 {
    let mut gaps: Vec<f64> = px.windows(2).map(|w| f64::from(w[1].0 - w[0].0).hypot(f64::from(w[1].1 - w[0].1))).collect();
    if gaps.is_empty() {
        return f64::INFINITY;
    }
    gaps.sort_by(f64::total_cmp);
    gaps[gaps.len() / 2]
}

/// Nodes denser than the pixels: each run of one state as a thick line, and a marker where the
/// state changes (the ends of the active set), so that neither merges into a bar of markers.
fn draw_bands<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    nodes: &[((f64, f64), bool)],
    at: &impl Fn(&(f64, f64)) -> (i32, i32),
) -> anyhow::Result<()> {
    for run in nodes.chunk_by(|a, b| a.1 == b.1) {
        let color = if run[0].1 { ACTIVE.color } else { INACTIVE.color };
        let px: Vec<(i32, i32)> = run.iter().map(|(p, _)| at(p)).collect();
        root.draw(&PathElement::new(px, color.stroke_width(4))).drawn()?;
    }
    for pair in nodes.windows(2).filter(|w| w[0].1 != w[1].1) {
        let end = if pair[0].1 { &pair[0] } else { &pair[1] };
        draw_marker(root, at(&end.0), ACTIVE, 4)?;
    }
    Ok(())
}

/// The legend rows; `n_active` and `n_inactive` count the contact nodes inside the window.
fn legend(m: &MeshFigure, dense: bool, n_active: usize, n_inactive: usize) -> Vec<(Mark, String)> {
    let fmt = |v: f64| {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let state = |style: Style, n: usize, what: &str| {
        if dense {
            (Mark::Band(style.color), format!("{what} contact nodes ({n})"))
        } else {
            (Mark::Marker(style, VERTEX_R), format!("{what} contact node ({n})"))
        }
    };
    let mut rows = vec![state(ACTIVE, n_active, "active"), state(INACTIVE, n_inactive, "inactive")];
    if dense {
        rows.push((Mark::Marker(ACTIVE, 4), "end of the active set".to_string()));
    }
    if !m.kinks.is_empty() {
        let kinks = m.kinks.iter().map(|&(x, y)| format!("({}, {})", fmt(x), fmt(y))).collect::<Vec<_>>().join(", ");
        rows.push((Mark::Marker(KINK, 7), format!("kink of the obstacle {kinks}")));
    }
    rows.push((Mark::Nothing, format!("{} triangles, {} vertices", m.n_triangles, m.n_vertices)));
    // lines without a text share the legend entry of the one before
    rows.extend(m.vlines.iter().filter(|v| !v.1.is_empty()).map(|v| (Mark::Dashes, v.1.clone())));
    rows
}

fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[(Mark, String)],
    (x, y): (i32, i32),
    metrics: Metrics,
) -> anyhow::Result<()> {
    for (k, (mark, text)) in rows.iter().enumerate() {
        let cy = y + ROW * k as i32 + ROW / 2;
        match mark {
            Mark::Marker(st, r) => draw_marker(root, (x + 12, cy), *st, *r)?,
            Mark::Band(color) => root.draw(&PathElement::new(vec![(x + 2, cy), (x + 22, cy)], color.stroke_width(4))).drawn()?,
            Mark::Dashes => {
                for (s0, s1) in [(x + 2, x + 9), (x + 14, x + 22)] {
                    root.draw(&PathElement::new(vec![(s0, cy), (s1, cy)], PALETTE[3].stroke_width(2))).drawn()?;
                }
            }
            Mark::Nothing => {}
        }
        rich::draw(root, text, FS_LEGEND, &BLACK, (HPos::Left, VPos::Center), (x + 30, cy), false, metrics)?;
    }
    Ok(())
}

/// The parts of a polyline inside the rectangle `[x0, y0, x1, y1]` (Liang–Barsky per segment;
/// consecutive inside pieces joined).
pub(super) fn clip_polyline(chain: &[(f64, f64)], r: [f64; 4]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut open = false;
    for s in chain.windows(2) {
        match clip_segment(s[0], s[1], r) {
            Some((a, b)) => {
                if !open || out.last().and_then(|c| c.last()) != Some(&a) {
                    out.push(vec![a]);
                }
                out.last_mut().expect("pushed above").push(b);
                open = b == s[1];
            }
            None => open = false,
        }
    }
    out
}

fn clip_segment(a: (f64, f64), b: (f64, f64), r: [f64; 4]) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, a.0 - r[0]), (dx, r[2] - a.0), (-dy, a.1 - r[1]), (dy, r[3] - a.1)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| {
        if t == 0.0 {
            a
        } else if t == 1.0 {
            b
        } else {
            (a.0 + t * dx, a.1 + t * dy)
        }
    };
    Some((at(t0), at(t1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_polyline_is_cut_at_the_window_and_kept_whole_inside_it() {
        let r = [0.0, 0.0, 1.0, 1.0];
        assert_eq!(clip_polyline(&[(0.2, 0.2), (0.5, 0.5), (0.8, 0.2)], r), vec![vec![(0.2, 0.2), (0.5, 0.5), (0.8, 0.2)]]);
        // leaves through the top and comes back: two pieces, the crossings on the edge
        let cut = clip_polyline(&[(0.0, 0.5), (0.5, 1.5), (1.0, 0.5)], r);
        assert_eq!(cut.len(), 2);
        assert_eq!(cut[0], vec![(0.0, 0.5), (0.25, 1.0)]);
        assert_eq!(cut[1], vec![(0.75, 1.0), (1.0, 0.5)]);
        assert!(clip_polyline(&[(2.0, 2.0), (3.0, 3.0)], r).is_empty());
    }

    #[test]
    fn the_median_gap_is_in_pixels() {
        assert_eq!(median_gap(&[(0, 0), (3, 4), (6, 8), (106, 8)]), 5.0);
        assert!(median_gap(&[(0, 0)]).is_infinite());
    }
}
