//! Every CLAIMS row states what would fail it, from the criterion its verdict applies
//! (`claims::criterion`): the rendered CLAIMS.md carries the condition in every evidence section,
//! the stored CLAIMS.md is what the records render, and for several rows evidence built to
//! violate the condition as stated (its numbers read back from the text) fails the row, while
//! evidence inside it passes.

use signorini::base::stats::LineFit;
use signorini::claims::{self, Claim, Criterion, Evidence, Verdict};
use signorini::verdict::{Abscissa, RateFit};
use std::path::Path;

fn stored() -> Vec<Claim> {
    claims::claims(&crate::common::shelf(Path::new("results")), crate::common::roles()).unwrap()
}

fn row<'a>(c: &'a [Claim], id: &str) -> &'a Claim {
    c.iter().find(|c| c.id == id).unwrap_or_else(|| panic!("no row {id}"))
}

/// The number right after `after` in `text` ("lies below 1.400 (slower)" -> 1.4).
fn number_after(text: &str, after: &str) -> f64 {
    let rest = &text[text.find(after).unwrap_or_else(|| panic!("'{after}' not in: {text}")) + after.len()..];
    let end = rest.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e')).unwrap_or(rest.len());
    rest[..end].trim_end_matches('.').parse().unwrap_or_else(|e| panic!("no number after '{after}' in {text}: {e}"))
}

/// A fit of `slope` ± `half_width` over 2.5 decades of NDF.
fn fit(slope: f64, half_width: f64, abscissa: Abscissa) -> Evidence {
    Evidence::Fit(RateFit {
        rate: LineFit { slope, half_width, points: 8 },
        abscissa,
        first_level: 10,
        last_level: 24,
        first_ndof: 10_000,
        last_ndof: 3_162_278,
    })
}

fn fails(v: Verdict) -> bool {
    matches!(v, Verdict::NotReproduced | Verdict::Different | Verdict::Fails)
}

fn passes(v: Verdict) -> bool {
    matches!(v, Verdict::Reproduced | Verdict::Holds)
}

#[test]
fn every_row_states_what_would_fail_it_and_claims_md_is_what_the_records_render() {
    let c = stored();
    assert!(c.len() >= 20, "{} rows", c.len());
    let md = claims::markdown_for(&c, Path::new("results"));
    for r in &c {
        let f = r.criterion.fails_if();
        assert!(!f.trim().is_empty(), "{}: no failure condition", r.id);
        // a row that passes has a condition that can fail it, not a report
        if passes(r.verdict) {
            assert!(!matches!(r.criterion, Criterion::Reported { .. }), "{} passes with nothing that can fail it", r.id);
            assert!(f.contains("fails"), "{}: {f}", r.id);
        }
        let section = md.split(&format!("\n### {}\n", r.id)).nth(1).unwrap_or_else(|| panic!("no section {}", r.id));
        let section = section.split("\n### ").next().unwrap();
        assert!(section.contains(&format!("**What would fail it.** {}", claims::capitalised(&f))), "{}: {section}", r.id);
    }
    assert_eq!(md.matches("**What would fail it.**").count(), c.len());
    let on_disk = std::fs::read_to_string("results/CLAIMS.md").unwrap();
    assert!(on_disk == md, "results/CLAIMS.md differs from what `signorini figures` renders from the records: rerun it");
}

#[test]
fn a_rate_outside_the_stated_band_fails_the_rate_rows() {
    let c = stored();
    for (id, abscissa) in [
        ("7.1-error-rate", Abscissa::Ndof),
        ("fb-error-rate", Abscissa::Ndof),
        ("7.2-corners (beyond the paper)", Abscissa::InverseHMin),
        ("7.2r-error-rate (as written)", Abscissa::Ndof),
        ("7.2r-error-rate (without full-contact nodes)", Abscissa::Ndof),
        ("7.2r-error-rate (repaired)", Abscissa::Ndof),
    ] {
        let r = row(&c, id);
        let f = r.criterion.fails_if();
        let (lo, hi) = (number_after(&f, "lies below "), number_after(&f, "or above "));
        assert!(lo < hi, "{id}: {f}");
        let v = |e: Evidence| r.criterion.verdict(r.kind(), Some(&e));
        assert!(fails(v(fit(lo - 0.05, 0.02, abscissa))), "{id}: a rate below {lo} must fail: {f}");
        assert!(fails(v(fit(hi + 0.05, 0.02, abscissa))), "{id}: a rate above {hi} must fail: {f}");
        assert!(passes(v(fit((lo + hi) / 2.0, 0.02, abscissa))), "{id}: a rate in the middle of [{lo}, {hi}] passes");
        assert!(!fails(v(fit(lo + 0.01, 0.02, abscissa))), "{id}: an interval straddling {lo} is not decided");
    }
}

