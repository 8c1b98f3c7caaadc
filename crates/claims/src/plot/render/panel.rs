//! Line panels: the axes chosen from the data (log or linear, padded, room for guide lines and
//! slope labels), reference slopes with their triangles, the curves and markers, and a legend
//! placed where it covers no data (a corner first, then room at the top, then beside or under).

use super::*;

/// A series reduced to what can be drawn on the chosen axes.
struct Prepared<'a> {
    series: &'a Series,
    segments: Vec<Vec<(f64, f64)>>,
    zeros: usize,
    present: usize,
}

impl Prepared<'_> {
    fn points(&self) -> impl Iterator<Item = &(f64, f64)> {
        self.segments.iter().flatten()
    }
    fn legend_label(&self) -> String {
        let l = &self.series.label;
        let zero = if self.series.roundoff { "0 or below round-off" } else { "0" };
        if self.segments.is_empty() {
            if self.zeros > 0 && self.zeros == self.present { format!("{l} = {zero} at all levels") } else { format!("{l}: no data") }
        } else if self.zeros > 0 {
            format!("{l} (= {zero} at {} of {} levels, not drawn)", self.zeros, self.present)
        } else {
            l.clone()
        }
    }
}

fn prepare(series: &Series, x_log: bool, y_log: bool) -> Prepared<'_> {
    let mut segments = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let (mut zeros, mut present) = (0, 0);
    for &(x, y) in &series.points {
        let ok = match y {
            Some(v) if (x > 0.0 || !x_log) && x.is_finite() && v.is_finite() => {
                present += 1;
                if y_log && v <= 0.0 {
                    zeros += 1;
                    None
                } else {
                    Some(v)
                }
            }
            _ => None,
        };
        match ok {
            Some(v) => current.push((x, v)),
            None => {
                if !current.is_empty() {
                    segments.push(std::mem::take(&mut current));
                }
            }
        }
    }
    if !current.is_empty() {
        segments.push(current);
    }
    Prepared { series, segments, zeros, present }
}

enum Entry<'a> {
    Curve(Style, String),
    Note(&'a str),
    Text(String),
}

impl Entry<'_> {
    fn text(&self) -> &str {
        match self {
            Entry::Curve(_, t) | Entry::Text(t) => t,
            Entry::Note(t) => t,
        }
    }
}

/// A padded axis range around values, in axis coordinates.
fn padded(values: &[f64], log: bool, pad: f64, min_decades: f64) -> Axis {
    let lo = values.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = values.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    if log {
        let (mut a, mut b) = (lo.log10(), hi.log10());
        let span = (b - a).max(1e-3);
        a -= pad * span.max(0.5);
        b += pad * span.max(0.5);
        if b - a < min_decades {
            let mid = 0.5 * (a + b);
            a = mid - 0.5 * min_decades;
            b = mid + 0.5 * min_decades;
        }
        Axis::log(10f64.powf(a), 10f64.powf(b))
    } else {
        // from 0 for positive data; padded on both sides where the data go below 0
        let lo = lo.min(0.0);
        let hi = if hi > lo { hi } else { lo + 1.0 };
        let below = if lo < 0.0 { pad * (hi - lo) } else { 0.0 };
        Axis::linear(lo - below, hi + pad * (hi - lo))
    }
}

