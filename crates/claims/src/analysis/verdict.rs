//! Verdicts a referee can check: observed rates with 95% confidence intervals, the rules that
//! turn an interval into a verdict, trends of the efficiency index, and the singular exponent of a
//! clamped / traction-free corner (what Example 7.2's error measures).
//!
//! **Rates.** A rate is the least-squares slope of -log(quantity) against log(NDF). Newest-vertex
//! bisection refines in two-level staircases (one bisection halves an element's area, two halve
//! its diameter), so a fit over consecutive levels depends on where the window starts; the fit
//! therefore takes every other level (levels of the same parity as the window's last level). The
//! window ends at a given level and reaches back until it spans at least two decades of NDF
//! ([`MIN_DECADES`]) and holds at least [`MIN_POINTS`] levels. The 95% interval is slope ± t_{0.975, n-2} x standard error (Student's t,
//! n points). Stability: the same fit over the windows ending at the last level, two levels
//! earlier and four levels earlier ([`RateReport::windows`]). A window shorter than two decades
//! (a run that ends early) decides nothing: one decade of small meshes is pre-asymptotic more
//! often than not, and a rate read there is not a verdict (its `range` says how short it is).
//!
//! **Round-off floor.** Deep runs reach errors near 1e-10 where the computed u_h carries round-off
//! of its own (`LevelRecord::roundoff_floor`). Error fits stop before the first level whose error
//! is below [`FLOOR_MARGIN`] x that floor ([`floor_hit`], [`above_floor`]), and the rows say where.
//!
//! **Abscissa.** Exponents are fitted against the variable the theory speaks of: NDF for
//! adaptive refinement, the smallest element diameter h_min for uniform refinement ([`Abscissa`];
//! on coarse uniform meshes NDF = 2(2N + 1)^2 is not proportional to h^-2, which biases an NDF
//! fit). The window is chosen in NDF either way; a rate in h is judged against the claim in h
//! (2c for a claim of NDF^-c) with the band doubled (± 0.2 in h is ± 0.1 in NDF).
//!
//! **Rules** ([`judge_rate`]), for a claimed rate c and interval [lo, hi]:
//! 0. a window spanning less than two decades of NDF: *inconclusive*, whatever the interval;
//! 1. the interval lies below c - 0.1: *not reproduced*; above c + 0.1: *different (faster)*;
//! 2. the whole interval lies inside [c - 0.1, c + 0.1]: *reproduced*;
//! 3. anything else (an interval that reaches outside the band, however close its centre is to
//!    c): *inconclusive*.
//!
//! A verdict is *fragile* ([`window_fragility`]) when the windows ending two and four levels
//! earlier give another verdict; `claims` also marks a row fragile when the dense sampling of the
//! error gives another verdict.
//!
//! **Bounded** ([`judge_trend`]): the slope of log(quantity) against log(NDF), over the same
//! two-decade window, has an interval containing 0 and no wider than 0.3; an interval containing 0
//! but wider than 0.3 is inconclusive, whatever its centre (a flat centre is no evidence with a
//! wide interval), and so is a window shorter than two decades.
//! The method: `docs/method.md`, section "From rates to verdicts".

use store::records::RunRecord;

/// A claimed rate counts as met when the interval lies within claim ± RATE_BAND (or contains it).
pub const RATE_BAND: f64 = 0.1;
/// An interval wider than this decides nothing.
pub const MAX_WIDTH: f64 = 0.3;
/// The fit window spans at least this many decades of NDF; a shorter one (the run ends
/// early) decides nothing ([`judge_rate`], [`judge_trend`]).
pub const MIN_DECADES: f64 = 2.0;
/// The fit window holds at least this many levels (where the run has them): with fewer, the t
/// factor of the interval is large (t_{0.975, 3} = 3.18).
pub const MIN_POINTS: usize = 5;
/// Relative size below which a value is round-off (see [`rate_over`]).
pub const ROUND_OFF: f64 = 1e-12;
/// Levels between the ends of the three stability windows.
pub const WINDOW_SHIFT: usize = 2;
/// An error counts in a rate fit only while it is at least this many times the level's
/// round-off floor (`LevelRecord::roundoff_floor`): below, it measures round-off ([`floor_hit`]).
pub const FLOOR_MARGIN: f64 = 10.0;

