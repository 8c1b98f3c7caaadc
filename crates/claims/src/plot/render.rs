//! Drawing: a figure description (`Figure`, built from records in `mod.rs`) onto any plotters
//! backend. The same code renders the SVG and the PNG.
//!
//! Line panels: log x (NDF), log or linear y, one colour and marker shape per series, dashed
//! lines and hollow markers for secondary series, reference slopes dashed grey with their label
//! next to the line, horizontal guide lines (efficiency = 1), and a legend in a white box put in
//! the first corner of the plot (upper right, upper left, lower right, lower left) where it
//! covers no data; if every corner is taken, the y range is extended upwards once, by at most
//! half a decade (a quarter of a linear range), and if that is not enough the legend goes beside
//! the plot, on the right, or under it (whichever leaves the plot's shorter side longer): the
//! axes span the data, not the legend.
//! On a log axis, points with value 0 (or missing) are not drawn: the line breaks there and the
//! legend says how many levels were zero ("η₆ = 0 at all levels").

use super::axis::Axis;
use super::font::{DrawResult, font};
use super::rich::{self, Metrics};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

mod mesh;
mod panel;
pub(crate) use mesh::MeshFigure;

/// Reference slopes and grey legend text.
const GREY: RGBColor = RGBColor(110, 110, 110);

const FS_FIGURE_TITLE: f64 = 24.0;
const FS_TITLE: f64 = 20.0;
const FS_DESC: f64 = 17.0;
const FS_TICK: f64 = 15.0;
const FS_LEGEND: f64 = 15.0;
const FS_SLOPE: f64 = 16.0;
const MARKER: i32 = 5;
/// Pixels between the legend box and any curve, marker or label.
const LEGEND_CLEARANCE: i32 = 14;
const X_LABEL_AREA: i32 = 62;
const Y_LABEL_AREA: i32 = 96;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
    Cross,
    Plus,
    Star,
    /// No marker: a curve drawn from many points (a closed-form solution).
    None,
}

pub(crate) const MARKERS: [Marker; 8] =
    [Marker::Circle, Marker::Square, Marker::TriangleUp, Marker::Diamond, Marker::TriangleDown, Marker::Cross, Marker::Plus, Marker::Star];

/// Tableau-10 colours: distinct, and readable on white.
pub(crate) const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
];

#[derive(Clone, Copy, Debug)]
pub(crate) struct Style {
    pub color: RGBColor,
    pub marker: Marker,
    pub dashed: bool,
    pub filled: bool,
    /// Markers half as large again (and hollow): a series drawn under another that coincides
    /// with it stays visible around it.
    pub large: bool,
}

impl Style {
    /// Series number `i` of a panel: colour and marker cycle together.
    pub fn nth(i: usize) -> Self {
        Style { color: PALETTE[i % PALETTE.len()], marker: MARKERS[i % MARKERS.len()], dashed: false, filled: true, large: false }
    }
    pub fn dashed(mut self, dashed: bool) -> Self {
        self.dashed = dashed;
        self.filled = !dashed;
        self
    }
    /// Large hollow markers ([`Style::large`]).
    pub fn large(mut self) -> Self {
        self.large = true;
        self.filled = false;
        self
    }
    /// The marker radius for a base radius `r`.
    pub fn radius(&self, r: i32) -> i32 {
        if self.large { r * 2 } else { r }
    }
}

/// One curve: y per x (NDF); `None` is a missing value (e.g. no error measured at that level).
#[derive(Clone, Debug)]
pub(crate) struct Series {
    pub label: String,
    pub points: Vec<(f64, Option<f64>)>,
    pub style: Style,
    /// Some zeros stand for values below round-off (the legend says so).
    pub roundoff: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum YScale {
    /// Log if all values are positive and span more than a decade, else linear from 0.
    Auto,
    Log,
}

/// A reference line y = c x^rate, drawn over the finer half (in log NDF) of the data.
#[derive(Clone, Debug)]
pub(crate) struct Slope {
    pub rate: f64,
    pub label: String,
    pub anchor: SlopeAnchor,
}

/// Where a reference line goes: a factor 2.5 below (or above) the data it is compared with,
/// over the x range of the line.
#[derive(Clone, Copy, Debug)]
pub(crate) enum SlopeAnchor {
    /// Below series `i`.
    Below(usize),
    BelowAll,
    AboveAll,
}

/// A reference line placed: the series, its end points in data coordinates, above the data?
type PlacedSlope<'a> = (&'a Slope, [f64; 4], bool);

