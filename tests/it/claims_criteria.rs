//! Every CLAIMS row states what would fail it, from the criterion its verdict applies
//! (`claims::criterion`); rows of one kind are judged by one rule, whatever the problem or the
//! contact term; and every kind of row can fail: the stored records altered in memory (a rate
//! moved, an efficiency made to grow or fall, errors made larger, the free-boundary edge made to
//! stall, a contact term made to appear, a reference made coarse) flip the verdicts of its rows.

use signorini::claims::{self, Claim, Criterion, RowKind, Verdict, terms};
use signorini::records::RunRecord;
use signorini::store::Shelf;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn stored_shelf() -> Shelf {
    crate::common::shelf(Path::new("results"))
}

fn verdicts(shelf: &Shelf) -> Vec<Claim> {
    claims::claims(shelf, crate::common::roles()).unwrap()
}

fn fails(v: Verdict) -> bool {
    matches!(v, Verdict::NotReproduced | Verdict::Different | Verdict::Fails)
}

fn passes(v: Verdict) -> bool {
    matches!(v, Verdict::Reproduced | Verdict::Holds)
}

/// Whether a row's criterion is one check with a reference part (a row over several runs, some
/// without a reference, is judged run by run: its other runs may still fail it).
fn has_reference_part(c: &Criterion) -> bool {
    matches!(c, Criterion::All(parts) if parts.iter().any(|p| matches!(p, Criterion::Reference { .. })))
}

/// Multiply `f`'s value at every level of `r` by (NDF / NDF_0)^power: its rate in NDF moves by
/// -power (its trend by +power).
fn scale_by_ndof(r: &mut RunRecord, power: f64, f: impl Fn(&mut signorini::level::record::LevelRecord) -> Vec<&mut f64>) {
    let n0 = r.levels.first().map_or(1.0, |l| l.ndof as f64);
    for l in &mut r.levels {
        let factor = (l.ndof as f64 / n0).powf(power);
        for v in f(l) {
            *v *= factor;
        }
    }
}

/// Every error and estimator quantity a rate row fits.
fn rated(l: &mut signorini::level::record::LevelRecord) -> Vec<&mut f64> {
    let t = &mut l.terms;
    let mut out: Vec<&mut f64> = vec![
        &mut t.eta1,
        &mut t.eta2,
        &mut t.eta3,
        &mut t.eta4,
        &mut t.eta5,
        &mut t.eta6,
        &mut t.eta7,
        &mut t.psi,
        &mut t.eta_h,
        &mut t.estimate,
    ];
    out.extend([&mut l.err_quadrature, &mut l.err_dense, &mut l.err_contact, &mut l.err_right_half].into_iter().flatten());
    out
}