use model::base::stats::{LineFit, fit_line};

/// The variable a rate is fitted against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Abscissa {
    /// log NDF: value ~ NDF^-rate (adaptive refinement).
    Ndof,
    /// log (1 / h_min): value ~ h_min^rate (uniform refinement).
    InverseHMin,
}

/// A rate fitted over a window of levels: rate = slope of -log(value) against log(x), x the
/// [`Abscissa`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateFit {
    /// The rate (positive: decaying) and its interval.
    pub rate: LineFit,
    pub abscissa: Abscissa,
    pub first_level: usize,
    pub last_level: usize,
    pub first_ndof: usize,
    pub last_ndof: usize,
}

impl RateFit {
    pub fn decades(&self) -> f64 {
        (self.last_ndof as f64 / self.first_ndof as f64).log10()
    }
    /// "1.52 ± 0.04"
    pub fn text(&self) -> String {
        format!(
            "{:.2} ± {}",
            self.rate.slope,
            if self.rate.half_width.is_finite() { format!("{:.2}", self.rate.half_width) } else { "inf".into() }
        )
    }
    /// Whether the window is long enough for a verdict ([`MIN_DECADES`]).
    pub fn spans_enough(&self) -> bool {
        self.decades() >= MIN_DECADES
    }
    /// "levels 14–24 every other, NDF 3.1e4–3.1e6", with "in h_min, " first for a fit against
    /// h_min and ", only 1.0 decade(s): no verdict" last for a window shorter than [`MIN_DECADES`]
    pub fn range(&self) -> String {
        format!(
            "{}levels {}–{} every other, NDF {:.1e}–{:.1e}{}",
            if self.abscissa == Abscissa::InverseHMin { "in h_min, " } else { "" },
            self.first_level,
            self.last_level,
            self.first_ndof as f64,
            self.last_ndof as f64,
            if self.spans_enough() { String::new() } else { format!(", only {:.1} decade(s): no verdict", self.decades()) }
        )
    }
    /// A claim of NDF^-c and its band in this fit's variable: (2c, 2 band) in h_min (NDF ~ h^-2).
    pub fn claim_in_abscissa(&self, claim: f64) -> (f64, f64) {
        match self.abscissa {
            Abscissa::Ndof => (claim, RATE_BAND),
            Abscissa::InverseHMin => (2.0 * claim, 2.0 * RATE_BAND),
        }
    }
}

/// Levels of the window ending at `end`: end, end - 2, ... back until the window spans
/// `MIN_DECADES` of NDF and holds `MIN_POINTS` levels (or to the start of the run), in increasing order.
pub fn window(ndof: &[usize], end: usize) -> Vec<usize> {
    let mut out = vec![end];
    let mut i = end;
    while i >= 2 && ((ndof[end] as f64 / ndof[i] as f64).log10() < MIN_DECADES || out.len() < MIN_POINTS) {
        i -= 2;
        out.push(i);
    }
    out.reverse();
    out
}

/// Rate of `values` (one per level; None or non-positive values end the window) against `ndof`
/// over the window ending at `end`.
/// Values at or below `ROUND_OFF` x the largest value of the run count as zero (e.g. eta_6 of
/// 3e-17 where it is otherwise 1e-5) and end the window like missing ones.
pub fn rate_over(ndof: &[usize], values: &[Option<f64>], end: usize) -> Option<RateFit> {
    let x: Vec<f64> = ndof.iter().map(|&n| n as f64).collect();
    rate_over_x(ndof, &x, Abscissa::Ndof, values, end)
}