/// The slope triangle of a reference line `l` = [x0, y0, x1, y1] (log-log): its hypotenuse is the
/// part of the line between 68 % and 95 % of its length, its legs are horizontal (one unit of
/// run) and vertical (the rate), on the side of the line away from the data. Returns the corners
/// A (start of the hypotenuse), B (its end) and the right-angle corner C.
fn slope_triangle(l: [f64; 4], above: bool) -> [(f64, f64); 3] {
    let at = |t: f64| {
        let x = l[0] * (l[2] / l[0]).powf(t);
        let y = l[1] * (l[3] / l[1]).powf(t);
        (x, y)
    };
    let (a, b) = (at(0.68), at(0.95));
    // a falling line: below it the corner is under A, above it over B (and the other way round)
    let falling = l[3] < l[1];
    let c = if above == falling { (b.0, a.1) } else { (a.0, b.1) };
    [a, b, c]
}

/// The rate as the legs' label: "1.5", "2", "0.5".
fn rate_text(rate: f64) -> String {
    let r = rate.abs();
    if (r - r.round()).abs() < 1e-9 { format!("{}", r.round()) } else { format!("{r}") }
}

#[derive(Clone, Debug)]
pub(crate) struct HLine {
    pub y: f64,
    pub label: String,
}

#[derive(Clone, Debug)]
pub(crate) struct Panel {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub y_scale: YScale,
    /// Logarithmic x axis (NDF; the default) or linear (a coordinate, which may be negative).
    pub x_log: bool,
    pub series: Vec<Series>,
    pub slopes: Vec<Slope>,
    pub hlines: Vec<HLine>,
    /// Legend lines without a curve (e.g. "η₆ = η₇ = 0 at all levels (not shown)").
    pub notes: Vec<String>,
}

impl Panel {
    pub fn new(title: impl Into<String>, x_desc: impl Into<String>, y_desc: impl Into<String>) -> Self {
        Panel {
            title: title.into(),
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            y_scale: YScale::Log,
            x_log: true,
            series: Vec::new(),
            slopes: Vec::new(),
            hlines: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Whether any series has a point that can be drawn (on a linear axis at least).
    pub fn has_data(&self) -> bool {
        self.series
            .iter()
            .any(|s| s.points.iter().any(|&(x, y)| (x > 0.0 || !self.x_log) && x.is_finite() && y.is_some_and(f64::is_finite)))
    }
}

#[derive(Clone, Debug)]
pub(crate) struct LineFigure {
    /// Title over all panels (a single panel has its own title only).
    pub title: Option<String>,
    pub panels: Vec<Panel>,
    /// Panels per row (None: all in one row); the rows fill from the top.
    pub columns: Option<usize>,
}

impl LineFigure {
    /// (rows, columns) of the panels' grid.
    pub fn grid(&self) -> (usize, usize) {
        let n = self.panels.len().max(1);
        let cols = self.columns.unwrap_or(n).clamp(1, n);
        (n.div_ceil(cols), cols)
    }
}

#[derive(Clone, Debug)]
pub(crate) enum Figure {
    Lines(LineFigure),
    Mesh(MeshFigure),
}

impl Figure {
    pub fn size(&self) -> (u32, u32) {
        match self {
            Figure::Lines(f) if f.panels.len() > 1 => {
                let (rows, cols) = f.grid();
                (if rows > 1 { 900 } else { 800 } * cols as u32, if rows > 1 { 780 } else { 650 } * rows as u32)
            }
            Figure::Lines(_) => (900, 650),
            Figure::Mesh(m) => m.size(900),
        }
    }

    /// Draw onto `root`; `m` describes how the backend places text (`rich::SVG`, `rich::BITMAP`).
    /// Returns the y range of every line panel drawn and the range of its data ([`YRange`]).
    pub fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, m: Metrics) -> anyhow::Result<Vec<YRange>> {
        root.fill(&WHITE).drawn()?;
        let ranges = match self {
            Figure::Lines(f) => render_lines(root, f, m)?,
            Figure::Mesh(mesh) => {
                mesh::render_mesh(root, mesh, m)?;
                Vec::new()
            }
        };
        root.present().drawn()?;
        Ok(ranges)
    }
}

/// A line panel's y axis and the range of what it must show: the curves' points and the guide
/// lines (the efficiency index's line at 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YRange {
    pub title_index: usize,
    pub axis_lo: f64,
    pub axis_hi: f64,
    pub data_lo: f64,
    pub data_hi: f64,
    pub log: bool,
}

