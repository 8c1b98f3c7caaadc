//! Text with real subscripts and superscripts: `C_{0}η_{h}`, `NDF^{-3/2}`. (DejaVu's Unicode
//! subscript glyphs sit almost on the baseline and read like superscripts next to η, so labels
//! are drawn segment by segment instead: a smaller font, shifted down or up.)
//!
//! Markup: `_{...}` lowers, `^{...}` raises; no nesting. Text without braces after `_`/`^`
//! (run ids such as `ex71_adaptive`) is left as it is.
//!
//! The SVG and bitmap backends place text differently, so segment positions need the backend's
//! metrics: where the baseline falls below a top-anchored text (bitmap: half the size, from
//! plotters' ab_glyph code; SVG: `dy = 0.76em` with `font-size = size / 1.24`), and how wide the
//! SVG text is relative to the ab_glyph width estimate (the SVG em is size / 1.24, ab_glyph's is
//! size * 2048 / 2384 for DejaVu Sans).

use super::font::{DrawResult, font};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

#[derive(Clone, Copy, Debug)]
pub(crate) struct Metrics {
    /// Baseline below the top anchor, as a fraction of the font size.
    pub baseline: f64,
    /// Rendered width / ab_glyph's estimate.
    pub width_scale: f64,
}

pub(crate) const BITMAP: Metrics = Metrics { baseline: 0.5, width_scale: 1.0 };
pub(crate) const SVG: Metrics = Metrics { baseline: 0.76 / 1.24, width_scale: (2384.0 / 2048.0) / 1.24 };

/// Size of a sub/superscript relative to the text.
const SMALL: f64 = 0.72;

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Seg {
    pub text: String,
    /// -1 subscript, 0 normal, +1 superscript
    pub level: i8,
}

pub(crate) fn parse(s: &str) -> Vec<Seg> {
    let mut out: Vec<Seg> = Vec::new();
    let mut cur = String::new();
    let mut rest = s;
    while !rest.is_empty() {
        let marker = rest.find(['_', '^']);
        let Some(i) = marker else {
            cur.push_str(rest);
            break;
        };
        let (before, after) = rest.split_at(i);
        cur.push_str(before);
        let level = if after.starts_with('_') { -1 } else { 1 };
        let inner = &after[1..];
        match inner.strip_prefix('{').and_then(|b| b.find('}').map(|j| (&b[..j], &b[j + 1..]))) {
            Some((script, tail)) => {
                if !cur.is_empty() {
                    out.push(Seg { text: std::mem::take(&mut cur), level: 0 });
                }
                out.push(Seg { text: script.to_string(), level });
                rest = tail;
            }
            None => {
                cur.push_str(&after[..1]);
                rest = inner;
            }
        }
    }
    if !cur.is_empty() {
        out.push(Seg { text: cur, level: 0 });
    }
    out
}

fn seg_size(size: f64, level: i8) -> f64 {
    if level == 0 { size } else { size * SMALL }
}

/// Baseline shift (down positive) of a segment.
fn seg_shift(size: f64, level: i8) -> f64 {
    match level {
        l if l < 0 => 0.22 * size,
        l if l > 0 => -0.36 * size,
        _ => 0.0,
    }
}

/// Segment widths in pixels as rendered.
fn widths<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, segs: &[Seg], size: f64, m: Metrics) -> anyhow::Result<Vec<f64>> {
    segs.iter()
        .map(|g| {
            let (w, _) = area.estimate_text_size(&g.text, &font(seg_size(size, g.level))).drawn()?;
            // a little air after a sub/superscript, whose glyphs crowd the next letter
            let pad = if g.level != 0 { 0.12 * size } else { 0.0 };
            Ok(w as f64 * m.width_scale + pad)
        })
        .collect()
}

/// Width of the text as rendered.
pub(crate) fn width<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, text: &str, size: f64, m: Metrics) -> anyhow::Result<i32> {
    Ok(widths(area, &parse(text), size, m)?.iter().sum::<f64>().ceil() as i32)
}

/// Draw `text` anchored at `pos` (backend pixels of `area`). Vertical anchors: `Top` puts the
/// cap height at `pos`, `Center` the middle of the lower-case letters, `Bottom` the descenders.
/// `rotated` draws upwards (for a y-axis label).
#[allow(clippy::too_many_arguments)]
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    color: &RGBColor,
    (h, v): (HPos, VPos),
    pos: (i32, i32),
    rotated: bool,
    m: Metrics,
) -> anyhow::Result<()> {
    let segs = parse(text);
    let w = widths(area, &segs, size, m)?;
    let total: f64 = w.iter().sum();
    let mut u = match h {
        HPos::Left => 0.0,
        HPos::Center => -0.5 * total,
        HPos::Right => -total,
    };
    let baseline = match v {
        VPos::Top => 0.66 * size,
        VPos::Center => 0.3 * size,
        VPos::Bottom => -0.2 * size,
    };
    for (g, wi) in segs.iter().zip(&w) {
        let s = seg_size(size, g.level);
        let top = baseline + seg_shift(size, g.level) - m.baseline * s;
        let mut style = font(s).color(color).pos(Pos::new(HPos::Left, VPos::Top));
        let at = if rotated {
            style = style.transform(FontTransform::Rotate270);
            (pos.0 + top.round() as i32, pos.1 - u.round() as i32)
        } else {
            (pos.0 + u.round() as i32, pos.1 + top.round() as i32)
        };
        // SVG viewers strip leading white space from a <text>: skip it here, by its width
        let text = g.text.trim_start();
        let lead = if text.len() < g.text.len() {
            let (w_all, _) = area.estimate_text_size(&g.text, &font(s)).drawn()?;
            let (w_text, _) = area.estimate_text_size(text, &font(s)).drawn()?;
            (w_all as f64 - w_text as f64) * m.width_scale
        } else {
            0.0
        };
        let at = if rotated { (at.0, at.1 - lead.round() as i32) } else { (at.0 + lead.round() as i32, at.1) };
        if !text.is_empty() {
            area.draw_text(text, &style, at).drawn()?;
        }
        u += wi;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup() {
        let segs = parse("C_{0}η_{h}, NDF^{-3/2} ex71_adaptive_");
        let texts: Vec<(&str, i8)> = segs.iter().map(|g| (g.text.as_str(), g.level)).collect();
        assert_eq!(texts, [("C", 0), ("0", -1), ("η", 0), ("h", -1), (", NDF", 0), ("-3/2", 1), (" ex71_adaptive_", 0)]);
    }
}