/// As [`rate_over`] (the window chosen in NDF), fitted against `x` (one per level, positive).
pub fn rate_over_x(ndof: &[usize], x: &[f64], abscissa: Abscissa, values: &[Option<f64>], end: usize) -> Option<RateFit> {
    let floor = ROUND_OFF * values.iter().flatten().cloned().fold(0.0, f64::max);
    let levels: Vec<usize> = window(ndof, end).into_iter().rev().take_while(|&l| values[l].is_some_and(|v| v > floor)).collect();
    let pts: Vec<(f64, f64)> = levels.iter().map(|&l| (x[l].ln(), -values[l].unwrap().ln())).collect();
    let rate = fit_line(&pts)?;
    let (first, last) = (*levels.last()?, levels[0]);
    Some(RateFit { rate, abscissa, first_level: first, last_level: last, first_ndof: ndof[first], last_ndof: ndof[last] })
}

/// `run` without its trailing levels whose value is round-off (at or below [`ROUND_OFF`] x the
/// largest value of the run: a quantity that is zero for the exact solution, like Example 7.1's
/// eta_4, decays to 1e-17): the fit of such a quantity ends where it was last above round-off
/// (its range says where) instead of finding no level at all.
pub fn above_round_off<'a>(run: &'a RunRecord, values: &[Option<f64>]) -> std::borrow::Cow<'a, RunRecord> {
    let floor = ROUND_OFF * values.iter().flatten().cloned().fold(0.0, f64::max);
    let keep = values.iter().rposition(|v| v.is_some_and(|v| v > floor)).map_or(0, |l| l + 1);
    if keep == run.levels.len() {
        return std::borrow::Cow::Borrowed(run);
    }
    let mut cut = run.clone();
    cut.levels.truncate(keep);
    std::borrow::Cow::Owned(cut)
}

/// The first level of `run` whose error (`errors`, one per level) is below [`FLOOR_MARGIN`] x the
/// level's round-off floor: from there on the error measures the round-off of u_h, not the
/// discretisation. None where every error is above (or the run has no floor on record).
pub fn floor_hit(run: &RunRecord, errors: &[Option<f64>]) -> Option<usize> {
    run.levels.iter().zip(errors).position(|(l, e)| e.is_some_and(|e| e < FLOOR_MARGIN * l.roundoff_floor))
}

/// `run` without its levels from [`floor_hit`] on (the run itself where the floor is not hit).
pub fn above_floor<'a>(run: &'a RunRecord, errors: &[Option<f64>]) -> std::borrow::Cow<'a, RunRecord> {
    match floor_hit(run, errors) {
        None => std::borrow::Cow::Borrowed(run),
        Some(l) => {
            let mut cut = run.clone();
            cut.levels.truncate(l);
            std::borrow::Cow::Owned(cut)
        }
    }
}

/// "error above 10x the round-off floor at every level (last: 7.6e-9 vs floor 4.4e-12)" or
/// "error within 10x the round-off floor from level 41 (NDF 5.2e6: 3.1e-11 vs floor 4.0e-12); fits end at level 40".
pub fn floor_text(run: &RunRecord, errors: &[Option<f64>]) -> String {
    match floor_hit(run, errors) {
        None => match (run.levels.last(), errors.last().copied().flatten()) {
            (Some(l), Some(e)) if l.roundoff_floor > 0.0 => {
                format!("error above {FLOOR_MARGIN}x the round-off floor at every level (last: {e:.1e} vs floor {:.1e})", l.roundoff_floor)
            }
            _ => "no round-off floor on record".into(),
        },
        Some(h) => format!(
            "error within {FLOOR_MARGIN}x the round-off floor from level {h} (NDF {:.1e}: {:.1e} vs floor {:.1e}); fits end {}",
            run.levels[h].ndof as f64,
            errors[h].unwrap_or(f64::NAN),
            run.levels[h].roundoff_floor,
            if h == 0 { "before level 0".to_string() } else { format!("at level {}", h - 1) }
        ),
    }
}

/// The value of a `LevelRecord` field at every level of a run (None where absent or not a number).
pub fn field(run: &RunRecord, name: &str) -> Vec<Option<f64>> {
    run.levels.iter().map(|l| serde_json::to_value(l).ok().and_then(|v| v[name].as_f64())).collect()
}

/// A rate over the last window of a run (at least [`MIN_DECADES`] decades), and the same fit over the windows ending
/// `WINDOW_SHIFT` and 2 `WINDOW_SHIFT` levels earlier.
#[derive(Clone, Debug)]
pub struct RateReport {
    pub main: RateFit,
    pub windows: Vec<RateFit>,
}

