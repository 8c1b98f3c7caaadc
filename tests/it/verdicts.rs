//! The verdict rules on synthetic data: rate intervals cover known slopes at their nominal level,
//! super-optimal rates are "different", bounded trends are told from growing ones, refinement
//! centres are told from the coarse end of a grading, and the `fb` rows of CLAIMS.md read
//! synthetic records (and say "no data" without them).

use crate::common::scratch;
use signorini::claims::{self, Verdict};
use signorini::level::record::LevelRecord;
use signorini::records::{MeshSnapshot, RunRecord, RunSpec, StudyDir, write_json};
use signorini::settings::adapt::Refine;
use signorini::settings::estimator::EstimatorConfig;
use signorini::verdict::{self, RateReport, RateVerdict, refinement};

/// Deterministic pseudo-random numbers, roughly standard normal (sum of 12 uniforms - 6).
struct Lcg(u64);
impl Lcg {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.uniform()).sum::<f64>() - 6.0
    }
}

/// NDF growing by 1.35 per level from 200 (like an adaptive run), `levels` levels.
fn ndofs(levels: usize) -> Vec<usize> {
    (0..levels).map(|l| (200.0 * 1.35f64.powi(l as i32)) as usize).collect()
}

fn values(ndof: &[usize], rate: f64, noise: f64, rng: &mut Lcg) -> Vec<Option<f64>> {
    ndof.iter().map(|&n| Some(3.0 * (n as f64).powf(-rate) * (noise * rng.normal()).exp())).collect()
}

#[test]
fn interval_covers_a_known_slope_at_about_the_nominal_level() {
    let ndof = ndofs(24);
    let mut rng = Lcg(7);
    let trials = 400;
    let mut covered = 0;
    for _ in 0..trials {
        let r = RateReport::from_values(&ndof, &values(&ndof, 1.5, 0.05, &mut rng)).unwrap();
        let f = r.main.rate;
        assert!(r.main.decades() >= verdict::MIN_DECADES);
        covered += (f.lo() <= 1.5 && 1.5 <= f.hi()) as usize;
    }
    let share = covered as f64 / trials as f64;
    assert!((0.90..=0.99).contains(&share), "95% interval covered the true slope in {share} of the trials");
}

#[test]
fn verdicts_on_synthetic_rates() {
    let ndof = ndofs(24);
    let mut rng = Lcg(11);
    let judge = |rate: f64, noise: f64, rng: &mut Lcg| {
        let r = RateReport::from_values(&ndof, &values(&ndof, rate, noise, rng)).unwrap();
        verdict::judge_rate(&r.main, 1.5)
    };
    assert_eq!(judge(1.5, 0.01, &mut rng), RateVerdict::Reproduced);
    assert_eq!(judge(1.45, 0.01, &mut rng), RateVerdict::Reproduced, "within the band claim ± 0.1");
    assert_eq!(judge(2.0, 0.01, &mut rng), RateVerdict::Different, "a super-optimal rate is different, not reproduced");
    assert_eq!(judge(3.3, 0.05, &mut rng), RateVerdict::Different);
    assert_eq!(judge(1.0, 0.01, &mut rng), RateVerdict::NotReproduced);
    assert_eq!(judge(1.5, 0.5, &mut rng), RateVerdict::Inconclusive, "noise this large gives an interval wider than 0.3");
    // 1.3 with a tight interval: overlaps nothing of [1.4, 1.6] -> not reproduced; 1.35 ± small -> borderline
    assert_eq!(judge(1.3, 0.005, &mut rng), RateVerdict::NotReproduced);
}