pub(super) fn render_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    m: Metrics,
) -> anyhow::Result<Option<YRange>> {
    let area = titled(root, area, &p.title, FS_TITLE, m)?;
    if !p.has_data() {
        return message(root, &area, "no results yet", m).map(|()| None);
    }
    let y_log = y_is_log(p);
    let prepared: Vec<Prepared> = p.series.iter().map(|s| prepare(s, p.x_log, y_log)).collect();
    let xs: Vec<f64> = prepared.iter().flat_map(|s| s.points().map(|p| p.0)).collect();
    let yv: Vec<f64> = prepared.iter().flat_map(|s| s.points().map(|p| p.1)).collect();
    if xs.is_empty() {
        let msg = prepared.iter().map(|s| s.legend_label()).collect::<Vec<_>>().join("; ");
        return message(root, &area, &msg, m).map(|()| None);
    }
    // the data and the guide lines (efficiency = 1 is part of what a reader must see)
    let guides = p.hlines.iter().map(|h| h.y).filter(|y| !y_log || *y > 0.0);
    let (data_lo, data_hi) = yv.iter().cloned().chain(guides).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let xa = padded(&xs, p.x_log, 0.06, 1.0);
    let slopes = place_slopes(p, &prepared, &xs, y_log);
    let ya = y_axis(p, yv, &slopes, y_log);
    let legend = Legend::of(root, p, &prepared, m)?;

    let build = |ya: Axis, right: i32, bottom: i32| {
        ChartBuilder::on(&area)
            .margin(14)
            .margin_right(right)
            .margin_bottom(bottom)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xa, ya)
            .drawn()
    };
    let Placed { mut chart, ya, legend_at, label_at } = place(root, &build, p, &prepared, &slopes, &legend, (xa, ya), m)?;

    chart
        .configure_mesh()
        .x_labels(12)
        .y_labels(12)
        .max_light_lines(10)
        .label_style(font(FS_TICK))
        .axis_desc_style(font(FS_DESC))
        .bold_line_style(BLACK.mix(0.16))
        .light_line_style(BLACK.mix(0.06))
        .set_all_tick_mark_size(6)
        .draw()
        .drawn()?;
    axis_descs(root, &chart, &p.x_desc, &p.y_desc, m)?;

    draw_guides(root, &mut chart, &p.hlines, (xa, ya), m)?;
    draw_slopes(root, &mut chart, &slopes, &label_at, m)?;
    draw_curves(root, &mut chart, &prepared)?;

    draw_legend(root, &legend.entries, legend_at, (legend.w, legend.h), (legend.pad, legend.swatch, legend.row), m)?;
    Ok(Some(YRange { title_index: 0, axis_lo: ya.lo, axis_hi: ya.hi, data_lo, data_hi, log: y_log }))
}

/// Whether the panel's y axis is logarithmic: always for [`YScale::Log`]; for [`YScale::Auto`]
/// when every value is positive and they span more than a decade.
fn y_is_log(p: &Panel) -> bool {
    let ys: Vec<f64> = p
        .series
        .iter()
        .flat_map(|s| s.points.iter().filter(|(x, _)| *x > 0.0 || !p.x_log).filter_map(|p| p.1))
        .filter(|v| v.is_finite())
        .collect();
    match p.y_scale {
        YScale::Log => true,
        YScale::Auto => {
            let pos: Vec<f64> = ys.iter().cloned().filter(|&v| v > 0.0).collect();
            let (lo, hi) = pos.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
            pos.len() == ys.len() && !pos.is_empty() && hi / lo > 10.0
        }
    }
}

/// The y axis around the values `yv`, with room for the slope labels and triangles and for the
/// guide lines' labels below them.
fn y_axis(p: &Panel, mut yv: Vec<f64>, slopes: &[PlacedSlope], y_log: bool) -> Axis {
    for (_, l, above) in slopes {
        // room for the label on its side of the line, and for the triangle's labels
        let room = if *above { 3.0 } else { 1.0 / 3.0 };
        yv.extend([l[1], l[3], l[1] * room]);
        yv.extend(slope_triangle(*l, *above).iter().map(|c| c.1 * if *above { 1.5 } else { 1.0 / 1.5 }));
    }
    // guide lines, with room below them for their label
    let (ymin, ymax) = yv.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    for h in &p.hlines {
        if y_log && h.y > 0.0 {
            yv.push(h.y);
            yv.push(h.y * 10f64.powf(-0.08 * (ymax / ymin).log10().max(1.0)));
        } else if !y_log {
            yv.push(h.y);
            yv.push(h.y - 0.08 * (ymax.max(h.y) - ymin.min(h.y)).max(1e-12));
        }
    }
    padded(&yv, y_log, 0.05, 1.0)
}

