//! `plot::draw_all` on a synthetic results directory: every figure is written as SVG and PNG,
//! the SVGs carry the axis and legend text, and studies without results are skipped, not errors.
//! The figures are left in `target/tmp/figures-test/figures/` for a look.

use signorini::level::record::LevelRecord;
use signorini::plot::{self, FIGURES};
use signorini::records::{MeshSnapshot, RunRecord, RunSpec, StudyDir, write_json};
use signorini::settings::adapt::Refine;
use signorini::settings::estimator::{ContactTerm, EstimatorConfig, LogFactor};
use std::path::{Path, PathBuf};

fn level(level: usize, ndof: usize, err: Option<f64>, c0: f64, eta: [f64; 7]) -> LevelRecord {
    let h_min = 0.25 / 2f64.powf(level as f64 / 2.0);
    let l_h = 1.0 + h_min.ln().powi(2);
    let psi: f64 = eta[..5].iter().sum();
    let eta_h = l_h * psi + eta[5] + eta[6];
    let estimate = c0 * eta_h;
    serde_json::from_value(serde_json::json!({
        "level": level, "ndof": ndof, "ndof_free": ndof * 9 / 10, "n_elements": ndof / 4, "h_min": h_min, "h_max": 0.25,
        "min_angle": 45.0, "contact_nodes": 9, "active_nodes": 4, "full_contact_nodes": 1, "pdas_iterations": 3,
        "zone_min": null, "zone_max": null,
        "eta1": eta[0], "eta2": eta[1], "eta3": eta[2], "eta4": eta[3], "eta5": eta[4], "eta6": eta[5], "eta7": eta[6],
        "l_h": l_h, "psi": psi, "eta_h": eta_h, "c0": c0, "estimate": estimate,
        "err_quadrature": err, "err_dense": err, "err_nodal": null,
        "efficiency": err.map(|e| estimate / e), "marked": 3,
        "t_assembly": 0.0, "t_factorisation": 0.0, "t_active_set": 0.0, "t_solve": 0.0, "t_estimate": 0.0,
        "t_refine": 0.0, "t_level": 0.0
    }))
    .expect("a LevelRecord")
}

struct Run<'a> {
    id: &'a str,
    problem: &'a str,
    refine: Refine,
    theta: f64,
    estimator: EstimatorConfig,
    /// Error constant: err = c * NDF^-3/2 (times a pre-asymptotic bump).
    err: f64,
    /// No error at these levels (None), or no errors at all.
    missing: fn(usize) -> bool,
    /// eta6 and eta7 vanish (Example 7.1).
    eta67_zero: bool,
}

impl Run<'_> {
    fn record(&self, study: &str) -> RunRecord {
        let growth: f64 = if self.refine == Refine::Uniform { 2.0 } else { 1.45 };
        let levels = if self.refine == Refine::Uniform { 9 } else { 21 };
        let log = match self.estimator.log_factor {
            LogFactor::Squared => 1.0,
            LogFactor::Linear => 0.35,
            LogFactor::One => 0.08,
        };
        let lv = (0..levels)
            .map(|k| {
                let ndof = (60.0 * growth.powi(k as i32)) as usize;
                let n = ndof as f64;
                let bump = 1.0 + 2.0 / (1.0 + k as f64);
                let base = self.err * n.powf(-1.5) * bump;
                let err = (!(self.missing)(k)).then_some(base);
                let eta5 = if self.estimator.contact_term == ContactTerm::WithoutFullContact { 0.3 * base } else { 2.0 * base };
                let mut eta = [3.0 * base, 1.5 * base, 0.8 * base, 0.4 * base, eta5, 0.0, 0.0];
                if !self.eta67_zero {
                    eta[5] = 5.0 * base * (1.0 + 0.3 * (k % 3) as f64);
                    eta[6] = if k % 4 == 0 { 0.0 } else { 2.0 * base };
                }
                for e in &mut eta[..5] {
                    *e *= log;
                }
                // the main Example 7.1 study: a flat efficiency (a linear y axis in fig2b)
                if study == "ex71" {
                    let l_h = 1.0 + (0.25f64 / 2f64.powf(k as f64 / 2.0)).ln().powi(2);
                    for e in &mut eta[..5] {
                        *e *= 3.0 / l_h * (1.0 + 0.2 * (k as f64 * 0.7).sin());
                    }
                }
                level(k, ndof, err, self.estimator.c0, eta)
            })
            .collect();
        RunRecord {
            study: study.to_string(),
            run: RunSpec {
                id: self.id.to_string(),
                problem: self.problem.to_string(),
                mesh: "structured:4".to_string(),
                refine: self.refine,
                theta: self.theta,
                levels,
                max_ndof: None,
                stop_ndof: None,
                estimator: self.estimator,
                reference: None,
                save_levels: vec![20],
                constants: Default::default(),
                inputs: Default::default(),
            },
            levels: lv,
            reference_ndof: (self.problem == "ex72").then_some(2_000_000),
            history: None,
            snapshots: Default::default(),
        }
    }
}