impl RateReport {
    pub fn from_values(ndof: &[usize], values: &[Option<f64>]) -> Option<RateReport> {
        let x: Vec<f64> = ndof.iter().map(|&n| n as f64).collect();
        Self::from_values_x(ndof, &x, Abscissa::Ndof, values)
    }

    /// Fitted against `x` ([`rate_over_x`]).
    pub fn from_values_x(ndof: &[usize], x: &[f64], abscissa: Abscissa, values: &[Option<f64>]) -> Option<RateReport> {
        let end = ndof.len().checked_sub(1)?;
        let main = rate_over_x(ndof, x, abscissa, values, end)?;
        let windows =
            (0..3).filter_map(|k| end.checked_sub(k * WINDOW_SHIFT)).filter_map(|e| rate_over_x(ndof, x, abscissa, values, e)).collect();
        Some(RateReport { main, windows })
    }

    /// The rate of `values` (one per level of `run`) against the run's [`abscissa_of`].
    pub fn of_values(run: &RunRecord, values: &[Option<f64>]) -> Option<RateReport> {
        let ndof: Vec<usize> = run.levels.iter().map(|l| l.ndof).collect();
        let abscissa = abscissa_of(run);
        let x: Vec<f64> = match abscissa {
            Abscissa::Ndof => ndof.iter().map(|&n| n as f64).collect(),
            Abscissa::InverseHMin => run.levels.iter().map(|l| 1.0 / l.h_min).collect(),
        };
        Self::from_values_x(&ndof, &x, abscissa, values)
    }

    pub fn of(run: &RunRecord, name: &str) -> Option<RateReport> {
        Self::of_values(run, &field(run, name))
    }

    /// "1.52 ± 0.04 (levels .., NDF ..; windows 1.52, 1.50, 1.49)"
    pub fn text(&self) -> String {
        format!(
            "{} ({}; windows {})",
            self.main.text(),
            self.main.range(),
            self.windows.iter().map(|w| format!("{:.2}", w.rate.slope)).collect::<Vec<_>>().join(", ")
        )
    }

    /// Largest minus smallest slope over the three windows.
    pub fn spread(&self) -> f64 {
        let s = self.windows.iter().map(|w| w.rate.slope);
        s.clone().fold(f64::NEG_INFINITY, f64::max) - s.fold(f64::INFINITY, f64::min)
    }
}

/// What a rate interval says about a claimed rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateVerdict {
    Reproduced,
    /// Slower than the claim: the interval lies below claim - RATE_BAND.
    NotReproduced,
    /// Faster than the claim: the interval lies above claim + RATE_BAND.
    Different,
    Inconclusive,
}

impl RateVerdict {
    pub fn text(self) -> &'static str {
        match self {
            RateVerdict::Reproduced => "reproduced",
            RateVerdict::NotReproduced => "not reproduced (slower)",
            RateVerdict::Different => "different (faster than claimed)",
            RateVerdict::Inconclusive => "inconclusive",
        }
    }
}

/// The variable the theory speaks of for this run: h_min under uniform refinement, NDF otherwise.
pub fn abscissa_of(run: &RunRecord) -> Abscissa {
    match run.run.refine {
        model::settings::adapt::Refine::Uniform => Abscissa::InverseHMin,
        model::settings::adapt::Refine::Adaptive => Abscissa::Ndof,
    }
}

/// The rules of the module docs: `claim` is a rate in NDF (NDF^-claim), converted to the fit's
/// abscissa.
pub fn judge_rate(fit: &RateFit, claim: f64) -> RateVerdict {
    let (lo, hi) = (fit.rate.lo(), fit.rate.hi());
    let (c, band) = fit.claim_in_abscissa(claim);
    if !fit.spans_enough() {
        RateVerdict::Inconclusive
    } else if hi < c - band {
        RateVerdict::NotReproduced
    } else if lo > c + band {
        RateVerdict::Different
    } else if lo >= c - band && hi <= c + band {
        RateVerdict::Reproduced
    } else {
        RateVerdict::Inconclusive
    }
}