/// The legend: its entries (a curve per series with points, a text for one without, the
/// panel's notes) and its box's size.
struct Legend<'a> {
    entries: Vec<Entry<'a>>,
    w: i32,
    h: i32,
    pad: i32,
    swatch: i32,
    row: i32,
}

impl<'a> Legend<'a> {
    fn of<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, p: &'a Panel, prepared: &[Prepared], m: Metrics) -> anyhow::Result<Self> {
        let mut entries: Vec<Entry> = Vec::new();
        for s in prepared {
            if s.segments.is_empty() {
                entries.push(Entry::Text(s.legend_label()));
            } else {
                entries.push(Entry::Curve(s.series.style, s.legend_label()));
            }
        }
        for n in &p.notes {
            entries.push(Entry::Note(n));
        }
        let mut text_w = 0;
        for e in &entries {
            text_w = text_w.max(rich::width(root, e.text(), FS_LEGEND, m)?);
        }
        let row = ((FS_LEGEND * 1.45) as i32).max(20);
        let (pad, swatch) = (8, 44);
        let w = pad + swatch + 8 + text_w + pad;
        let h = pad * 2 + row * entries.len() as i32;
        Ok(Legend { entries, w, h, pad, swatch, row })
    }
}

/// A line panel's chart.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Axis, Axis>>;

/// The chart as finally built, with its y axis, the legend's corner and the slope labels' anchors.
struct Placed<'a, DB: DrawingBackend> {
    chart: Chart<'a, DB>,
    ya: Axis,
    legend_at: Option<(i32, i32)>,
    label_at: Vec<(i32, i32)>,
}

/// The chart built by `build` (y axis, right and bottom margins), the slope labels placed beside
/// their lines and the legend where it covers nothing (as near a corner as possible, upper right
/// first); if there is no such place, room is made at the top, and failing that the legend goes
/// beside or under the plot.
#[allow(clippy::too_many_arguments)]
fn place<'a, DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    build: &dyn Fn(Axis, i32, i32) -> anyhow::Result<Chart<'a, DB>>,
    p: &Panel,
    prepared: &[Prepared],
    slopes: &[PlacedSlope],
    legend: &Legend,
    (xa, mut ya): (Axis, Axis),
    m: Metrics,
) -> anyhow::Result<Placed<'a, DB>> {
    let (legend_w, legend_h) = (legend.w, legend.h);
    let mut slope_labels = Vec::new();
    for (s, _, _) in slopes {
        slope_labels.push((rich::width(root, &s.label, FS_SLOPE, m)?, 20));
    }
    let hline_label_w: Vec<i32> = p.hlines.iter().map(|h| rich::width(root, &h.label, FS_LEGEND, m)).collect::<anyhow::Result<_>>()?;
    let inset = 10;
    // the y axis before any room is made for the legend at the top
    let ya_data = ya;
    let mut chart = build(ya, 24, 14)?;
    let mut legend_at = None;
    let mut label_at: Vec<(i32, i32)> = Vec::new();
    let (mut beside, mut below) = (false, false);
    for attempt in 0..3 {
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        let mut grid = Occupancy::new(xr.clone(), yr.clone());
        for q in obstacle_samples(&chart, prepared, slopes, &p.hlines, xa, ya) {
            grid.add_point(q);
        }
        let data = grid.clone().finish();
        label_at = slope_label_anchors(&chart, slopes, &slope_labels, &data, &mut grid);
        for (hl, w) in p.hlines.iter().zip(&hline_label_w) {
            if ya.contains(hl.y) {
                let (px, py) = chart.backend_coord(&(xa.hi, hl.y));
                grid.add_rect((px - 8 - w, py + 5, *w, 20));
            }
        }
        let taken = grid.finish();
        if legend.entries.is_empty() {
            break;
        }
        if beside {
            legend_at = Some(if below {
                // under the x axis and its description, left-aligned with the plot
                (xr.start, yr.end + X_LABEL_AREA + 8)
            } else {
                (xr.end + 16, yr.start)
            });
            break;
        }
        if let Some(c) = free_corner(&taken, (&xr, &yr), inset, (legend_w, legend_h)) {
            legend_at = Some(c);
            break;
        }
        if attempt == 0 {
            // once: room at the top, at most half a decade (a quarter of a linear range)
            let plot_h = (yr.end - yr.start).max(1) as f64;
            let f = ((legend_h + 2 * inset + 6) as f64 / plot_h).min(0.6);
            let (a, b) = (ya.t(ya.lo), ya.t(ya.hi));
            let cap = if ya.log { 0.5 } else { 0.25 * (b - a) };
            ya = Axis { hi: ya.inv((a + (b - a) / (1.0 - f)).min(b + cap)), ..ya };
            chart = build(ya, 24, 14)?;
        } else {
            // beside the plot, on the right, or under it: whichever leaves the plot's shorter
            // side longer (a convergence plot squashed flat is as hard to read as a narrow one)
            beside = true;
            // the room made at the top did not take the legend: give it back to the data
            ya = ya_data;
            let (w, h) = (xr.end - xr.start, yr.end - yr.start);
            below = w.min(h - legend_h - 12) > (w - legend_w - 16).min(h);
            chart = if below { build(ya, 24, 14 + legend_h + 12)? } else { build(ya, 24 + legend_w + 16, 14)? };
        }
    }
    Ok(Placed { chart, ya, legend_at, label_at })
}