fn never(_: usize) -> bool {
    false
}
fn always(_: usize) -> bool {
    true
}
fn last_two(k: usize) -> bool {
    k >= 19
}

fn run<'a>(id: &'a str, problem: &'a str, refine: Refine) -> Run<'a> {
    let ex71 = problem == "ex71";
    Run {
        id,
        problem,
        refine,
        theta: 0.5,
        estimator: EstimatorConfig::default(),
        err: if ex71 { 2.0 } else { 15.0 },
        missing: if ex71 { never } else { last_two },
        eta67_zero: ex71,
    }
}

fn write_study(results: &Path, study: &str, runs: &[Run]) {
    let dir = StudyDir::new(results, study);
    for r in runs {
        write_json(&dir.run_file(r.id), &r.record(study)).unwrap();
    }
}

/// A graded mesh of the unit square, finer towards x = 1 and y = 0.5, with the contact nodes on
/// x = 1 active near the kink.
fn mesh_snapshot() -> MeshSnapshot {
    let nx = 24;
    let ny = 30;
    let xs: Vec<f64> = (0..=nx).map(|i| 1.0 - (1.0 - i as f64 / nx as f64).powi(2)).collect();
    let ys: Vec<f64> = (0..=ny)
        .map(|j| {
            let t = 2.0 * j as f64 / ny as f64 - 1.0;
            0.5 + 0.5 * t.signum() * t.abs().powf(1.6)
        })
        .collect();
    let mut vertices = Vec::new();
    for &y in &ys {
        for &x in &xs {
            vertices.push([x, y]);
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let contact_nodes = ys
        .iter()
        .map(|&y| signorini::level::sample::ContactSample { x: [1.0, y], lambda: 0.0, pressure: 0.0, active: (y - 0.5).abs() < 0.22 })
        .collect();
    MeshSnapshot {
        study: "ex72".into(),
        run: "adaptive".into(),
        level: 20,
        ndof: 2 * (2 * nx + 1) * (2 * ny + 1),
        vertices,
        triangles,
        contact_nodes,
        kinks: vec![[1.0, 0.5]],
    }
}

fn with_estimator(mut r: Run<'_>, f: impl FnOnce(&mut EstimatorConfig)) -> Run<'_> {
    f(&mut r.estimator);
    r
}

fn with_theta(mut r: Run<'_>, theta: f64) -> Run<'_> {
    r.theta = theta;
    r
}

fn full_results(results: &Path) {
    use Refine::{Adaptive, Uniform};
    write_study(results, "ex71", &[run("adaptive", "ex71", Adaptive), run("uniform", "ex71", Uniform)]);
    write_study(results, "ex72", &[run("adaptive", "ex72", Adaptive), run("uniform", "ex72", Uniform)]);
    write_json(&StudyDir::new(results, "ex72").mesh_file("adaptive", 20, "json"), &mesh_snapshot()).unwrap();
    write_study(
        results,
        "c0_sweep",
        &[
            run("ex71_adaptive", "ex71", Adaptive),
            run("ex71_uniform", "ex71", Uniform),
            run("ex72_adaptive", "ex72", Adaptive),
            Run { missing: always, ..run("ex72_uniform", "ex72", Uniform) },
        ],
    );
    write_study(
        results,
        "log_ablation",
        &[
            run("ex71_squared", "ex71", Adaptive),
            with_estimator(run("ex71_linear", "ex71", Adaptive), |e| e.log_factor = LogFactor::Linear),
            with_estimator(run("ex71_one", "ex71", Adaptive), |e| e.log_factor = LogFactor::One),
        ],
    );
    let without = |r: Run<'static>| with_estimator(r, |e| e.contact_term = ContactTerm::WithoutFullContact);
    write_study(
        results,
        "contact_term_ablation",
        &[
            run("ex71_as_written", "ex71", Adaptive),
            without(run("ex71_without_full_contact", "ex71", Adaptive)),
            run("ex72_as_written", "ex72", Adaptive),
            without(run("ex72_without_full_contact", "ex72", Adaptive)),
        ],
    );
    let variant = MeshSnapshot { study: "contact_term_ablation".into(), run: "ex72_without_full_contact".into(), ..mesh_snapshot() };
    write_json(&StudyDir::new(results, "contact_term_ablation").mesh_file("ex72_without_full_contact", 20, "json"), &variant).unwrap();
    write_study(
        results,
        "theta_ablation",
        &[
            with_theta(run("ex71_theta0.3", "ex71", Adaptive), 0.3),
            with_theta(run("ex71_theta0.5", "ex71", Adaptive), 0.5),
            with_theta(run("ex71_theta0.7", "ex71", Adaptive), 0.7),
            run("ex71_uniform", "ex71", Uniform),
            Run { missing: always, ..with_theta(run("ex72_theta0.5", "ex72", Adaptive), 0.5) },
            Run { missing: always, ..run("ex72_uniform", "ex72", Uniform) },
        ],
    );
    let fb = |id, refine| Run { missing: never, ..run(id, "fb", refine) };
    write_study(results, "fb", &[fb("adaptive", Adaptive), without(fb("adaptive_wfc", Adaptive)), fb("uniform", Uniform)]);
    let snapshot = MeshSnapshot { study: "fb".into(), run: "adaptive_wfc".into(), level: 12, kinks: vec![], ..mesh_snapshot() };
    write_json(&StudyDir::new(results, "fb").mesh_file("adaptive_wfc", 12, "json"), &snapshot).unwrap();
    hertz_results(results);
    let repaired = |r: Run<'static>| with_estimator(r, |e| e.contact_term = ContactTerm::TensileOnFullContact);
    write_study(
        results,
        "estimator_repair",
        &[
            repaired(run("ex71_adaptive", "ex71", Adaptive)),
            repaired(with_estimator(run("ex71_adaptive_l1", "ex71", Adaptive), |e| e.log_factor = LogFactor::One)),
            repaired(run("ex71_uniform", "ex71", Uniform)),
            repaired(Run { missing: never, ..run("fb_adaptive", "fb", Adaptive) }),
        ],
    );
    write_study(
        results,
        "deep",
        &[
            run("ex71_as_written", "ex71", Adaptive),
            run("ex71_uniform", "ex71", Uniform),
            fb("fb_as_written", Adaptive),
            fb("fb_uniform", Uniform),
        ],
    );
    let ex72 = |id, refine| Run { missing: never, ..run(id, "ex72", refine) };
    write_study(
        results,
        "ex72_large",
        &[ex72("adaptive", Adaptive), without(ex72("without_full_contact", Adaptive)), ex72("uniform", Uniform)],
    );
    write_study(
        results,
        "ex72_rollers",
        &[ex72("adaptive", Adaptive), without(ex72("without_full_contact", Adaptive)), ex72("uniform", Uniform)],
    );
}

/// The hertz study: one run of the repository's Hertz problem file (found through the provenance's
/// manifest, as for stored results), its last level with contact nodes sampling Hertz's pressure.
fn hertz_results(results: &Path) {
    use signorini::hertz::Hertz;
    use signorini::level::sample::ContactSample;
    use signorini::problems::Material;
    let mut r = run("adaptive", "problems/hertz.toml", Refine::Adaptive);
    r.missing = never;
    write_study(results, "hertz", &[r]);
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/hertz.toml");
    let provenance = serde_json::json!({
        "study": "hertz", "manifest": manifest.display().to_string(), "manifest_sha256": "", "quick": false,
        "git_commit": null, "git_dirty": null, "cargo_lock_sha256": null, "rustc": null, "signorini_version": "test",
        "machine": { "cpu": "test", "cores": 1, "memory_kb": null, "os": "test" }, "threads": 1, "date": "", "runs": ["adaptive"]
    });
    write_json(&StudyDir::new(results, "hertz").provenance_file(), &provenance).unwrap();
    let h = Hertz::new(Material::from_young(1000.0, 0.3), 1.0);
    let f = 2.35;
    let n = 60;
    let xs: Vec<f64> = (-n..=n).map(|k| 0.1 * k as f64 / n as f64).collect();
    let contact_nodes = xs
        .iter()
        .map(|&x| {
            let p = h.pressure(f, x);
            ContactSample { x: [x, 1.0 - (1.0 - x * x).sqrt()], lambda: if x == 0.0 { f } else { 0.0 }, pressure: p, active: p > 0.0 }
        })
        .collect::<Vec<_>>();
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for j in 0..=6 {
        for &x in &xs {
            vertices.push([x, 0.01 * j as f64]);
        }
    }
    let w = xs.len();
    for j in 0..6 {
        for i in 0..w - 1 {
            let (a, b, c, d) = (j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i);
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let snapshot = MeshSnapshot {
        study: "hertz".into(),
        run: "adaptive".into(),
        level: 19,
        ndof: 2 * vertices.len(),
        vertices,
        triangles,
        contact_nodes,
        kinks: vec![],
    };
    write_json(&StudyDir::new(results, "hertz").mesh_file("adaptive", 19, "json"), &snapshot).unwrap();
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_figure_is_written_from_records() {
    let root = scratch("figures-test");
    let results = root.join("results");
    let figures = root.join("figures");
    full_results(&results);

    let written = plot::draw_all(&crate::common::sealed(&results), &figures, crate::common::roles()).expect("draw_all");
    assert_eq!(written.len(), 2 * FIGURES.len(), "{written:?}");
    for name in FIGURES {
        for ext in ["svg", "png"] {
            let f = figures.join(format!("{name}.{ext}"));
            assert!(written.contains(&f), "{} not reported", f.display());
            let size = std::fs::metadata(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display())).len();
            assert!(size > 5_000, "{} is only {size} bytes", f.display());
        }
        let png = std::fs::read(figures.join(format!("{name}.png"))).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
    // no temporary files left behind
    let leftovers: Vec<_> =
        std::fs::read_dir(&figures).unwrap().filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().starts_with('.')).collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    for name in FIGURES.iter().filter(|n| !["fig3b", "fig3b_variant", "fb_mesh", "hertz_pressure", "hertz_mesh"].contains(*n)) {
        let svg = read(&figures.join(format!("{name}.svg")));
        assert!(svg.contains("NDF (2 × P2 nodes"), "{name}: no NDF axis label");
        assert!(svg.contains("10³") || svg.contains("10⁴"), "{name}: no decade tick labels");
    }
    // Hertz: the pressure against x / a (linear axes) with the recovered deviations, the mesh near the contact
    let hertz = read(&figures.join("hertz_pressure.svg"));
    for text in ["Hertz", "x / a", "(+0.00%)", "max 0.000"] {
        assert!(hertz.contains(text), "hertz_pressure lacks {text:?}");
    }
    assert!(read(&figures.join("hertz_mesh.svg")).contains("Hertz&apos;s a = 0.05"));
    // labels are drawn in segments (subscripts separately): look for the pieces
    let fig2a = read(&figures.join("fig2a.svg"));
    for text in ["Example 7.1", "error ‖u − u", ", adaptive", "estimate C", ", uniform", "\nNDF\n", "−3/2"] {
        assert!(fig2a.contains(text), "fig2a lacks {text:?}");
    }
    assert!(read(&figures.join("fig2b.svg")).contains("efficiency = 1"));
    let fig3a = read(&figures.join("fig3a.svg"));
    assert!(fig3a.contains("vs reference, adaptive") && fig3a.contains("reference solution: NDF 2000000") && fig3a.contains("estimate C"));
    let fig3b = read(&figures.join("fig3b.svg"));
    for text in
        ["Example 7.2", "level 20", "NDF = ", "active contact node (17)", "inactive contact node (14)", "kink of the obstacle (1, 0.5)"]
    {
        assert!(fig3b.contains(text), "fig3b lacks {text:?}");
    }
    let fig4a = read(&figures.join("fig4a.svg"));
    assert_eq!(fig4a.matches("= 0 at all levels (not shown)").count(), 2, "fig4a: eta6 and eta7 noted as zero");
    let fig4b = read(&figures.join("fig4b.svg"));
    assert!(fig4b.contains("(= 0 at 6 of 21 levels, not drawn)"), "fig4b legend");
    let c0 = read(&figures.join("c0_sweep.svg"));
    assert!(c0.contains("= 0.45") && c0.contains("(smallest reliable)") && c0.contains("uniform: no errors recorded"));
    let log = read(&figures.join("log_ablation.svg"));
    assert!(log.contains("= 1 + |log h") && log.contains("|\n") && !log.contains("squared"));
    let contact = read(&figures.join("contact_term_ablation.svg"));
    assert!(contact.contains("Example 7.1") && contact.contains("Example 7.2") && contact.contains("without full-contact nodes"));
    let fb = read(&figures.join("fb_error.svg"));
    for text in ["Free boundary", "error, adaptive_wfc", "estimate, uniform", "exact contact zone [a, 1]", "−3/2"] {
        assert!(fb.contains(text), "fb_error lacks {text:?}");
    }
    let fb_mesh = read(&figures.join("fb_mesh.svg"));
    assert!(fb_mesh.contains("adaptive_wfc mesh at level 12") && fb_mesh.contains("free boundary x = a"), "fb_mesh");
    let theta = read(&figures.join("theta_ablation.svg"));
    assert!(theta.contains("θ = 0.3") && theta.contains("uniform") && theta.contains("(errors not available)"));
}

#[test]
fn missing_studies_are_skipped_not_errors() {
    let root = scratch("figures-partial");
    let results = root.join("results");
    let figures = root.join("figures");

    // nothing at all
    let written = plot::draw_all(&crate::common::sealed(&results), &figures, crate::common::roles())
        .expect("an empty results directory is not an error");
    assert!(written.is_empty());

    // only Example 7.1: its figures are drawn, the others skipped with a reason
    write_study(&results, "ex71", &[run("adaptive", "ex71", Refine::Adaptive)]);
    let outcome = plot::draw_figures(&crate::common::sealed(&results), &figures, crate::common::roles()).expect("draw_figures");
    let drawn: Vec<String> = outcome.written.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    for f in ["fig2a.svg", "fig2a.png", "fig2b.svg", "fig4a.png"] {
        assert!(drawn.contains(&f.to_string()), "{f} not drawn: {drawn:?}");
    }
    let skipped: Vec<&str> = outcome.skipped.iter().map(|(n, _)| n.as_str()).collect();
    for f in ["fig3a", "fig3b", "fig4b", "c0_sweep", "log_ablation", "contact_term_ablation", "theta_ablation"] {
        assert!(skipped.contains(&f), "{f} not skipped: {skipped:?}");
    }
    assert!(!figures.join("fig3b.svg").exists());
    // a study present without its mesh snapshot: fig3a drawn, fig3b skipped
    write_study(&results, "ex72", &[run("adaptive", "ex72", Refine::Adaptive)]);
    let outcome = plot::draw_figures(&crate::common::sealed(&results), &figures, crate::common::roles()).expect("draw_figures");
    assert!(outcome.written.iter().any(|p| p.ends_with("fig3a.svg")));
    assert!(outcome.skipped.iter().any(|(n, why)| n == "fig3b" && why.contains("mesh snapshot")), "{:?}", outcome.skipped);
}

/// Tick labels of the y axis as exponents: "10⁻¹⁶" -> -16.
fn decade_exponents(svg: &str) -> Vec<i32> {
    let sup = |c: char| "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().position(|d| d == c);
    svg.lines()
        .filter_map(|l| l.trim().strip_prefix("10"))
        .filter_map(|rest| {
            let (neg, digits) = match rest.strip_prefix('⁻') {
                Some(d) => (true, d),
                None => (false, rest),
            };
            let v = digits.chars().map(sup).try_fold(0i32, |a, d| d.map(|d| 10 * a + d as i32))?;
            (!digits.is_empty()).then_some(if neg { -v } else { v })
        })
        .collect()
}

#[test]
fn roundoff_estimator_terms_are_zeros_and_the_legend_says_so() {
    let root = scratch("figures-roundoff");
    let results = root.join("results");
    let figures = root.join("figures");
    // Example 7.2's adaptive run with eta6 at round-off (3e-17, next to eta1 of order 1e-2) at three levels
    let mut rec = run("adaptive", "ex72", Refine::Adaptive).record("ex72");
    for l in &mut rec.levels[8..11] {
        l.terms.eta6 = 2.78e-17;
    }
    let smallest = rec
        .levels
        .iter()
        .flat_map(|l| [l.terms.eta1, l.terms.eta2, l.terms.eta3, l.terms.eta4, l.terms.eta5, l.terms.eta7])
        .filter(|&v| v > 0.0)
        .fold(f64::INFINITY, f64::min);
    write_json(&StudyDir::new(&results, "ex72").run_file("adaptive"), &rec).unwrap();
    plot::draw_all(&crate::common::sealed(&results), &figures, crate::common::roles()).expect("draw_all");
    let fig4b = read(&figures.join("fig4b.svg"));
    assert!(fig4b.contains("0 or below round-off at 3 of 21 levels, not drawn"), "fig4b legend");
    // the y axis is not stretched down to the round-off values
    let lowest = decade_exponents(&fig4b).into_iter().min().unwrap();
    assert!(lowest as f64 >= smallest.log10().floor() - 2.0, "y axis reaches 10^{lowest}, data go down to {smallest:e}");
}

#[test]
fn convergence_plots_carry_slope_triangles_labelled_with_the_rate() {
    let root = scratch("figures-triangles");
    let results = root.join("results");
    let figures = root.join("figures");
    full_results(&results);
    plot::draw_all(&crate::common::sealed(&results), &figures, crate::common::roles()).expect("draw_all");
    for name in ["fig2a", "fig3a", "fig4a", "fig4b"] {
        let svg = read(&figures.join(format!("{name}.svg")));
        // the legs' labels: run 1, rise 1.5 (the rate in NDF)
        let lines: Vec<&str> = svg.lines().map(str::trim).collect();
        assert!(lines.contains(&"1.5") && lines.contains(&"1"), "{name}: no slope triangle labels");
    }
}

/// A polyline in pixels.
type Curve = Vec<(f64, f64)>;

/// The legend box (x0, y0, x1, y1) and the curves (stroke width 2) of a panel SVG, in pixels.
fn legend_and_curves(svg: &str) -> (Vec<[f64; 4]>, Vec<Curve>) {
    let attr = |l: &str, name: &str| -> Option<String> {
        let i = l.find(&format!(" {name}=\""))? + name.len() + 3;
        Some(l[i..].split('"').next()?.to_string())
    };
    let mut boxes = Vec::new();
    let mut curves = Vec::new();
    for l in svg.lines() {
        if l.starts_with("<rect") && attr(l, "opacity").as_deref() == Some("0.45") {
            let v: Vec<f64> = ["x", "y", "width", "height"].iter().map(|k| attr(l, k).unwrap().parse().unwrap()).collect();
            boxes.push([v[0], v[1], v[0] + v[2], v[1] + v[3]]);
        }
        if l.starts_with("<polyline") && attr(l, "stroke-width").as_deref() == Some("2") {
            let pts = attr(l, "points").unwrap();
            curves.push(
                pts.split_whitespace()
                    .map(|p| {
                        let (x, y) = p.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect(),
            );
        }
    }
    (boxes, curves)
}

#[test]
fn legends_keep_clear_of_every_curve() {
    // the stored results where present (fig3a's legend nearly touched a curve), else synthetic ones
    let root = scratch("figures-clearance");
    let stored = Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    let results = if stored.join("ex72").join("runs").is_dir() {
        stored.clone()
    } else {
        full_results(&root.join("results"));
        root.join("results")
    };
    let figures = root.join("figures");
    let shelf = if results == stored { crate::common::shelf(&results) } else { crate::common::sealed(&results) };
    plot::draw_figures(&shelf, &figures, crate::common::roles()).expect("draw_figures");
    for name in ["fig2a", "fig3a", "fig4a", "fig4b"] {
        let Ok(svg) = std::fs::read_to_string(figures.join(format!("{name}.svg"))) else { continue };
        let (boxes, curves) = legend_and_curves(&svg);
        assert_eq!(boxes.len(), 1, "{name}: one legend");
        let [x0, y0, x1, y1] = boxes[0];
        let mut closest = f64::INFINITY;
        let inside = |&(x, y): &(f64, f64)| x >= x0 && x <= x1 && y >= y0 && y <= y1;
        // the legend's own swatches are inside it
        for c in curves.iter().filter(|c| !c.iter().all(inside)) {
            for w in c.windows(2) {
                for k in 0..=100 {
                    let t = k as f64 / 100.0;
                    let (x, y) = (w[0].0 + t * (w[1].0 - w[0].0), w[0].1 + t * (w[1].1 - w[0].1));
                    let (dx, dy) = ((x0 - x).max(x - x1).max(0.0), (y0 - y).max(y - y1).max(0.0));
                    closest = closest.min(dx.hypot(dy));
                }
            }
        }
        // 9 px in fig3a before: it looked as if the legend touched the curve
        assert!(closest >= 12.0, "{name}: a curve passes {closest:.1} px from the legend");
    }
}

/// Every log y axis of every stored figure spans its data (and guide lines such as efficiency
/// = 1) plus at most two decades in all (room for slopes, labels and the legend): a figure is
/// its data, not empty decades. Checked on the records in `results/`.
#[test]
fn log_axes_stay_within_two_decades_of_their_data() {
    let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    let mut wide = Vec::new();
    let shelf = crate::common::shelf(&results);
    for name in FIGURES {
        for r in plot::y_ranges(name, &shelf, crate::common::roles()).unwrap() {
            if !r.log {
                continue;
            }
            let beyond = (r.axis_hi / r.data_hi).log10().max(0.0) + (r.data_lo / r.axis_lo).log10().max(0.0);
            if beyond > 2.0 {
                wide.push(format!(
                    "{name} panel {}: axis {:.1e}..{:.1e}, data {:.1e}..{:.1e} ({beyond:.1} decades beyond)",
                    r.title_index, r.axis_lo, r.axis_hi, r.data_lo, r.data_hi
                ));
            }
        }
    }
    assert!(wide.is_empty(), "axes far beyond their data:\n{}", wide.join("\n"));
}

/// In every figure, a series with the same values as an earlier one at every level names it in
/// its legend (the earlier one drawn with large hollow markers around it): on the stored
/// results, `repaired` and `without_full_contact` of ex72_large, ex72_rollers and deep, and
/// `uniform` and `uniform_cartesian` of ex71; a run with values of its own is named by nothing.
#[test]
fn a_series_that_coincides_with_another_is_named_in_the_legend() {
    let figures = scratch("figures-coincide").join("figures");
    let shelf = crate::common::shelf(&Path::new(env!("CARGO_MANIFEST_DIR")).join("results"));
    let studies = ["ex71", "deep", "ex72_large", "ex72_rollers"].map(String::from);
    plot::draw_studies(&shelf, &figures, crate::common::roles(), Some(&studies)).expect("draw_studies");
    for (name, label, panels) in [
        ("ex72_large_error", "without full contact (same values as repaired)", 2),
        ("ex72_rollers_error", "without full contact (same values as repaired)", 2),
        ("deep_error", "without full contact (same values as repaired)", 1),
        // the error and the estimate of each
        ("fig2a", ", uniform_cartesian (same values as uniform)", 2),
        ("fig2b", "uniform_cartesian (same values as uniform)", 2),
    ] {
        let svg = read(&figures.join(format!("{name}.svg")));
        assert_eq!(svg.matches(label).count(), panels, "{name}: legend {label:?}");
        assert_eq!(svg.matches("(same values as").count(), panels, "{name}: only the coinciding runs are named");
    }
}