/// Why a verdict is fragile: the windows ending `WINDOW_SHIFT` and 2 `WINDOW_SHIFT` levels
/// earlier give other verdicts ("windows 2, 4 levels earlier: inconclusive, reproduced"); None
/// when every window agrees.
pub fn window_fragility(rep: &RateReport, claim: f64) -> Option<String> {
    let main = judge_rate(&rep.main, claim);
    let others: Vec<RateVerdict> = rep.windows.iter().skip(1).map(|w| judge_rate(w, claim)).collect();
    others.iter().any(|v| *v != main).then(|| {
        format!(
            "the windows ending {} and {} levels earlier give {}",
            WINDOW_SHIFT,
            2 * WINDOW_SHIFT,
            others.iter().map(|v| v.text()).collect::<Vec<_>>().join(", ")
        )
    })
}

/// Trend of a quantity: slope of log(value) against log(NDF) over the last two decades
/// ([`window`]; positive: growing).
pub fn growth(ndof: &[usize], values: &[Option<f64>]) -> Option<RateFit> {
    let mut f = rate_over(ndof, values, ndof.len().checked_sub(1)?)?;
    f.rate.slope = -f.rate.slope;
    Some(f)
}

/// What a trend interval says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trend {
    Bounded,
    Growing,
    Falling,
    /// The interval contains 0 but is wider than `MAX_WIDTH`: it cannot tell bounded from growing.
    Inconclusive,
    /// The window spans less than [`MIN_DECADES`]: no verdict, whatever the interval.
    Short,
}

impl Trend {
    pub fn text(self) -> &'static str {
        match self {
            Trend::Bounded => "bounded",
            Trend::Growing => "growing",
            Trend::Falling => "falling",
            Trend::Inconclusive => "inconclusive (interval wider than 0.3)",
            Trend::Short => "inconclusive (window shorter than two decades)",
        }
    }
}

/// Bounded: the growth interval contains 0 and is at most `MAX_WIDTH` wide (a wider interval
/// containing 0 is inconclusive, whatever its centre).
pub fn judge_trend(growth: &RateFit) -> Trend {
    let contains_zero = growth.rate.lo() <= 0.0 && 0.0 <= growth.rate.hi();
    if !growth.spans_enough() {
        Trend::Short
    } else if contains_zero && growth.rate.width() <= MAX_WIDTH {
        Trend::Bounded
    } else if contains_zero {
        Trend::Inconclusive
    } else if growth.rate.slope > 0.0 {
        Trend::Growing
    } else {
        Trend::Falling
    }
}