/// Each slope label at the first position along its line where it covers no `data`, its box
/// added to `grid`; the labels' anchors.
fn slope_label_anchors<DB: DrawingBackend>(
    chart: &ChartContext<DB, Cartesian2d<Axis, Axis>>,
    slopes: &[PlacedSlope],
    slope_labels: &[(i32, i32)],
    data: &Occupancy,
    grid: &mut Occupancy,
) -> Vec<(i32, i32)> {
    let mut label_at = Vec::new();
    for ((_, l, above), &(w, h)) in slopes.iter().zip(slope_labels) {
        let (a, b) = (chart.backend_coord(&(l[0], l[1])), chart.backend_coord(&(l[2], l[3])));
        let rect = |t: f64| {
            let (px, py) = ((a.0 as f64 + t * (b.0 - a.0) as f64) as i32, (a.1 as f64 + t * (b.1 - a.1) as f64) as i32);
            if *above { (px + 6, py - 6 - h, w, h) } else { (px - 6 - w, py + 6, w, h) }
        };
        let t = [0.55, 0.4, 0.7, 0.25, 0.85].into_iter().find(|&t| !data.hits(rect(t), 2)).unwrap_or(0.55);
        let r = rect(t);
        grid.add_rect(r);
        label_at.push(if *above { (r.0, r.1 + r.3) } else { (r.0 + r.2, r.1) });
    }
    label_at
}