#[test]
fn less_than_two_decades_is_inconclusive() {
    // 6 levels growing by 1.35: 0.65 decades in all
    let ndof = ndofs(6);
    let mut rng = Lcg(3);
    let r = RateReport::from_values(&ndof, &values(&ndof, 1.5, 0.0, &mut rng)).unwrap();
    assert!(r.main.decades() < 1.0);
    assert_eq!(verdict::judge_rate(&r.main, 1.5), RateVerdict::Inconclusive);
    // 13 levels: 1.56 decades, a clearly slow rate with a tight interval: still no verdict,
    // and the range says why (one pre-asymptotic decade and a half is not a verdict)
    let ndof = ndofs(13);
    let r = RateReport::from_values(&ndof, &values(&ndof, 1.0, 0.0, &mut rng)).unwrap();
    assert!((1.0..verdict::MIN_DECADES).contains(&r.main.decades()) && r.main.rate.half_width < 0.01);
    assert_eq!(verdict::judge_rate(&r.main, 1.5), RateVerdict::Inconclusive);
    assert!(r.main.range().contains("only 1.6 decade(s): no verdict"), "{}", r.main.range());
    let g = verdict::growth(&ndof, &values(&ndof, -0.3, 0.0, &mut rng)).unwrap();
    assert_eq!(verdict::judge_trend(&g), verdict::Trend::Short, "a growing trend over 1.6 decades is no verdict either");
    // the same over 17 levels (2.2 decades) decides
    let ndof = ndofs(17);
    let r = RateReport::from_values(&ndof, &values(&ndof, 1.0, 0.0, &mut rng)).unwrap();
    assert!(r.main.decades() >= verdict::MIN_DECADES);
    assert_eq!(verdict::judge_rate(&r.main, 1.5), RateVerdict::NotReproduced);
    assert!(!r.main.range().contains("no verdict"));
}

#[test]
fn every_other_level_removes_a_bisection_staircase() {
    // the value drops only at every second level (diameters halve every two bisections) while
    // NDF grows each level: consecutive levels would see a staircase, level pairs see the slope
    let ndof: Vec<usize> = (0..20).map(|l| 100 * 2usize.pow(l as u32)).collect();
    let v: Vec<Option<f64>> = (0..20).map(|l| Some(4f64.powf(-1.5 * (l / 2) as f64))).collect();
    let r = RateReport::from_values(&ndof, &v).unwrap();
    assert!((r.main.rate.slope - 1.5).abs() < 1e-12, "{}", r.text());
    assert!(r.main.rate.half_width < 1e-9);
    assert!(r.windows.iter().all(|w| (w.rate.slope - 1.5).abs() < 1e-12));
}

#[test]
fn flat_efficiency_is_bounded_and_rising_is_not() {
    let ndof = ndofs(24);
    let mut rng = Lcg(5);
    let flat = verdict::growth(&ndof, &values(&ndof, 0.0, 0.05, &mut rng)).unwrap();
    assert_eq!(verdict::judge_trend(&flat), verdict::Trend::Bounded, "{}", flat.text());
    // flat but so noisy that the interval is wider than 0.3: no evidence either way
    let noisy = verdict::growth(&ndof, &values(&ndof, 0.0, 0.6, &mut rng)).unwrap();
    assert!(noisy.rate.width() > verdict::MAX_WIDTH);
    assert_eq!(verdict::judge_trend(&noisy), verdict::Trend::Inconclusive, "{}", noisy.text());
    // efficiency growing like l_h = 1 + log(NDF)^2 / 4: the log factor
    let rising: Vec<Option<f64>> = ndof.iter().map(|&n| Some(1e3 * (1.0 + (n as f64).ln().powi(2) / 4.0))).collect();
    let g = verdict::growth(&ndof, &rising).unwrap();
    assert_eq!(verdict::judge_trend(&g), verdict::Trend::Growing, "{}", g.text());
    let powered = verdict::growth(&ndof, &values(&ndof, -0.3, 0.05, &mut rng)).unwrap();
    assert_eq!(verdict::judge_trend(&powered), verdict::Trend::Growing);
    let falling = verdict::growth(&ndof, &values(&ndof, 0.3, 0.05, &mut rng)).unwrap();
    assert_eq!(verdict::judge_trend(&falling), verdict::Trend::Falling);
}