#[test]
fn a_growing_efficiency_and_a_c0_beyond_its_limit_fail_their_rows() {
    let c = stored();
    for id in ["7.1-efficiency", "fb-efficiency"] {
        let r = row(&c, id);
        assert!(r.criterion.fails_if().contains("excludes 0"), "{id}: {}", r.criterion.fails_if());
        assert!(fails(r.criterion.verdict(r.kind(), Some(&fit(0.2, 0.04, Abscissa::Ndof)))), "{id}");
        assert!(passes(r.criterion.verdict(r.kind(), Some(&fit(0.0, 0.04, Abscissa::Ndof)))), "{id}");
    }
    for id in ["c0", "fb-reliability"] {
        let r = row(&c, id);
        let limit = number_after(&r.criterion.fails_if(), "exceeds ");
        assert_eq!(limit, 0.45, "{id}: {}", r.criterion.fails_if());
        assert!(fails(r.criterion.verdict(r.kind(), Some(&Evidence::Value(limit * 1.01)))), "{id}");
        assert!(passes(r.criterion.verdict(r.kind(), Some(&Evidence::Value(limit)))), "{id}");
    }
    let s = row(&c, "sampling");
    assert!(fails(s.criterion.verdict(s.kind(), Some(&Evidence::Value(1.0)))));
    assert_eq!(s.criterion.verdict(s.kind(), Some(&Evidence::Value(0.0))), Verdict::Holds);
}

/// The rows of Example 7.2 on rollers that judge a rate against a limit (the uniform rate against
/// the clamped corners' h^0.711, h_fb against uniform refinement's NDF^-1/2): a rate below the
/// stated limit fails, one above it passes, one whose interval contains it is not decided; and
/// the efficiency rows fail on a growing estimate / error / l_h, pass on a bounded or falling one.
#[test]
fn the_rollers_rows_fail_below_their_stated_limits() {
    let c = stored();
    for (id, abscissa, limit) in [
        ("7.2r-uniform (beyond the paper)", Abscissa::InverseHMin, 0.711),
        ("7.2r-refinement (as written)", Abscissa::Ndof, 0.5),
        ("7.2r-refinement (without full-contact nodes)", Abscissa::Ndof, 0.5),
        ("7.2r-refinement (repaired)", Abscissa::Ndof, 0.5),
    ] {
        let r = row(&c, id);
        let f = r.criterion.fails_if();
        let stated = number_after(&f, "lies below ");
        assert!((stated - limit).abs() < 1e-3, "{id}: {f}");
        let v = |slope: f64| r.criterion.verdict(r.kind(), Some(&fit(slope, 0.02, abscissa)));
        assert!(fails(v(stated - 0.05)), "{id}: a rate below {stated} must fail: {f}");
        assert!(passes(v(stated + 0.05)), "{id}: a rate above {stated} passes");
        assert!(!fails(v(stated)) && !passes(v(stated)), "{id}: an interval containing {stated} is not decided");
        if abscissa == Abscissa::InverseHMin {
            let other = r.criterion.verdict(r.kind(), Some(&fit(stated + 0.05, 0.02, Abscissa::Ndof)));
            assert!(!passes(other) && !fails(other), "{id}: a fit against NDF decides nothing");
        }
    }
    for id in ["7.2r-efficiency (as written)", "7.2r-efficiency (without full-contact nodes)", "7.2r-efficiency (repaired)"] {
        let r = row(&c, id);
        assert!(r.criterion.fails_if().contains("lies above 0 (growing)"), "{id}: {}", r.criterion.fails_if());
        let v = |slope: f64| r.criterion.verdict(r.kind(), Some(&fit(slope, 0.04, Abscissa::Ndof)));
        assert!(fails(v(0.2)), "{id}: growing");
        assert!(passes(v(0.0)) && passes(v(-0.2)), "{id}: bounded or falling");
    }
}

/// The repair row: passes on evidence where every criterion of every problem holds and one
/// separates; one problem's reliability beyond 0.45 fails it; no separating criterion leaves it
/// undecided.
#[test]
fn one_failing_criterion_fails_the_repair_row() {
    let c = stored();
    let r = row(&c, "estimator-repair (beyond the paper)");
    let Criterion::All(parts) = &r.criterion else { panic!("{:?}", r.criterion) };
    let Criterion::Each { of, .. } = &parts[0] else { panic!("{:?}", parts[0]) };
    assert_eq!(of, &["ex71", "fb", "ex72", "hertz"], "the problems judged (Hertz's errors against its reference)");
    let f = r.criterion.fails_if();
    assert!(f.contains("exceeds 0.45") && f.contains("not decided unless"), "{f}");
    let problem = |c0: f64| {
        Some(Evidence::All(vec![
            Some(fit(1.5, 0.02, Abscissa::Ndof)),
            Some(fit(0.0, 0.05, Abscissa::Ndof)),
            Some(Evidence::Value(c0)),
            Some(Evidence::Unknowns { uniform_rate_hi: 1.499, lines: None }),
        ]))
    };
    let evidence = |c0s: [f64; 4], separates: bool| {
        Evidence::All(vec![Some(Evidence::All(c0s.iter().map(|c| problem(*c)).collect())), Some(Evidence::Bool(separates))])
    };
    assert_eq!(r.criterion.verdict(r.kind(), Some(&evidence([4e-4, 4e-4, 4e-6, 9e-7], true))), Verdict::Holds);
    assert_eq!(r.criterion.verdict(r.kind(), Some(&evidence([4e-4, 0.5, 4e-6, 9e-7], true))), Verdict::Fails);
    assert_eq!(r.criterion.verdict(r.kind(), Some(&evidence([4e-4, 4e-4, 4e-6, 0.5], true))), Verdict::Fails, "Hertz's reliability counts");
    assert_eq!(r.criterion.verdict(r.kind(), Some(&evidence([4e-4, 4e-4, 4e-6, 9e-7], false))), Verdict::Inconclusive);
}