/// The legend's corner inside the plot (pixel ranges `xr`, `yr`, `inset` from the border)
/// where it keeps [`LEGEND_CLEARANCE`] from everything `taken`, as near a corner as possible
/// (upper right first); none if there is no such place.
fn free_corner(
    taken: &Occupancy,
    (xr, yr): (&std::ops::Range<i32>, &std::ops::Range<i32>),
    inset: i32,
    (legend_w, legend_h): (i32, i32),
) -> Option<(i32, i32)> {
    let (left, right) = (xr.start + inset, xr.end - inset - legend_w);
    let (top, bottom) = (yr.start + inset, yr.end - inset - legend_h);
    if !(right >= left && bottom >= top) {
        return None;
    }
    let xs_: Vec<i32> = (left..=right).step_by(6).chain([right]).collect();
    let ys_: Vec<i32> = (top..=bottom).step_by(6).chain([bottom]).collect();
    ys_.iter()
        .flat_map(|&y| xs_.iter().map(move |&x| (x, y)))
        .filter(|&(x, y)| !taken.hits((x, y, legend_w, legend_h), LEGEND_CLEARANCE))
        .min_by_key(|&(x, y)| {
            let (dx, dy) = ((x - left).min(right - x), (y - top).min(bottom - y));
            (dx + dy, (y - top > bottom - y) as u8, (x - left < right - x) as u8)
        })
}

/// The reference slopes of a log-log panel, each a line (x0, y0, x1, y1) over the right half of
/// the data's x range, 2.5x below (or above) the series it is anchored to.
fn place_slopes<'a>(p: &'a Panel, prepared: &[Prepared], xs: &[f64], y_log: bool) -> Vec<PlacedSlope<'a>> {
    let lx = xs.iter().map(|x| x.log10()).fold(f64::NEG_INFINITY, f64::max);
    let fx = xs.iter().map(|x| x.log10()).fold(f64::INFINITY, f64::min);
    p.slopes
        .iter()
        .filter(|_| y_log)
        .filter_map(|s| {
            let x0 = 10f64.powf(0.5 * (fx + lx));
            let x1 = 10f64.powf(lx);
            let ratios =
                |pr: &Prepared| -> Vec<f64> { pr.points().filter(|q| q.0 >= x0 * (1.0 - 1e-9)).map(|q| q.1 / q.0.powf(s.rate)).collect() };
            let r: Vec<f64> = match s.anchor {
                SlopeAnchor::Below(i) => prepared.get(i).map(ratios).unwrap_or_default(),
                SlopeAnchor::BelowAll | SlopeAnchor::AboveAll => prepared.iter().flat_map(ratios).collect(),
            };
            let above = matches!(s.anchor, SlopeAnchor::AboveAll);
            let c = if above {
                r.iter().cloned().fold(f64::NEG_INFINITY, f64::max) * 2.5
            } else {
                r.iter().cloned().fold(f64::INFINITY, f64::min) / 2.5
            };
            (x1 > x0 && c.is_finite() && c > 0.0).then(|| (s, [x0, c * x0.powf(s.rate), x1, c * x1.powf(s.rate)], above))
        })
        .collect()
}

/// The horizontal guide lines (efficiency = 1) across the panel, labelled under their right end.
fn draw_guides<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<DB, Cartesian2d<Axis, Axis>>,
    hlines: &[HLine],
    (xa, ya): (Axis, Axis),
    m: Metrics,
) -> anyhow::Result<()> {
    let guide = RGBColor(60, 60, 60);
    for h in hlines {
        if !ya.contains(h.y) {
            continue;
        }
        chart.draw_series(LineSeries::new(vec![(xa.lo, h.y), (xa.hi, h.y)], guide.mix(0.8).stroke_width(1))).drawn()?;
        // the label under the line at the right end: where an efficiency >= 1 leaves room
        let (px, py) = chart.backend_coord(&(xa.hi, h.y));
        rich::draw(root, &h.label, FS_LEGEND, &guide, (HPos::Right, VPos::Top), (px - 8, py + 5), false, m)?;
    }
    Ok(())
}