/// A strip (0, 1) x (0, 1) triangulated over the vertices `xs` on both y = 0 and y = 1.
fn strip(xs: &[f64], level: usize) -> MeshSnapshot {
    let n = xs.len();
    let mut vertices: Vec<[f64; 2]> = xs.iter().map(|&x| [x, 0.0]).collect();
    vertices.extend(xs.iter().map(|&x| [x, 1.0]));
    let mut triangles = Vec::new();
    for i in 0..n - 1 {
        triangles.push([i, i + 1, n + i]);
        triangles.push([i + 1, n + i + 1, n + i]);
    }
    MeshSnapshot {
        study: "fb".into(),
        run: "adaptive_wfc".into(),
        level,
        ndof: 2 * (2 * n),
        vertices,
        triangles,
        contact_nodes: vec![],
        kinks: vec![],
    }
}

/// Vertices graded geometrically towards `a` from both sides.
fn graded_at(a: f64, k: usize) -> Vec<f64> {
    let mut xs = vec![0.0, 1.0];
    for j in 0..k {
        let d = 0.3 * 0.5f64.powi(j as i32);
        xs.push(a - d);
        xs.push(a + d);
    }
    xs.sort_by(f64::total_cmp);
    xs
}

#[test]
fn refinement_centre_is_told_from_the_coarse_end_of_a_grading() {
    let a = claims::fb_free_boundary();
    let prof = refinement::profile(&strip(&graded_at(a, 12), 0), [0.0, 0.0], [1.0, 0.0]);
    assert!(refinement::local_minimum(&prof, a, 0.15).unwrap().holds);
    assert!(!refinement::local_minimum(&prof, 0.2, 0.15).unwrap().holds, "a point on the graded slope is no refinement centre");
    // graded towards x = 1 only (the wedge tip of Ex. 7.2): a point on the way is no centre,
    // although it is finer than the far end
    let mut xs: Vec<f64> = (0..12).map(|j| 1.0 - 0.5f64.powi(j)).collect();
    xs.push(1.0);
    let prof = refinement::profile(&strip(&xs, 0), [0.0, 0.0], [1.0, 0.0]);
    let lm = refinement::local_minimum(&prof, 0.8, 0.15).unwrap();
    assert!(!lm.holds, "{}", lm.text());
    // uniform: no centre anywhere
    let xs: Vec<f64> = (0..=64).map(|i| i as f64 / 64.0).collect();
    let prof = refinement::profile(&strip(&xs, 0), [0.0, 0.0], [1.0, 0.0]);
    assert_eq!(prof.len(), 64);
    assert!(!refinement::local_minimum(&prof, a, 0.15).unwrap().holds);
}

fn record(id: &str, refine: Refine, levels: Vec<LevelRecord>) -> RunRecord {
    let run = RunSpec {
        id: id.into(),
        problem: "fb".into(),
        mesh: "structured:4".into(),
        refine,
        theta: 0.5,
        levels: levels.len(),
        max_ndof: None,
        stop_ndof: None,
        estimator: EstimatorConfig::default(),
        reference: None,
        save_levels: vec![],
        constants: Default::default(),
        inputs: Default::default(),
    };
    RunRecord { study: "fb".into(), run, levels, reference_ndof: None, history: None, snapshots: Default::default() }
}

/// Levels with error C NDF^-rate, estimate 100x the error, l_h = 1, a contact zone that closes
/// in on [a, 1] like h, and the contact edge at the free boundary shrinking like NDF^-0.75.
fn synthetic_levels(rate: f64, growth: f64, n: usize) -> Vec<LevelRecord> {
    let a = claims::fb_free_boundary();
    ndofs(n)
        .into_iter()
        .enumerate()
        .map(|(level, ndof)| {
            let err = (ndof as f64).powf(-rate);
            let h = (ndof as f64).powf(-0.5);
            let estimate = 100.0 * err * (ndof as f64).powf(growth);
            LevelRecord {
                level,
                ndof,
                h_min: h,
                zone_min: Some(a + 0.7 * h),
                zone_max: Some(1.0),
                terms: signorini::level::terms::Terms { l_h: 1.0, eta_h: estimate / 0.45, c0: 0.45, estimate, ..Default::default() },
                h_free_boundary: Some(0.5 * (ndof as f64).powf(-0.75)),
                err_quadrature: Some(err),
                err_dense: Some(1.1 * err),
                efficiency: Some(estimate / err),
                ..Default::default()
            }
        })
        .collect()
}

