//! One coordinate type for every axis of the figures: linear or base-10 logarithmic, with
//! tick positions chosen here rather than by plotters' `LogCoord` (whose light/bold key points
//! mix decades with arbitrary multiples). On a log axis the labelled (bold) ticks are the
//! decades, `10⁻⁴`, `10⁻³`, ...; the unlabelled light grid lines are 2..9 times a decade. When
//! the range holds fewer than two decades, 2x and 5x a decade are labelled too.

use plotters::coord::ranged1d::{KeyPointHint, KeyPointWeight, NoDefaultFormatting, Ranged, ValueFormatter};
use std::ops::Range;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
}

/// Target number of labelled ticks on a linear axis.
const LINEAR_TICKS: f64 = 6.0;

impl Axis {
    pub fn linear(lo: f64, hi: f64) -> Self {
        Axis { lo, hi, log: false }
    }

    pub fn log(lo: f64, hi: f64) -> Self {
        debug_assert!(lo > 0.0 && hi > lo, "log axis needs 0 < lo < hi, got {lo}..{hi}");
        Axis { lo, hi, log: true }
    }

    /// The axis coordinate (log10 on a log axis).
    pub fn t(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    pub fn inv(&self, t: f64) -> f64 {
        if self.log { 10f64.powf(t) } else { t }
    }

    pub fn contains(&self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0) && v >= self.lo * (1.0 - 1e-12) && v <= self.hi * (1.0 + 1e-12)
    }

    /// Spacing of the labelled ticks of a linear axis: 1, 2 or 5 times a power of ten.
    fn linear_step(&self) -> f64 {
        let raw = (self.hi - self.lo).abs() / LINEAR_TICKS;
        if raw.is_nan() || raw <= 0.0 || !raw.is_finite() {
            return 1.0;
        }
        let p = 10f64.powf(raw.log10().floor());
        let m = raw / p;
        let nice = if m < 1.5 {
            1.0
        } else if m < 3.0 {
            2.0
        } else if m < 7.0 {
            5.0
        } else {
            10.0
        };
        nice * p
    }

    fn multiples(&self, step: f64) -> Vec<f64> {
        let first = (self.lo / step - 1e-9).ceil() as i64;
        let last = (self.hi / step + 1e-9).floor() as i64;
        (first..=last).map(|k| k as f64 * step).map(|v| if v.abs() < step * 1e-9 { 0.0 } else { v }).collect()
    }

    /// Decade exponents inside the range.
    fn decades(&self) -> Vec<i32> {
        let first = (self.lo.log10() - 1e-9).ceil() as i32;
        let last = (self.hi.log10() + 1e-9).floor() as i32;
        (first..=last).collect()
    }

    fn log_points(&self, mantissas: &[f64]) -> Vec<f64> {
        let first = self.lo.log10().floor() as i32;
        let last = self.hi.log10().ceil() as i32;
        let mut out = Vec::new();
        for e in first..=last {
            for &m in mantissas {
                let v = m * 10f64.powi(e);
                if self.contains(v) {
                    out.push(v);
                }
            }
        }
        out
    }

    /// Labelled tick positions.
    pub fn major_ticks(&self, max: usize) -> Vec<f64> {
        let max = max.max(2);
        if self.log {
            let d = self.decades();
            if d.len() < 2 {
                return self.log_points(&[1.0, 2.0, 5.0]);
            }
            let stride = d.len().div_ceil(max).max(1) as i32;
            d.into_iter().filter(|e| e.rem_euclid(stride) == 0).map(|e| 10f64.powi(e)).collect()
        } else {
            self.multiples(self.linear_step())
        }
    }

    /// Unlabelled grid positions.
    pub fn minor_ticks(&self, max: usize) -> Vec<f64> {
        if self.log {
            let pts = self.log_points(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
            if pts.len() <= max { pts } else { self.major_ticks(max) }
        } else {
            let step = self.linear_step();
            let mantissa = (step / 10f64.powf(step.log10().floor())).round();
            let sub = if mantissa == 2.0 { 4.0 } else { 5.0 };
            let pts = self.multiples(step / sub);
            if pts.len() <= max { pts } else { self.major_ticks(max) }
        }
    }

    /// The label of a tick.
    pub fn label(&self, v: f64) -> String {
        if self.log {
            log_label(v)
        } else {
            let step = self.linear_step();
            let decimals = (-step.log10().floor()).max(0.0) as usize;
            let s = format!("{v:.decimals$}");
            if s.starts_with('-') && s.trim_start_matches(['-', '0', '.']).is_empty() { s[1..].to_string() } else { s }
        }
    }
}

/// `10⁻⁴`, `2×10⁻⁴`.
pub(crate) fn log_label(v: f64) -> String {
    if v.is_nan() || v <= 0.0 {
        return format!("{v}");
    }
    let e = v.log10().floor() as i32;
    let mut m = v / 10f64.powi(e);
    let mut e = e;
    if (m - 10.0).abs() < 1e-6 {
        m = 1.0;
        e += 1;
    }
    let pow = format!("10{}", superscript(e));
    if (m - 1.0).abs() < 1e-6 { pow } else { format!("{}×{pow}", fmt_mantissa(m)) }
}

fn fmt_mantissa(m: f64) -> String {
    let s = format!("{m:.1}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// An integer in Unicode superscript digits (all present in DejaVu Sans).
pub(crate) fn superscript(e: i32) -> String {
    e.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            other => other,
        })
        .collect()
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (self.t(self.lo), self.t(self.hi));
        let v = if self.log && (value.is_nan() || *value <= 0.0) { self.lo * 1e-3 } else { *value };
        let f = (self.t(v) - a) / (b - a);
        let px = limit.0 as f64 + f * (limit.1 - limit.0) as f64;
        px.clamp(-1e6, 1e6).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        match hint.weight() {
            KeyPointWeight::Bold => self.major_ticks(hint.max_num_points()),
            KeyPointWeight::Any => self.minor_ticks(hint.max_num_points()),
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, value: &f64) -> String {
        self.label(*value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_decades() {
        let a = Axis::log(3e-5, 2e-1);
        assert_eq!(a.major_ticks(10).iter().map(|&v| a.label(v)).collect::<Vec<_>>(), ["10⁻⁴", "10⁻³", "10⁻²", "10⁻¹"]);
        assert!(a.minor_ticks(100).len() > 20);
        let narrow = Axis::log(0.3, 4.0);
        assert_eq!(narrow.major_ticks(10).iter().map(|&v| narrow.label(v)).collect::<Vec<_>>(), ["5×10⁻¹", "10⁰", "2×10⁰"]);
    }

    #[test]
    fn linear_ticks_are_nice() {
        let a = Axis::linear(0.0, 3.3);
        assert_eq!(a.major_ticks(10).iter().map(|&v| a.label(v)).collect::<Vec<_>>(), ["0.0", "0.5", "1.0", "1.5", "2.0", "2.5", "3.0"]);
        let b = Axis::linear(-0.03, 1.03);
        assert_eq!(b.major_ticks(10).iter().map(|&v| b.label(v)).collect::<Vec<_>>(), ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
    }
}
