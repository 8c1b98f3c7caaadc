//! Least-squares lines with 95% Student-t intervals on their slope, and the special functions
//! they need (written by hand: a few dozen lines, where a statistics crate would bring far more
//! than these). Used by the verdicts of the analysis floor and the rate checks of the drift.

/// ln Gamma(x), x > 0 (Lanczos, g = 7, 9 terms; relative error below 1e-14).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let a = G[0] + G[1..].iter().enumerate().map(|(i, g)| g / (x + i as f64 + 1.0)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Continued fraction of the incomplete beta function (modified Lentz).
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < tiny {
        d = tiny;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        for aa in [m * (b - m) * x / ((qam + m2) * (a + m2)), -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))] {
            d = 1.0 + aa * d;
            if d.abs() < tiny {
                d = tiny;
            }
            c = 1.0 + aa / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// Regularised incomplete beta function I_x(a, b).
pub fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) { front * beta_cf(a, b, x) / a } else { 1.0 - front * beta_cf(b, a, 1.0 - x) / b }
}

/// Two-sided tail probability P(|T| > t) of Student's t with `dof` degrees of freedom.
pub fn t_two_sided_tail(t: f64, dof: f64) -> f64 {
    incomplete_beta(dof / 2.0, 0.5, dof / (dof + t * t))
}

/// The 97.5% quantile of Student's t (the factor of a two-sided 95% interval), by bisection.
pub fn t_quantile_975(dof: usize) -> f64 {
    assert!(dof >= 1, "Student's t needs at least one degree of freedom");
    let (mut lo, mut hi) = (0.0, 1e3);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if t_two_sided_tail(mid, dof as f64) > 0.05 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// A least-squares line y = intercept + slope x with the 95% interval of its slope.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    pub slope: f64,
    /// t_{0.975, n-2} x standard error of the slope (infinite with two points).
    pub half_width: f64,
    pub points: usize,
}

impl LineFit {
    pub fn lo(&self) -> f64 {
        self.slope - self.half_width
    }
    pub fn hi(&self) -> f64 {
        self.slope + self.half_width
    }
    pub fn width(&self) -> f64 {
        2.0 * self.half_width
    }
}

/// The least-squares sums of (x, y): n, mean x, mean y, Sxx, the slope and the residual sum of
/// squares; None with fewer than 2 points or no spread in x.
struct LeastSquares {
    n: usize,
    mx: f64,
    my: f64,
    sxx: f64,
    slope: f64,
    rss: f64,
}

fn least_squares(pts: &[(f64, f64)]) -> Option<LeastSquares> {
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / nf, pts.iter().map(|p| p.1).sum::<f64>() / nf);
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let rss: f64 = pts.iter().map(|p| (p.1 - my - slope * (p.0 - mx)).powi(2)).sum();
    Some(LeastSquares { n, mx, my, sxx, slope, rss })
}

/// The least-squares line through (x, y) evaluated at `x`, with the 95% half-width of that value
/// (the interval of the mean response: t_{0.975, n-2} s sqrt(1/n + (x - mean x)^2 / Sxx));
/// None with fewer than 3 points or no spread in x.
pub fn line_value_at(pts: &[(f64, f64)], x: f64) -> Option<(f64, f64)> {
    let l = least_squares(pts).filter(|l| l.n >= 3)?;
    let nf = l.n as f64;
    let s = (l.rss / (nf - 2.0)).sqrt();
    Some((l.my + l.slope * (x - l.mx), t_quantile_975(l.n - 2) * s * (1.0 / nf + (x - l.mx).powi(2) / l.sxx).sqrt()))
}

/// Least-squares line through (x, y) with a 95% interval on the slope; None with fewer than 2
/// points or no spread in x.
pub fn fit_line(pts: &[(f64, f64)]) -> Option<LineFit> {
    let l = least_squares(pts)?;
    let half_width = if l.n > 2 { t_quantile_975(l.n - 2) * (l.rss / (l.n as f64 - 2.0) / l.sxx).sqrt() } else { f64::INFINITY };
    Some(LineFit { slope: l.slope, half_width, points: l.n })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On points of an exact line the value is the line's and its interval has no width; with
    /// noise, the interval widens away from the points' centre and holds the true value.
    #[test]
    fn line_value_at_follows_the_line_and_its_uncertainty() {
        let exact: Vec<(f64, f64)> = (0..6).map(|i| (i as f64, 2.0 - 0.5 * i as f64)).collect();
        let (y, w) = line_value_at(&exact, 10.0).unwrap();
        assert!((y - (2.0 - 5.0)).abs() < 1e-12 && w < 1e-12, "{y} ± {w}");
        let noisy: Vec<(f64, f64)> = (0..8).map(|i| (i as f64, 1.0 + i as f64 + if i % 2 == 0 { 0.1 } else { -0.1 })).collect();
        let (mid, w_mid) = line_value_at(&noisy, 3.5).unwrap();
        let (end, w_end) = line_value_at(&noisy, 7.0).unwrap();
        assert!((mid - 4.5).abs() <= w_mid && (end - 8.0).abs() <= w_end, "{mid} ± {w_mid}, {end} ± {w_end}");
        assert!(w_end > w_mid, "the interval is narrowest at the centre: {w_mid} vs {w_end}");
        assert!(line_value_at(&noisy[..2], 1.0).is_none(), "two points give no interval");
    }
}