/// The reference slopes, dashed, with their labels at `label_at` and their slope triangles.
fn draw_slopes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<DB, Cartesian2d<Axis, Axis>>,
    slopes: &[PlacedSlope],
    label_at: &[(i32, i32)],
    m: Metrics,
) -> anyhow::Result<()> {
    for ((s, [x0, y0, x1, y1], above), at) in slopes.iter().zip(label_at) {
        chart.draw_series(DashedLineSeries::new(vec![(*x0, *y0), (*x1, *y1)], 9, 6, GREY.stroke_width(2))).drawn()?;
        let anchor = if *above { (HPos::Left, VPos::Bottom) } else { (HPos::Right, VPos::Top) };
        rich::draw(root, &s.label, FS_SLOPE, &GREY, anchor, *at, false, m)?;
        // the slope triangle: legs 1 (horizontal) and the rate (vertical), labelled outside
        let [a, b, c] = slope_triangle([*x0, *y0, *x1, *y1], *above);
        let [pa, pb, pc] = [a, b, c].map(|q| chart.backend_coord(&q));
        root.draw(&PathElement::new(vec![pa, pc, pb], GREY.stroke_width(2))).drawn()?;
        // the horizontal leg joins C and whichever of A, B shares its y
        let (h_end, v_end) = if pc.1 == pa.1 { (pa, pb) } else { (pb, pa) };
        let h_mid = ((pc.0 + h_end.0) / 2, pc.1);
        let v_mid = (pc.0, (pc.1 + v_end.1) / 2);
        let h_below = pc.1 > v_end.1;
        let v_left = pc.0 < h_end.0;
        rich::draw(
            root,
            "1",
            FS_SLOPE,
            &GREY,
            (HPos::Center, if h_below { VPos::Top } else { VPos::Bottom }),
            (h_mid.0, h_mid.1 + if h_below { 5 } else { -5 }),
            false,
            m,
        )?;
        rich::draw(
            root,
            &rate_text(s.rate),
            FS_SLOPE,
            &GREY,
            (if v_left { HPos::Right } else { HPos::Left }, VPos::Center),
            (v_mid.0 + if v_left { -6 } else { 6 }, v_mid.1),
            false,
            m,
        )?;
    }
    Ok(())
}

/// The series: lines (dashed or solid) first, then every marker on top.
fn draw_curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<DB, Cartesian2d<Axis, Axis>>,
    prepared: &[Prepared],
) -> anyhow::Result<()> {
    for s in prepared {
        let st = s.series.style;
        let line = st.color.stroke_width(2);
        for seg in &s.segments {
            if seg.len() < 2 {
                continue;
            }
            if st.dashed {
                chart.draw_series(DashedLineSeries::new(seg.clone(), 8, 5, line)).drawn()?;
            } else {
                chart.draw_series(LineSeries::new(seg.clone(), line)).drawn()?;
            }
        }
    }
    for s in prepared {
        for pt in s.points() {
            draw_marker(root, chart.backend_coord(pt), s.series.style, MARKER)?;
        }
    }
    Ok(())
}

/// The legend box at (x, y) with one row per entry: a line and marker (a series), or grey text.
#[allow(clippy::too_many_arguments)]
fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    legend_at: Option<(i32, i32)>,
    (legend_w, legend_h): (i32, i32),
    (pad, swatch, row): (i32, i32, i32),
    m: Metrics,
) -> anyhow::Result<()> {
    if let (Some((x, y)), false) = (legend_at, entries.is_empty()) {
        root.draw(&Rectangle::new([(x, y), (x + legend_w, y + legend_h)], WHITE.mix(0.92).filled())).drawn()?;
        root.draw(&Rectangle::new([(x, y), (x + legend_w, y + legend_h)], BLACK.mix(0.45).stroke_width(1))).drawn()?;
        for (k, e) in entries.iter().enumerate() {
            let cy = y + pad + row * k as i32 + row / 2;
            let tx = x + pad + swatch + 8;
            match e {
                Entry::Curve(st, label) => {
                    let (a, b) = (x + pad, x + pad + swatch);
                    if st.dashed {
                        for (s0, s1) in [(a, a + 12), (a + 16, a + 28), (a + 32, b)] {
                            root.draw(&PathElement::new(vec![(s0, cy), (s1, cy)], st.color.stroke_width(2))).drawn()?;
                        }
                    } else {
                        root.draw(&PathElement::new(vec![(a, cy), (b, cy)], st.color.stroke_width(2))).drawn()?;
                    }
                    draw_marker(root, ((a + b) / 2, cy), *st, MARKER)?;
                    rich::draw(root, label, FS_LEGEND, &BLACK, (HPos::Left, VPos::Center), (tx, cy), false, m)?;
                }
                Entry::Note(t) => rich::draw(root, t, FS_LEGEND, &GREY, (HPos::Left, VPos::Center), (x + pad, cy), false, m)?,
                Entry::Text(t) => rich::draw(root, t, FS_LEGEND, &GREY, (HPos::Left, VPos::Center), (tx, cy), false, m)?,
            }
        }
    }
    Ok(())
}