/// Singular exponent lambda in (1/2, 1) of the displacement u ~ r^lambda at a corner of angle
/// pi/2 where a clamped side (u = 0) meets a traction-free side, in plane strain with Poisson
/// ratio `nu`: the smallest root of the eigenvalue equation
/// 4 lambda^2 = 1 + kappa^2 + 2 kappa cos(lambda pi), kappa = 3 - 4 nu,
/// which is Williams' characteristic equation of the clamped/free wedge of opening omega,
/// 4 lambda^2 sin^2(omega) = 1 + kappa^2 + 2 kappa cos(2 lambda omega), at omega = pi/2 (at
/// omega = pi it gives the known oscillatory exponents 1/2 ± i ln(kappa) / (2 pi)). For
/// nu = 0.3 (Example 7.2) lambda = 0.7112. Under uniform refinement the L-infinity error near
/// such a corner decays like h^lambda = NDF^(-lambda/2).
pub fn clamped_free_corner_exponent(nu: f64) -> f64 {
    let kappa = 3.0 - 4.0 * nu;
    let f = |l: f64| 4.0 * l * l - 1.0 - kappa * kappa - 2.0 * kappa * (l * std::f64::consts::PI).cos();
    let (mut lo, mut hi) = (0.5, 1.0);
    assert!(f(lo) < 0.0 && f(hi) > 0.0, "no root of the corner eigenvalue equation in (1/2, 1) for nu = {nu}");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use model::base::stats::t_quantile_975;

    #[test]
    fn t_quantiles_match_tables() {
        for (dof, t) in [(1, 12.7062), (2, 4.3027), (5, 2.5706), (10, 2.2281), (30, 2.0423), (1000, 1.9623)] {
            assert!((t_quantile_975(dof) - t).abs() < 1e-3, "dof {dof}: {} vs {t}", t_quantile_975(dof));
        }
    }

    #[test]
    fn corner_exponent_solves_its_equation() {
        let l = clamped_free_corner_exponent(0.3);
        let kappa: f64 = 3.0 - 4.0 * 0.3;
        assert!((4.0 * l * l - 1.0 - kappa * kappa - 2.0 * kappa * (l * std::f64::consts::PI).cos()).abs() < 1e-12);
        assert!((l - 0.7112).abs() < 5e-4, "{l}");
        // error reduction per halving of h: 2^-lambda = 0.611 (0.608 as measured)
        assert!((0.5f64.powf(l) - 0.61).abs() < 0.01);
    }

    /// A fit with a given slope and half-width over `decades` of NDF (against NDF).
    fn fit(slope: f64, half_width: f64, decades: f64) -> RateFit {
        RateFit {
            rate: LineFit { slope, half_width, points: 6 },
            abscissa: Abscissa::Ndof,
            first_level: 0,
            last_level: 10,
            first_ndof: 1000,
            last_ndof: (1000.0 * 10f64.powf(decades)) as usize,
        }
    }

    #[test]
    fn reproduced_only_when_the_whole_interval_lies_in_the_band() {
        assert_eq!(judge_rate(&fit(1.52, 0.05, 2.5), 1.5), RateVerdict::Reproduced);
        assert_eq!(judge_rate(&fit(1.42, 0.02, 2.5), 1.5), RateVerdict::Reproduced, "inside the band without containing c");
        // touches c, 0.29 wide: it reaches outside the band, however central
        assert_eq!(judge_rate(&fit(1.355, 0.146, 2.5), 1.5), RateVerdict::Inconclusive);
        assert_eq!(judge_rate(&fit(1.5, 0.145, 2.5), 1.5), RateVerdict::Inconclusive, "centred on c, wider than the band");
        assert_eq!(judge_rate(&fit(1.2, 0.05, 2.5), 1.5), RateVerdict::NotReproduced);
        assert_eq!(judge_rate(&fit(1.8, 0.05, 2.5), 1.5), RateVerdict::Different);
        // a window shorter than two decades decides nothing, however clear the interval
        assert_eq!(judge_rate(&fit(1.5, 0.01, 1.9), 1.5), RateVerdict::Inconclusive, "less than two decades");
        assert_eq!(judge_rate(&fit(1.0, 0.01, 1.5), 1.5), RateVerdict::Inconclusive, "a slow rate over a decade and a half");
        assert_eq!(judge_rate(&fit(2.0, 0.01, 1.5), 1.5), RateVerdict::Inconclusive, "a fast rate over a decade and a half");
    }

    #[test]
    fn bounded_only_with_a_narrow_interval_around_zero() {
        assert_eq!(judge_trend(&fit(0.02, 0.12, 2.0)), Trend::Bounded);
        // contains 0 but 0.43 wide: no verdict, even with a flat centre (no |slope| < 0.05 escape)
        assert_eq!(judge_trend(&fit(0.02, 0.215, 2.0)), Trend::Inconclusive);
        assert_eq!(judge_trend(&fit(-0.02, 0.37, 2.0)), Trend::Inconclusive);
        assert_eq!(judge_trend(&fit(0.04, 0.01, 2.0)), Trend::Growing, "a small slope known precisely is a trend");
        assert_eq!(judge_trend(&fit(-0.14, 0.11, 2.0)), Trend::Falling);
        assert_eq!(judge_trend(&fit(0.3, 0.01, 1.5)), Trend::Short, "a clear growth over a decade and a half is no verdict");
    }

    #[test]
    fn a_drifting_window_is_fragile() {
        // error ~ NDF^-1.5 on the last levels, NDF^-1 before: the earlier windows see the slower rate
        let ndof: Vec<usize> = (0..20).map(|l| 100 * 2usize.pow(l)).collect();
        let mut log_e = 0.0;
        let values: Vec<Option<f64>> = (0..20)
            .map(|l| {
                if l > 0 {
                    log_e -= if l >= 16 { 1.5 } else { 1.0 } * 2f64.ln();
                }
                Some(log_e.exp())
            })
            .collect();
        let rep = RateReport::from_values(&ndof, &values).unwrap();
        assert!(window_fragility(&rep, 1.5).is_some(), "{}", rep.text());
        let steady: Vec<Option<f64>> = ndof.iter().map(|&n| Some((n as f64).powf(-1.5))).collect();
        assert_eq!(window_fragility(&RateReport::from_values(&ndof, &steady).unwrap(), 1.5), None);
    }

    #[test]
    fn uniform_exponents_are_fitted_against_h_min() {
        // NDF = 2(2N + 1)^2 on structured:N, h = 1/N: error = h^0.7112 exactly
        let n: Vec<f64> = (2..12).map(|k| 2f64.powi(k)).collect();
        let ndof: Vec<usize> = n.iter().map(|n| (2.0 * (2.0 * n + 1.0) * (2.0 * n + 1.0)) as usize).collect();
        let values: Vec<Option<f64>> = n.iter().map(|n| Some(n.powf(-0.7112))).collect();
        let in_h = RateReport::from_values_x(&ndof, &n, Abscissa::InverseHMin, &values).unwrap();
        assert!((in_h.main.rate.slope - 0.7112).abs() < 1e-9, "{}", in_h.text());
        let in_ndof = RateReport::from_values(&ndof, &values).unwrap();
        assert!((2.0 * in_ndof.main.rate.slope - 0.7112).abs() > 1e-3, "the NDF fit is biased on coarse meshes: {}", in_ndof.text());
        // judged against the claim in h: NDF^-(lambda/2) is h^lambda, band doubled
        assert_eq!(judge_rate(&in_h.main, 0.7112 / 2.0), RateVerdict::Reproduced);
    }

    #[test]
    fn window_reaches_back_two_decades_on_every_other_level() {
        let ndof: Vec<usize> = (0..14).map(|l| 100 * 2usize.pow(l)).collect();
        // two decades are reached at level 5 (2^8 >= 100), five points at level 5 too
        assert_eq!(window(&ndof, 13), vec![5, 7, 9, 11, 13]);
        assert_eq!(window(&ndof, 2), vec![0, 2]);
        // fast growth: the five points decide (level 3 spans 2^10)
        let fast: Vec<usize> = (0..14).map(|l| 100 * 4usize.pow(l)).collect();
        assert_eq!(window(&fast, 13), vec![5, 7, 9, 11, 13]);
        // slow growth: the two decades decide
        let slow: Vec<usize> = (0..60).map(|l| (100.0 * 1.2f64.powi(l)) as usize).collect();
        let w = window(&slow, 59);
        assert!((slow[59] as f64 / slow[w[0]] as f64) >= 100.0 && (slow[59] as f64 / slow[w[1]] as f64) < 100.0, "{w:?}");
    }
}