fn render_lines<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, f: &LineFigure, m: Metrics) -> anyhow::Result<Vec<YRange>> {
    let body = match &f.title {
        Some(t) => titled(root, root, t, FS_FIGURE_TITLE, m)?,
        None => root.clone(),
    };
    let areas = body.split_evenly(f.grid());
    let mut out = Vec::new();
    for (k, (area, panel)) in areas.iter().zip(&f.panels).enumerate() {
        if let Some(r) = panel::render_panel(root, area, panel, m)? {
            out.push(YRange { title_index: k, ..r });
        }
    }
    Ok(out)
}

/// Draw a centred title at the top of `area`; return the rest of the area.
fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    m: Metrics,
) -> anyhow::Result<DrawingArea<DB, Shift>> {
    let (w, _) = area.dim_in_pixel();
    let (x0, y0) = area.get_base_pixel();
    rich::draw(root, text, size, &BLACK, (HPos::Center, VPos::Top), (x0 + w as i32 / 2, y0 + 10), false, m)?;
    Ok(area.split_vertically((size * 1.3) as i32 + 14).1)
}

/// A message in the middle of an area that has nothing to plot.
fn message<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, area: &DrawingArea<DB, Shift>, text: &str, m: Metrics) -> anyhow::Result<()> {
    let (w, h) = area.dim_in_pixel();
    let (x0, y0) = area.get_base_pixel();
    rich::draw(root, text, FS_TITLE, &BLACK, (HPos::Center, VPos::Center), (x0 + w as i32 / 2, y0 + h as i32 / 2), false, m)
}

/// A marker centred at a backend pixel; hollow markers are white inside.
pub(crate) fn draw_marker<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, (x, y): (i32, i32), st: Style, r: i32) -> anyhow::Result<()> {
    let r = st.radius(r);
    let fill = if st.filled { st.color.filled() } else { WHITE.filled() };
    let edge = st.color.stroke_width(2);
    let poly = |pts: Vec<(i32, i32)>| -> anyhow::Result<()> {
        root.draw(&Polygon::new(pts.clone(), fill)).drawn()?;
        let mut closed = pts;
        closed.push(closed[0]);
        root.draw(&PathElement::new(closed, edge)).drawn()
    };
    match st.marker {
        Marker::None => {}
        Marker::Circle => {
            root.draw(&Circle::new((x, y), r, fill)).drawn()?;
            root.draw(&Circle::new((x, y), r, edge)).drawn()?;
        }
        Marker::Square => poly(vec![(x - r + 1, y - r + 1), (x + r - 1, y - r + 1), (x + r - 1, y + r - 1), (x - r + 1, y + r - 1)])?,
        Marker::TriangleUp => poly(vec![(x, y - r - 1), (x + r + 1, y + r), (x - r - 1, y + r)])?,
        Marker::TriangleDown => poly(vec![(x, y + r + 1), (x + r + 1, y - r), (x - r - 1, y - r)])?,
        Marker::Diamond => poly(vec![(x, y - r - 1), (x + r + 1, y), (x, y + r + 1), (x - r - 1, y)])?,
        Marker::Star => {
            let pts: Vec<(i32, i32)> = (0..10)
                .map(|k| {
                    let rad = if k % 2 == 0 { r as f64 + 2.0 } else { 0.45 * (r as f64 + 2.0) };
                    let a = std::f64::consts::PI * (k as f64 / 5.0 - 0.5);
                    ((x as f64 + rad * a.cos()).round() as i32, (y as f64 + rad * a.sin()).round() as i32)
                })
                .collect();
            poly(pts)?
        }
        Marker::Cross => {
            root.draw(&PathElement::new(vec![(x - r, y - r), (x + r, y + r)], edge)).drawn()?;
            root.draw(&PathElement::new(vec![(x - r, y + r), (x + r, y - r)], edge)).drawn()?;
        }
        Marker::Plus => {
            root.draw(&PathElement::new(vec![(x - r - 1, y), (x + r + 1, y)], edge)).drawn()?;
            root.draw(&PathElement::new(vec![(x, y - r - 1), (x, y + r + 1)], edge)).drawn()?;
        }
    }
    Ok(())
}