/// The axis descriptions, centred below and left of the plotting area (drawn here rather than by
/// plotters so that they can have subscripts).
fn axis_descs<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &ChartContext<DB, Cartesian2d<Axis, Axis>>,
    x_desc: &str,
    y_desc: &str,
    m: Metrics,
) -> anyhow::Result<()> {
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let (cx, cy) = ((xr.start + xr.end) / 2, (yr.start + yr.end) / 2);
    rich::draw(root, x_desc, FS_DESC, &BLACK, (HPos::Center, VPos::Bottom), (cx, yr.end + X_LABEL_AREA - 8), false, m)?;
    rich::draw(root, y_desc, FS_DESC, &BLACK, (HPos::Center, VPos::Top), (xr.start - Y_LABEL_AREA + 6, cy), true, m)
}

/// Pixels labels and the legend must not cover: every marker (as a small box), every line
/// sampled every few pixels, the slope lines, the guide lines.
fn obstacle_samples<DB: DrawingBackend>(
    chart: &ChartContext<DB, Cartesian2d<Axis, Axis>>,
    prepared: &[Prepared],
    slopes: &[PlacedSlope],
    hlines: &[HLine],
    xa: Axis,
    ya: Axis,
) -> Vec<(i32, i32)> {
    let mut out = Vec::new();
    let line = |a: (i32, i32), b: (i32, i32), out: &mut Vec<(i32, i32)>| {
        let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) / 3).max(1);
        for k in 0..=n {
            let t = k as f64 / n as f64;
            out.push(((a.0 as f64 + t * (b.0 - a.0) as f64) as i32, (a.1 as f64 + t * (b.1 - a.1) as f64) as i32));
        }
    };
    for s in prepared {
        for seg in &s.segments {
            let px: Vec<(i32, i32)> = seg.iter().map(|p| chart.backend_coord(p)).collect();
            let r = s.series.style.radius(MARKER);
            for &(x, y) in &px {
                for (dx, dy) in [(-r, -r), (r, -r), (-r, r), (r, r), (0, 0)] {
                    out.push((x + dx, y + dy));
                }
            }
            for w in px.windows(2) {
                line(w[0], w[1], &mut out);
            }
        }
    }
    for (_, l, above) in slopes {
        let (a, b) = (chart.backend_coord(&(l[0], l[1])), chart.backend_coord(&(l[2], l[3])));
        line(a, b, &mut out);
        // the slope triangle's legs and a box for each of their labels
        let [pa, pb, pc] = slope_triangle(*l, *above).map(|q| chart.backend_coord(&q));
        line(pa, pc, &mut out);
        line(pc, pb, &mut out);
        let (h_end, v_end) = if pc.1 == pa.1 { (pa, pb) } else { (pb, pa) };
        for mid in [((pc.0 + h_end.0) / 2, pc.1), (pc.0, (pc.1 + v_end.1) / 2)] {
            for dx in [-30, -15, 0, 15, 30] {
                for dy in [-20, -10, 0, 10, 20] {
                    out.push((mid.0 + dx, mid.1 + dy));
                }
            }
        }
    }
    for h in hlines {
        if ya.contains(h.y) {
            let (a, b) = (chart.backend_coord(&(xa.lo, h.y)), chart.backend_coord(&(xa.hi, h.y)));
            line(a, b, &mut out);
        }
    }
    out
}