#[test]
fn every_row_states_what_would_fail_it_and_claims_md_is_what_the_records_render() {
    let c = verdicts(&stored_shelf());
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
fn rows_of_one_kind_are_judged_by_one_rule_on_every_problem_and_contact_term() {
    let c = verdicts(&stored_shelf());
    let mut rules: BTreeMap<RowKind, BTreeSet<String>> = BTreeMap::new();
    for r in &c {
        match r.row {
            RowKind::Finding => {}
            RowKind::Measured => {
                assert!(matches!(r.criterion, Criterion::Reported { .. }), "{}: a measurement with a criterion", r.id);
                assert_eq!(r.verdict, Verdict::NoClaim, "{}", r.id);
            }
            kind => {
                rules.entry(kind).or_default().insert(r.criterion.rule());
            }
        }
    }
    for kind in [RowKind::Rate, RowKind::Efficiency, RowKind::EfficiencyUpToLh, RowKind::Reliability, RowKind::Refinement] {
        let r = rules.get(&kind).unwrap_or_else(|| panic!("no row of kind {kind:?}"));
        assert_eq!(r.len(), 1, "rows of kind {kind:?} are judged by different rules: {r:#?}");
    }
    // every claim of the paper is judged for every contact term
    let mut per_claim: BTreeMap<&str, BTreeSet<_>> = BTreeMap::new();
    for r in c.iter().filter(|r| r.kind() == claims::Kind::Paper) {
        assert!(!r.terms.is_empty(), "{}: a claim of the paper judged for no contact term", r.id);
        per_claim.entry(r.id.split(" (").next().unwrap()).or_default().extend(r.terms.iter().map(|t| terms::name(*t)));
    }
    for (id, t) in &per_claim {
        assert_eq!(t.len(), terms::ALL.len(), "{id} is not judged for every contact term: {t:?}");
    }
}

#[test]
fn the_headline_counts_the_papers_claims_per_contact_term_and_a_fragile_pass_as_undecided() {
    let c = verdicts(&stored_shelf());
    let md = claims::markdown_for(&c, Path::new("results"));
    let head = md.split("## Headline\n\n").nth(1).unwrap().split("\n## ").next().unwrap();
    assert!(head.lines().filter(|l| !l.is_empty()).count() <= 10, "the headline is at most ten lines: {head}");
    for t in terms::ALL {
        let rows: Vec<&Claim> = c.iter().filter(|r| r.kind() == claims::Kind::Paper && r.terms.contains(&t)).collect();
        let robust = rows.iter().filter(|r| passes(r.verdict) && r.fragile.is_none()).count();
        let line = head
            .lines()
            .find(|l| l.starts_with(&format!("- **{}**", terms::name(t))))
            .unwrap_or_else(|| panic!("no line for {t:?}: {head}"));
        assert!(line.contains(&format!("of the paper's {} Section 7 claims, {robust} reproduce", rows.len())), "{line}");
    }
}

/// A change to every stored record, made in memory.
type Alteration = Box<dyn Fn(&mut RunRecord)>;

/// Each kind of row, by an alteration of the stored records that its criterion must see.
#[test]
fn every_kind_of_row_fails_when_the_records_are_altered_against_it() {
    let before = verdicts(&stored_shelf());
    let kinds: BTreeSet<RowKind> = before.iter().map(|c| c.row).collect();
    // (kind, alteration, what the rows of that kind must become)
    let far_reference = |r: &mut RunRecord| r.reference_ndof = r.reference_ndof.map(|n| n * 1000);
    let checks: Vec<(RowKind, &str, Alteration)> = vec![
        (
            RowKind::Rate,
            "every rate 0.6 slower",
            Box::new(move |r| {
                scale_by_ndof(r, 0.6, rated);
                far_reference(r);
            }),
        ),
        (
            RowKind::Efficiency,
            "the estimate growing at 0.6 against the error",
            Box::new(move |r| {
                scale_by_ndof(r, 0.6, |l| vec![&mut l.terms.estimate]);
                far_reference(r);
            }),
        ),
        (
            RowKind::Efficiency,
            "the estimate falling at 0.6 against the error",
            Box::new(move |r| {
                scale_by_ndof(r, -0.6, |l| vec![&mut l.terms.estimate]);
                far_reference(r);
            }),
        ),
        (
            RowKind::EfficiencyUpToLh,
            "the estimate growing at 0.6 against the error",
            Box::new(move |r| {
                scale_by_ndof(r, 0.6, |l| vec![&mut l.terms.estimate]);
                far_reference(r);
            }),
        ),
        (
            RowKind::Reliability,
            "every error 1e4 times larger",
            Box::new(|r| {
                for l in &mut r.levels {
                    for e in [&mut l.err_quadrature, &mut l.err_dense].into_iter().flatten() {
                        *e *= 1e4;
                    }
                }
            }),
        ),
        (
            RowKind::Refinement,
            "the free-boundary edge shrinking 0.8 slower",
            Box::new(|r| {
                scale_by_ndof(r, 0.8, |l| l.h_free_boundary.as_mut().into_iter().collect());
            }),
        ),
        (
            RowKind::Vanishing,
            "eta_6 of 1e-3 at the last level",
            Box::new(|r| {
                if let Some(l) = r.levels.last_mut() {
                    l.terms.eta6 = 1e-3;
                }
            }),
        ),
    ];
    for kind in &kinds {
        let covered = checks.iter().any(|(k, ..)| k == kind) || matches!(kind, RowKind::Finding | RowKind::Measured);
        assert!(covered, "no alteration shows that rows of kind {kind:?} can fail");
    }
    for (kind, what, alter) in &checks {
        let after = verdicts(&stored_shelf().alter(alter));
        let rows: Vec<(&Claim, &Claim)> = before
            .iter()
            .filter(|c| c.row == *kind && c.verdict != Verdict::NoData)
            .map(|b| (b, after.iter().find(|a| a.id == b.id).unwrap_or_else(|| panic!("{} gone after: {what}", b.id))))
            .collect();
        assert!(!rows.is_empty(), "no row of kind {kind:?}");
        for (b, a) in rows {
            assert!(
                fails(a.verdict),
                "{} ({kind:?}, {:?} before) does not fail with {what}: {:?}, {}",
                b.id,
                b.verdict,
                a.verdict,
                a.summary.headline
            );
        }
    }
}

#[test]
fn a_coarse_reference_leaves_every_row_that_measures_against_it_undecided() {
    let before = verdicts(&stored_shelf());
    // a reference as coarse as each run's middle level: its own error is as large as the errors
    let after = verdicts(&stored_shelf().alter(|r| {
        let middle = r.levels.get(r.levels.len() / 2).map(|l| l.ndof);
        if let (Some(n), Some(m)) = (r.reference_ndof.as_mut(), middle) {
            *n = m;
        }
    }));
    let with_reference: Vec<&Claim> = before.iter().filter(|c| has_reference_part(&c.criterion)).collect();
    assert!(with_reference.len() >= 5, "{} rows measure against a reference", with_reference.len());
    for b in with_reference {
        let a = after.iter().find(|a| a.id == b.id).unwrap();
        assert!(
            !passes(a.verdict) && !fails(a.verdict),
            "{}: {:?} with a reference as coarse as the run's middle level ({:?} before): {}",
            b.id,
            a.verdict,
            b.verdict,
            a.measured
        );
    }
}

/// A verdict that the other parity of levels changes is fragile, and the row `parity` counts it.
#[test]
fn a_verdict_that_depends_on_the_parity_of_levels_is_fragile() {
    let shelf = stored_shelf();
    let roles = crate::common::roles();
    let c = verdicts(&shelf);
    let last = claims::claims_with(&shelf, roles, claims::ErrorSampling::Quadrature, claims::Parity::Last).unwrap();
    let other = claims::claims_with(&shelf, roles, claims::ErrorSampling::Quadrature, claims::Parity::Other).unwrap();
    let mut flips = 0;
    for (l, o) in last.iter().zip(&other) {
        assert_eq!(l.id, o.id, "both parities give the same rows");
        if l.verdict != o.verdict {
            flips += 1;
            let r = c.iter().find(|r| r.id == l.id).unwrap();
            assert!(r.fragile.as_deref().is_some_and(|f| f.contains("other parity")), "{}: {:?}", r.id, r.fragile);
        }
    }
    let parity = c.iter().find(|r| r.id == "parity").expect("the row parity");
    assert!(parity.summary.headline.starts_with(&format!("{flips} of ")), "{}", parity.summary.headline);
}

#[test]
fn the_c0_row_names_the_runs_it_leaves_out() {
    let claims = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/results/CLAIMS.md")).unwrap();
    // the row's claim and measured lines
    let at = claims.find("in all experiments with repaired").expect("row c0 (repaired), where the l_h = 1 runs are");
    let row = claims[at..].lines().take_while(|l| !l.starts_with("**Verdict")).collect::<Vec<_>>().join("\n");
    assert!(row.contains("whose eta_h carries the paper's log factor l_h (6.3)"), "{row}");
    assert!(row.contains("Left out, with another l_h:"), "{row}");
    // the estimator repair's l_h = 1 runs have an error and another eta_h: named, not counted
    assert!(row.contains("estimator_repair/ex71_adaptive_l1 (log_factor one)"), "{row}");
    assert!(!row.contains("estimator_repair/ex71_adaptive_l1: estimate/error"), "{row}");
}