/// Refinement locations, tested as what they are: a claimed location is a refinement centre when
/// the local mesh size h has a local minimum (or a plateau of its own) there.
pub mod refinement {
    use store::records::MeshSnapshot;

    /// One mesh edge on a boundary segment: parameter range [s0, s1] along the segment and length.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct SegmentEdge {
        pub s0: f64,
        pub s1: f64,
        pub h: f64,
    }

    /// The edges of the triangulation lying on the segment from `a` to `b` (both end points on
    /// it), sorted along it; s in [0, 1].
    pub fn profile(m: &MeshSnapshot, a: [f64; 2], b: [f64; 2]) -> Vec<SegmentEdge> {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let len = len2.sqrt();
        let on = |p: [f64; 2]| -> Option<f64> {
            let q = [p[0] - a[0], p[1] - a[1]];
            let s = (q[0] * d[0] + q[1] * d[1]) / len2;
            let off = (q[0] * d[1] - q[1] * d[0]).abs() / len;
            (off <= 1e-12 * len && (-1e-12..=1.0 + 1e-12).contains(&s)).then_some(s)
        };
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        for t in &m.triangles {
            for i in 0..3 {
                let (u, v) = (t[i], t[(i + 1) % 3]);
                if !seen.insert((u.min(v), u.max(v))) {
                    continue;
                }
                if let (Some(s0), Some(s1)) = (on(m.vertices[u]), on(m.vertices[v])) {
                    let (s0, s1) = (s0.min(s1), s0.max(s1));
                    out.push(SegmentEdge { s0, s1, h: (s1 - s0) * len });
                }
            }
        }
        out.sort_by(|x, y| x.s0.total_cmp(&y.s0));
        out
    }

    /// The mesh size at a point and on either side of it.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct LocalMinimum {
        /// Smallest edge among the edge containing the point and its two neighbours.
        pub h_at: f64,
        /// Smallest and largest edge on each side within `reach` (None: no edge there).
        pub left: Option<(f64, f64)>,
        pub right: Option<(f64, f64)>,
        pub holds: bool,
    }

    impl LocalMinimum {
        pub fn text(&self) -> String {
            let side = |s: Option<(f64, f64)>| s.map(|(lo, hi)| format!("{lo:.1e}..{hi:.1e}")).unwrap_or("none".into());
            format!("h {:.1e} there, {} before, {} after", self.h_at, side(self.left), side(self.right))
        }
    }

    /// Is the point at parameter `s` a local minimum (or its own plateau) of h along the profile?
    /// Near = the edge containing s and one edge either side; each side = the further edges within
    /// `reach` (in parameter units). It holds when no edge on either side is smaller than near,
    /// and h grows somewhere on each side that has edges (at least one side must have edges).
    pub fn local_minimum(profile: &[SegmentEdge], s: f64, reach: f64) -> Option<LocalMinimum> {
        let k = profile.iter().position(|e| e.s0 <= s && s <= e.s1)?;
        let near = k.saturating_sub(1)..(k + 2).min(profile.len());
        let h_at = profile[near.clone()].iter().map(|e| e.h).fold(f64::INFINITY, f64::min);
        let range = |es: &[SegmentEdge]| -> Option<(f64, f64)> {
            (!es.is_empty()).then(|| (es.iter().map(|e| e.h).fold(f64::INFINITY, f64::min), es.iter().map(|e| e.h).fold(0.0, f64::max)))
        };
        let left: Vec<SegmentEdge> = profile[..near.start].iter().filter(|e| e.s0 >= s - reach).copied().collect();
        let right: Vec<SegmentEdge> = profile[near.end..].iter().filter(|e| e.s1 <= s + reach).copied().collect();
        let (left, right) = (range(&left), range(&right));
        let side_ok = |r: Option<(f64, f64)>| r.is_none_or(|(lo, hi)| lo >= h_at && hi > h_at);
        let holds = (left.is_some() || right.is_some()) && side_ok(left) && side_ok(right);
        Some(LocalMinimum { h_at, left, right, holds })
    }

    /// Smallest element diameter among triangles with centroid within `r` of `p`, and among those
    /// with centroid between `r` and `reach`: a corner is a refinement centre when the first is
    /// smaller than the second.
    pub fn corner(m: &MeshSnapshot, p: [f64; 2], r: f64, reach: f64) -> (f64, f64) {
        let (mut inner, mut ring) = (f64::INFINITY, f64::INFINITY);
        for t in &m.triangles {
            let v = t.map(|i| m.vertices[i]);
            let c = [(v[0][0] + v[1][0] + v[2][0]) / 3.0, (v[0][1] + v[1][1] + v[2][1]) / 3.0];
            let d = (0..3).map(|i| model::mesh::dist(v[i], v[(i + 1) % 3])).fold(0.0, f64::max);
            let dc = model::mesh::dist(c, p);
            if dc <= r {
                inner = inner.min(d);
            } else if dc <= reach {
                ring = ring.min(d);
            }
        }
        (inner, ring)
    }
}