/// Which pixels of the plotting area are taken, in cells of a few pixels, with prefix sums for
/// "is anything inside this rectangle" queries.
#[derive(Clone)]
struct Occupancy {
    x0: i32,
    y0: i32,
    nx: usize,
    ny: usize,
    cells: Vec<bool>,
    sum: Vec<u32>,
}

const CELL: i32 = 3;

impl Occupancy {
    fn new(xr: std::ops::Range<i32>, yr: std::ops::Range<i32>) -> Self {
        let nx = ((xr.end - xr.start).max(1) / CELL + 1) as usize;
        let ny = ((yr.end - yr.start).max(1) / CELL + 1) as usize;
        Occupancy { x0: xr.start, y0: yr.start, nx, ny, cells: vec![false; nx * ny], sum: Vec::new() }
    }

    fn cell(&self, (x, y): (i32, i32)) -> Option<(usize, usize)> {
        let (i, j) = ((x - self.x0).div_euclid(CELL), (y - self.y0).div_euclid(CELL));
        (i >= 0 && j >= 0 && (i as usize) < self.nx && (j as usize) < self.ny).then_some((i as usize, j as usize))
    }

    fn add_point(&mut self, q: (i32, i32)) {
        if let Some((i, j)) = self.cell(q) {
            self.cells[j * self.nx + i] = true;
        }
    }

    fn add_rect(&mut self, (x, y, w, h): (i32, i32, i32, i32)) {
        for py in (y..=y + h).step_by(CELL as usize) {
            for px in (x..=x + w).step_by(CELL as usize) {
                self.add_point((px, py));
            }
        }
    }

    fn finish(mut self) -> Self {
        let (nx, ny) = (self.nx, self.ny);
        let mut sum = vec![0u32; (nx + 1) * (ny + 1)];
        for j in 0..ny {
            for i in 0..nx {
                sum[(j + 1) * (nx + 1) + i + 1] =
                    self.cells[j * nx + i] as u32 + sum[j * (nx + 1) + i + 1] + sum[(j + 1) * (nx + 1) + i] - sum[j * (nx + 1) + i];
            }
        }
        self.sum = sum;
        self
    }

    /// Whether anything is inside the rectangle grown by `margin` pixels.
    fn hits(&self, (x, y, w, h): (i32, i32, i32, i32), margin: i32) -> bool {
        let clamp = |v: i32, n: usize| v.clamp(0, n as i32) as usize;
        let i0 = clamp((x - margin - self.x0).div_euclid(CELL), self.nx);
        let j0 = clamp((y - margin - self.y0).div_euclid(CELL), self.ny);
        let i1 = clamp((x + w + margin - self.x0).div_euclid(CELL) + 1, self.nx);
        let j1 = clamp((y + h + margin - self.y0).div_euclid(CELL) + 1, self.ny);
        if i1 <= i0 || j1 <= j0 {
            return false;
        }
        let s = |i: usize, j: usize| self.sum[j * (self.nx + 1) + i];
        s(i1, j1) + s(i0, j0) > s(i0, j1) + s(i1, j0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn occupancy_finds_points_in_rectangles() {
        let mut g = Occupancy::new(100..400, 50..300);
        g.add_point((200, 100));
        g.add_rect((300, 200, 20, 10));
        let g = g.finish();
        assert!(g.hits((190, 90, 20, 20), 0));
        assert!(!g.hits((210, 110, 50, 50), 0));
        assert!(g.hits((205, 105, 50, 50), 6));
        assert!(g.hits((310, 205, 2, 2), 0));
        assert!(!g.hits((100, 250, 150, 40), 0));
    }
}
