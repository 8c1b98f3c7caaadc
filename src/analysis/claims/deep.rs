//! The rows of the deep study (`experiments/deep.toml`): Example 7.1 and fb, which have exact
//! solutions, adaptively with the three contact terms to about 1e7 NDF and uniformly to 8.4e6,
//! their error rates fitted over windows of [`DEEP_DECADES`] decades of NDF (the last levels),
//! so that a verdict no longer rests on one pre-asymptotic decade.

use super::{Claim, Ctx, OPTIMAL, Q, Verdict, fragility, growth_text, judge, run};
use crate::records::{RunRecord, StudyDir};
use crate::verdict::{self, RateReport};

/// The span of the deep fits, in decades of NDF.
pub const DEEP_DECADES: f64 = 2.0;

/// The half-width a deep rate verdict aims at (issue: <= 0.05 on every rate verdict).
pub const TARGET_HALF_WIDTH: f64 = 0.05;

const STUDY: &str = "deep";

pub(super) fn claims(ctx: &Ctx, out: &mut Vec<Claim>) -> std::io::Result<()> {
    let runs = StudyDir::new(ctx.results, STUDY).read_runs()?;
    for (problem, id, claim) in [
        (
            "ex71",
            "7.1-deep (two decades)",
            "Ex. 7.1: the error converges at NDF^(-3/2) under adaptive refinement (Fig. 2a), judged over the last two decades of NDF of runs to about 1e7 NDF (study deep), for eta_5 as written (the paper's estimator, the verdict), without full-contact nodes and repaired; uniform refinement in h_min beside them",
        ),
        (
            "fb",
            "fb-deep (beyond the paper)",
            "fb: the same over the last two decades of runs to about 1e7 NDF (study deep), the verdict for eta_5 as written",
        ),
    ] {
        out.push(row(ctx, &runs, problem, id, claim));
    }
    Ok(())
}

/// The error rate over the last [`DEEP_DECADES`] above the round-off floor.
fn rate(ctx: &Ctx, r: Option<&RunRecord>) -> Option<RateReport> {
    ctx.rate_spanning(r, Q::Error, DEEP_DECADES)
}

fn row(ctx: &Ctx, runs: &[RunRecord], problem: &str, id: &'static str, claim: &str) -> Claim {
    let get = |v: &str| run(runs, &format!("{problem}_{v}"));
    let variants = ["as_written", "without_full_contact", "repaired", "uniform"];
    let reports: Vec<Option<RateReport>> = variants.iter().map(|v| rate(ctx, get(v))).collect();
    let main = reports[0].as_ref();
    let measured = if get("as_written").is_none() {
        "no data (study deep not run)".to_string()
    } else {
        let parts: Vec<String> = variants
            .iter()
            .zip(&reports)
            .map(|(v, r)| {
                let r = r.as_ref();
                let final_ndof = get(v).and_then(|r| r.levels.last()).map(|l| l.ndof).unwrap_or(0);
                let text = match r {
                    None => "n/a".to_string(),
                    Some(r) => format!(
                        "{} → {}{}",
                        r.text(),
                        verdict::judge_rate(&r.main, OPTIMAL).text(),
                        if r.main.rate.half_width <= TARGET_HALF_WIDTH { "" } else { " (wider than ± 0.05)" }
                    ),
                };
                let eff = if *v == "uniform" {
                    String::new()
                } else {
                    format!("; {}", growth_text("efficiency", ctx.growth(get(v), Q::Efficiency).as_ref()))
                };
                let floor = get(v).map(|r| ctx.floor_text(r)).unwrap_or_default();
                format!("{v} (to NDF {final_ndof}): error rate {text}{eff}; {floor}")
            })
            .collect();
        parts.join(". ")
    };
    Claim {
        fragile: fragility(main, OPTIMAL),
        id,
        claim: claim.into(),
        measured,
        verdict: if get("as_written").is_none() { Verdict::NoData } else { judge(main, OPTIMAL) },
    }
}