fn row<'a>(c: &'a [claims::Claim], id: &str) -> &'a claims::Claim {
    c.iter().find(|c| c.id == id).unwrap_or_else(|| panic!("no row {id}"))
}

#[test]
fn fb_rows_say_no_data_without_the_study() {
    let d = scratch("verdicts-empty");
    std::fs::create_dir_all(&d).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    for id in ["fb-error-rate", "fb-efficiency", "fb-refinement", "fb-error-rate (without full-contact nodes)", "fb-contact-zone"] {
        assert_eq!(row(&c, id).verdict, Verdict::NoData, "{id}");
        assert!(row(&c, id).measured.contains("no data"), "{id}: {}", row(&c, id).measured);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn fb_rows_on_synthetic_records() {
    let d = scratch("verdicts-fb");
    let dir = StudyDir::new(&d, "fb");
    std::fs::create_dir_all(dir.root.join("runs")).unwrap();
    std::fs::create_dir_all(dir.root.join("meshes")).unwrap();
    for (id, refine, rate, growth) in
        [("adaptive", Refine::Adaptive, 1.0, 0.2), ("adaptive_wfc", Refine::Adaptive, 1.5, 0.0), ("uniform", Refine::Uniform, 1.25, 0.0)]
    {
        write_json(&dir.run_file(id), &record(id, refine, synthetic_levels(rate, growth, 26))).unwrap();
    }
    let a = claims::fb_free_boundary();
    // two saved levels: the larger one is graded at a, the smaller one uniform
    write_json(&dir.mesh_file("adaptive_wfc", 20, "json"), &strip(&graded_at(a, 14), 20)).unwrap();
    write_json(&dir.mesh_file("adaptive_wfc", 3, "json"), &strip(&(0..=8).map(|i| i as f64 / 8.0).collect::<Vec<_>>(), 3)).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();

    let e = row(&c, "fb-error-rate");
    assert_eq!(e.verdict, Verdict::Fails, "judged on eta_5 as written (rate 1.0): {}", e.measured);
    assert!(e.measured.contains("the adaptive error (fb/adaptive) 1.00 ± 0.00"), "{}", e.measured);
    let w = row(&c, "fb-error-rate (without full-contact nodes)");
    assert_eq!(w.verdict, Verdict::Holds, "{}", w.measured);
    assert!(w.measured.contains("the adaptive error (fb/adaptive_wfc) 1.50 ± 0.00"), "{}", w.measured);
    // the uniform run is fitted against h_min = NDF^-1/2: NDF^-1.25 is h^2.5
    assert!(e.measured.contains("uniform (fb/uniform) 2.50 ± 0.00 (in h_min"), "{}", e.measured);
    let r = row(&c, "c0");
    assert_eq!(r.verdict, Verdict::Reproduced, "{}", r.measured);
    assert!(r.measured.contains("smallest reliable C_0 4.5e-3"), "{}", r.measured);
    let f = row(&c, "fb-efficiency");
    assert_eq!(f.verdict, Verdict::Fails, "the adaptive run's efficiency grows like NDF^0.2: {}", f.measured);
    assert_eq!(row(&c, "fb-efficiency (without full-contact nodes)").verdict, Verdict::Holds);
    let m = row(&c, "fb-refinement");
    assert_eq!(m.verdict, Verdict::Holds, "h_fb ~ NDF^-0.75, faster than uniform's NDF^-0.5: {}", m.measured);
    let z = row(&c, "fb-contact-zone");
    assert_eq!(z.verdict, Verdict::Holds, "{}", z.measured);

    // optimal as written: reproduced
    write_json(&dir.run_file("adaptive"), &record("adaptive", Refine::Adaptive, synthetic_levels(1.5, 0.2, 26))).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    assert_eq!(row(&c, "fb-error-rate").verdict, Verdict::Holds);
    write_json(&dir.run_file("adaptive"), &record("adaptive", Refine::Adaptive, synthetic_levels(1.5, 0.0, 26))).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    assert_eq!(row(&c, "fb-efficiency").verdict, Verdict::Holds);

    // a zone that stalls away from a fails
    let mut stalled = synthetic_levels(1.5, 0.0, 26);
    for l in &mut stalled {
        l.zone_min = Some(a + 0.01);
    }
    write_json(&dir.run_file("uniform"), &record("uniform", Refine::Uniform, stalled)).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    assert_eq!(row(&c, "fb-contact-zone").verdict, Verdict::Fails);
    // unreliable C_0: error above 0.45 eta_h at one level of the fit window
    let mut bad = synthetic_levels(1.5, 0.0, 26);
    bad[24].terms.estimate = 0.5 * bad[24].err_quadrature.unwrap();
    bad[24].terms.eta_h = bad[24].terms.estimate / 0.45;
    write_json(&dir.run_file("uniform"), &record("uniform", Refine::Uniform, bad)).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    assert_eq!(row(&c, "c0").verdict, Verdict::NotReproduced);

    // a deep study's runs, where stored, are the ones judged (and named)
    let deep = StudyDir::new(&d, "deep");
    std::fs::create_dir_all(deep.root.join("runs")).unwrap();
    let mut as_written = record("fb_as_written", Refine::Adaptive, synthetic_levels(1.5, 0.0, 26));
    as_written.study = "deep".into();
    write_json(&deep.run_file("fb_as_written"), &as_written).unwrap();
    let c = claims::claims(&crate::common::sealed(&d), crate::common::roles()).unwrap();
    let e = row(&c, "fb-error-rate");
    assert_eq!(e.verdict, Verdict::Holds, "{}", e.measured);
    assert!(e.measured.contains("the adaptive error (deep/fb_as_written) 1.50 ± 0.00"), "{}", e.measured);
    let w = row(&c, "fb-error-rate (without full-contact nodes)");
    assert!(w.measured.contains("(fb/adaptive_wfc)"), "the variants the deep study lacks come from fb: {}", w.measured);
    let _ = std::fs::remove_dir_all(&d);
}

/// An error that decays like NDF^-1.5 until it meets a round-off floor growing like NDF: the fit
/// ends before the first level within 10x the floor, recovers the rate, and says where the floor
/// was hit; the same fit through the floor levels would not.
#[test]
fn rate_fits_end_where_the_error_meets_the_round_off_floor() {
    let mut levels = synthetic_levels(1.5, 0.0, 40);
    for l in &mut levels {
        l.roundoff_floor = 1e-17 * l.ndof as f64;
        l.err_quadrature = l.err_quadrature.map(|e| e + l.roundoff_floor);
    }
    let r = record("deep", Refine::Adaptive, levels);
    let err = verdict::field(&r, "err_quadrature");
    let hit = verdict::floor_hit(&r, &err).expect("the error meets the floor");
    let first_below = r.levels.iter().position(|l| l.err_quadrature.unwrap() < 10.0 * l.roundoff_floor).unwrap();
    assert_eq!(hit, first_below);
    assert!(hit > 20 && hit < 40, "{hit}");
    let cut = verdict::above_floor(&r, &err);
    assert_eq!(cut.levels.len(), hit);
    let fit = RateReport::of_values(&cut, &verdict::field(&cut, "err_quadrature")).unwrap();
    assert_eq!(fit.main.last_level, hit - 1);
    assert!((fit.main.rate.slope - 1.5).abs() < 0.05, "{}", fit.text());
    let through = RateReport::of_values(&r, &err).unwrap();
    assert!(through.main.rate.slope < 1.0, "through the floor: {}", through.text());
    let text = verdict::floor_text(&r, &err);
    assert!(text.contains(&format!("from level {hit}")) && text.contains(&format!("fits end at level {}", hit - 1)), "{text}");
    // a run with no floor on record is never cut
    let plain = record("plain", Refine::Adaptive, synthetic_levels(1.5, 0.0, 10));
    let e = verdict::field(&plain, "err_quadrature");
    assert_eq!(verdict::floor_hit(&plain, &e), None);
    assert_eq!(verdict::floor_text(&plain, &e), "no round-off floor on record");
}
