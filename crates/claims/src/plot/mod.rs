//! Figures of Section 7, regenerated from the stored records alone (`results/STUDY/runs/*.json`
//! and `results/STUDY/meshes/*.json`); nothing here calls the solver.
//!
//! [`draw_all`] writes every figure as `figures/NAME.svg` and `figures/NAME.png` (900 x 650, or
//! 800 px per panel for two-panel figures). A figure whose study (or run, or mesh snapshot) has
//! no results yet is skipped with a note on stderr; [`draw_figures`] returns the notes instead.
//! Runs are found by their `RunSpec`, not by a fixed list: runs are grouped by `run.problem`,
//! ordered adaptive (by theta) before uniform, and labelled from their spec or id, so new runs
//! of a study appear without code changes.
//!
//! NDF on every x axis is `LevelRecord::ndof` = 2 x number of P2 nodes, Dirichlet nodes included.
//! The "estimate" is `LevelRecord::estimate` = C0 * eta_h; the "error" is `err_quadrature`
//! (||u - u_h||_Linf at the quadrature points, the paper's way; for Example 7.2 against the
//! reference solution where one was computed).
//!
//! | figure | study / runs | shows |
//! |---|---|---|
//! | `fig2a` | `ex71`, all runs (the first, `adaptive`, solid; others dashed, hollow markers) | `err_quadrature` (blue circles) and `estimate` (red squares) vs NDF, log-log; NDF^-3/2 reference 2.5x below the adaptive error |
//! | `fig2b` | `ex71`, all runs | two panels: the efficiency index `efficiency` (= estimate / err_quadrature; recomputed if absent) and the efficiency / l_h, vs NDF, log x; y log if it spans more than a decade, else linear from 0; line at 1 |
//! | `fig3a` | `ex72`, all runs | `estimate` vs NDF, log-log, plus `err_quadrature` (against the reference solution, its NDF from `reference_ndof` noted in the legend) where present; NDF^-3/2 below the adaptive estimate |
//! | `fig3b_variant` | `contact_term_ablation`, the run of role `ex72-without-full-contact`, its mesh of level 20 | as `fig3b`, for the run marking with eta_5 without full-contact nodes: the mesh beside the paper's |
//! | `fig3b` | `ex72`, the run of role `as-written`, its mesh of level 20 (else the finest saved level, said in the title) | the triangles, thin; equal aspect; active contact nodes red, inactive blue; the obstacle's kink (`kinks`) as a black diamond; NDF, triangle and vertex counts |
//! | `fig4a` | `ex71`, the run of role `as-written` | `eta1`..`eta5` vs NDF, log-log, NDF^-3/2 above the data; `eta6`, `eta7` are not plotted (as in the paper) but the legend says whether they are 0 at every level or gives their maximum |
//! | `fig4b` | `ex72`, the run of role `as-written` | `eta1`..`eta7` vs NDF, same style |
//! | `c0_sweep` | `c0_sweep`, a panel per problem | efficiency C0' eta_h / err_quadrature vs NDF for C0' = [`C0_PAPER`] (solid) and the smallest reliable C0' = max over levels of err_quadrature / eta_h (dashed), per run; line at 1; runs without errors are named in the legend |
//! | `log_ablation` | `log_ablation`, a panel per problem | efficiency per level (vs NDF) for each `estimator.log_factor`; line at 1 |
//! | `contact_term_ablation` | `contact_term_ablation`, a panel per problem | `estimate` (solid) and `eta5` (dashed) vs NDF for each `estimator.contact_term` |
//! | `theta_ablation` | `theta_ablation`, a panel per problem | `err_quadrature` vs NDF for each theta and uniform, with NDF^-3/2; where some run of a problem has fewer than two errors, the estimate for all runs of that problem instead (the y label says which) |
//! | `fb_error`, `fb_mesh` | `fb` | see `plot/fb.rs`: error and estimate vs NDF of the free-boundary problem, and its late adaptive mesh with x = a marked |
//! | `hertz_pressure`, `hertz_mesh` | `hertz` | see `plot/hertz.rs`: the contact pressure against Hertz's, and the mesh near the contact |
//! | `deep_error`, `deep_floor` | `deep` | see `plot/deep.rs`: the error of the deep runs to 1e7 unknowns, and error, estimate and round-off floor together |
//! | `ex72_large_error` | `ex72_large` | see `plot/ex72_large.rs`: Example 7.2's error on the square and on Gamma_C against the reference, every run |
//! | `ex72_rollers_error` | `ex72_rollers` | the same for Example 7.2 on rollers (`plot/ex72_large.rs`) |
//! | `estimator_repair` | the runs the CLAIMS row `estimator-repair` reads (`claims::repair::Stored::fitted`: `deep`, `ex72_large`, `estimator_repair`), a 2 x 2 grid, a panel per problem | `err_quadrature` (solid, filled) and `estimate` (dashed, hollow) vs NDF for the repaired run, the run without full-contact nodes, eta_5 as written, uniform refinement and the repaired run with l_h = 1 |
//!
//! [`SHOWN`] gives each figure's study and the caption its study page shows under it.
//!
//! Coinciding series: in every panel of every line figure, a series with the same values as a
//! later one at every level (e.g. `uniform` and `uniform_cartesian` of ex71, `repaired` and
//! `without_full_contact` of ex72_large), or values within [`DRAWS_OVER_REL`] of them, would
//! hide under it; it gets large hollow markers drawn around the later one's, and the later one's
//! legend says "(same values as …)", naming it, with the largest relative difference where they
//! are not the same ([`show_coincident`], applied to every figure as it is built).
//!
//! Style: log axes labelled at the decades (`10⁻⁴`; also 2x and 5x when less than two decades
//! show), light grid lines at 2..9 x each decade; one colour and marker shape per series; the
//! legend in a white box where it covers no data, as near a corner as possible (upper right
//! first) and at least 14 px from every curve, the y range growing upwards only if no such place
//! exists; reference slopes dashed grey with their label beside the line where it covers no data,
//! and a slope triangle on the side away from the data, its legs labelled 1 (run) and the rate
//! (rise), as convergence plots in this field carry them. Labels have real subscripts and
//! superscripts (see `rich`).
//!
//! On log axes a value that is exactly 0 cannot be drawn: the point is left out, the line
//! breaks, and the legend says so ("η₆ = 0 at all levels", or "(= 0 at 3 of 20 levels, not
//! drawn)"). In Fig. 4 an estimator term below round-off (less than [`ROUNDOFF`] times the
//! largest term of its level, e.g. η₆ = 3×10⁻¹⁷ next to η₁ = 20) is treated as 0 in the same
//! way, and the legend says "0 or below round-off". Missing values (`None`, e.g. no error
//! measured at a level) are left out silently.
//!
//! Fonts: DejaVu Sans is bundled (`crates/claims/src/plot/DejaVuSans.ttf`, copied from the Debian
//! fonts-dejavu-core package, version 2.37; the DejaVu fonts licence, a Bitstream Vera
//! derivative, permits redistributing and embedding the font) and registered with plotters'
//! ab_glyph backend under the name "DejaVu Sans, sans-serif", so no system font is needed to
//! render the PNGs; the SVGs ask the viewer for that CSS font list.

mod axis;
mod deep;
mod ex72_large;
mod fb;
mod font;
mod glyphs;
mod hertz;
pub mod page;
pub mod render;
mod repair;
mod rich;

use crate::analysis::claims::COINCIDE_REL;
use crate::analysis::problem_names;
use crate::analysis::roles::{self, Role, Roles};
use crate::analysis::studies::{self, Study};
use anyhow::Context;
use model::level::record::LevelRecord;
use model::settings::adapt::Refine;
use model::settings::estimator::{C0_PAPER, ContactTerm, LogFactor, c0_paper};
use plotters::prelude::*;
use render::{Figure, HLine, LineFigure, Marker, MeshFigure, PALETTE, Panel, Series, Slope, SlopeAnchor, Style, YScale};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use store::records::{MeshSnapshot, RunRecord};
use store::study::store::Shelf;

/// A figure: its name (the file stem under `figures/`), the study it is drawn from, and its
/// caption on the study page (what it shows: the quantities, the runs, the axes).
#[derive(Clone, Copy, Debug)]
pub struct Shown {
    pub name: &'static str,
    pub study: Study,
    pub caption: &'static str,
}

/// Every figure, in the order drawn, with its study and caption (the table above says how each
/// is drawn). A figure that draws a whole ablation study (`c0_sweep`, `log_ablation`, ...) is
/// named after it: its name is the study's ([`studies`]).
pub const SHOWN: [Shown; 20] = [
    Shown {
        name: "fig2a",
        study: studies::EX71,
        caption: "Example 7.1 (Fig. 2a): the error ‖u − uₕ‖∞ and the estimate C₀ηₕ against the number of unknowns NDF, log-log, for every run of ex71 (the adaptive run solid, the others dashed), with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "fig2b",
        study: studies::EX71,
        caption: "Example 7.1 (Fig. 2b): the efficiency index C₀ηₕ / ‖u − uₕ‖∞ (left) and the efficiency index divided by the log factor lₕ (right) against NDF, for every run of ex71, with the line efficiency = 1.",
    },
    Shown {
        name: "fig3a",
        study: studies::EX72,
        caption: "Example 7.2 (Fig. 3a): the estimate C₀ηₕ and, where a reference solution was computed, the error ‖u − uₕ‖∞ against it, against NDF, log-log, for every run of ex72, with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "fig3b",
        study: studies::EX72,
        caption: "Example 7.2 (Fig. 3b): the adaptive mesh of the run with η₅ as written at level 20 (or its finest saved level, which the title names), active contact nodes red, inactive blue, the obstacle's kink a black diamond.",
    },
    Shown {
        name: "fig3b_variant",
        study: studies::CONTACT_TERM_ABLATION,
        caption: "Example 7.2: the adaptive mesh at level 20 of the run that marks with η₅ without full-contact nodes (contact_term_ablation), drawn as Fig. 3b, to set beside the paper's mesh.",
    },
    Shown {
        name: "fig4a",
        study: studies::EX71,
        caption: "Example 7.1 (Fig. 4a): the estimator contributions η₁ … η₅ of the run with η₅ as written against NDF, log-log, with the reference rate NDF^−3/2; the legend says what η₆ and η₇ are.",
    },
    Shown {
        name: "fig4b",
        study: studies::EX72,
        caption: "Example 7.2 (Fig. 4b): the estimator contributions η₁ … η₇ of the run with η₅ as written against NDF, log-log, with the reference rate NDF^−3/2.",
    },
    Shown {
        name: studies::C0_SWEEP,
        study: studies::C0_SWEEP,
        caption: concat!(
            "The efficiency C₀ηₕ / ‖u − uₕ‖∞ against NDF, a panel per problem, for every run of c0_sweep with the paper's C₀ = ",
            c0_paper!(),
            " (solid) and with the smallest C₀ that bounds the error at every level of the run (dashed), with the line efficiency = 1."
        ),
    },
    Shown {
        name: studies::LOG_ABLATION,
        study: studies::LOG_ABLATION,
        caption: "The efficiency index C₀ηₕ / ‖u − uₕ‖∞ against NDF, a panel per problem, for each log factor lₕ of the estimator in log_ablation (1 + |log h_min|², 1 + |log h_min|, 1), with the line efficiency = 1.",
    },
    Shown {
        name: studies::CONTACT_TERM_ABLATION,
        study: studies::CONTACT_TERM_ABLATION,
        caption: "The estimate C₀ηₕ (solid) and its contact term η₅ (dashed) against NDF, log-log, a panel per problem, for each form of η₅ in contact_term_ablation (as written, without full-contact nodes, repaired).",
    },
    Shown {
        name: studies::THETA_ABLATION,
        study: studies::THETA_ABLATION,
        caption: "The error ‖u − uₕ‖∞ against NDF, log-log, a panel per problem, for each marking parameter θ of theta_ablation and for uniform refinement (the estimate C₀ηₕ instead where a run has fewer than two errors, as the y label says), with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "fb_error",
        study: studies::FB,
        caption: "The free-boundary problem with an exact solution: the error ‖u − uₕ‖∞ (solid) and the estimate C₀ηₕ (dashed) against NDF, log-log, for every run of fb, with the reference rate NDF^−3/2; the legend gives each run's last contact zone against the exact one, [a, 1].",
    },
    Shown {
        name: "fb_mesh",
        study: studies::FB,
        caption: "The free-boundary problem: the finest saved adaptive mesh of the run without full-contact nodes (else of the run with η₅ as written), active contact nodes red, inactive blue, the free boundary x = a dashed.",
    },
    Shown {
        name: "hertz_pressure",
        study: studies::HERTZ,
        caption: "An elastic cylinder on a rigid flat: the contact pressure at the contact nodes of each run's finest saved mesh against Hertz's, in the units x / a and p / p₀ (left), and its deviation from Hertz's at the vertices (solid) and the edge midpoints (dashed) (right).",
    },
    Shown {
        name: "hertz_mesh",
        study: studies::HERTZ,
        caption: "An elastic cylinder on a rigid flat: the finest saved mesh of the adaptive run near the contact (|x| ≤ 1.5a), active contact nodes red, inactive blue, Hertz's half-width a dashed.",
    },
    Shown {
        name: studies::ESTIMATOR_REPAIR,
        study: studies::ESTIMATOR_REPAIR,
        caption: "The runs the CLAIMS row estimator-repair reads, a panel per problem: the error ‖u − uₕ‖∞ (solid) and the estimate C₀ηₕ (dashed) against NDF, log-log, for the repaired estimator, η₅ without full-contact nodes, η₅ as written, uniform refinement and the repaired estimator with lₕ = 1, with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "deep_error",
        study: studies::DEEP,
        caption: "The deep runs to 10⁷ unknowns: the error ‖u − uₕ‖∞ against NDF, log-log, a panel per problem (Example 7.1, the free-boundary problem), for η₅ as written, without full-contact nodes, repaired and uniform refinement, with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "deep_floor",
        study: studies::DEEP,
        caption: "The deep runs with η₅ as written and uniform refinement, a panel per problem: the error ‖u − uₕ‖∞, the estimate C₀ηₕ and a margin times the round-off floor of uₕ (dashed, the margin in the legend; CLAIMS fits no error below it) against NDF, log-log.",
    },
    Shown {
        name: "ex72_large_error",
        study: studies::EX72_LARGE,
        caption: "Example 7.2 to about 10⁶ unknowns: the error ‖u − uₕ‖∞ against a finer reference solution (its size in the title), on the whole square (left) and on Γ_C away from the corners (right), against NDF, log-log, for every run of ex72_large (η₅ as written, without full-contact nodes, repaired, uniform refinement), with the reference rate NDF^−3/2.",
    },
    Shown {
        name: "ex72_rollers_error",
        study: studies::EX72_ROLLERS,
        caption: "Example 7.2 with the left side on rollers: the error ‖u − uₕ‖∞ against a finer reference solution (its size in the title), on the whole square (left) and on Γ_C (right), against NDF, log-log, for every run of ex72_rollers (η₅ as written, without full-contact nodes, repaired, uniform refinement), with the reference rate NDF^−3/2.",
    },
];

/// Every figure's name, in the order drawn ([`SHOWN`]).
pub const FIGURES: [&str; SHOWN.len()] = {
    let mut names = [""; SHOWN.len()];
    let mut i = 0;
    while i < SHOWN.len() {
        names[i] = SHOWN[i].name;
        i += 1;
    }
    names
};

fn shown(figure: &str) -> Option<&'static Shown> {
    SHOWN.iter().find(|s| s.name == figure)
}

/// The study a figure is drawn from ([`SHOWN`]).
pub fn study_of(figure: &str) -> Option<Study> {
    shown(figure).map(|s| s.study)
}

/// What a figure shows, one sentence for its caption on the study page ([`SHOWN`]).
pub fn caption(figure: &str) -> Option<&'static str> {
    shown(figure).map(|s| s.caption)
}

/// An estimator term below `ROUNDOFF` times the largest term of its level is round-off: drawn
/// as 0 (not at all, on a log axis). Legitimate small terms are 1e-6 of the largest or more in
/// every stored run; round-off is 1e-18 of it.
pub const ROUNDOFF: f64 = 1e-12;

/// The level of the mesh in Fig. 3(b).
const MESH_LEVEL: usize = 20;

const NDF_DESC: &str = "NDF (2 × P2 nodes, Dirichlet nodes included)";
const ERR: &str = "‖u − u_{h}‖_{∞}";
const EFF_DESC: &str = "efficiency index C_{0}η_{h} / ‖u − u_{h}‖_{∞}";
const ESTIMATE: &str = "estimate C_{0}η_{h}";

/// The bundled font: DejaVu Sans 2.37, copied unchanged from
/// /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf (Debian fonts-dejavu-core). Licence: the
/// Bitstream Vera licence plus public-domain DejaVu changes, which allow copying, embedding and
/// redistribution provided the copyright and licence notices go with every copy; the font file
/// carries them in its name table (<https://dejavu-fonts.github.io/License.html>).
static FONT_BYTES: &[u8] = include_bytes!("DejaVuSans.ttf");

/// What [`draw_figures`] did.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// Every file written (`NAME.svg` and `NAME.png` per figure drawn).
    pub written: Vec<PathBuf>,
    /// Figures not drawn because their results do not exist yet: (figure, reason).
    pub skipped: Vec<(String, String)>,
}

/// Draw every figure whose results exist into `figures/`; figures without results are skipped
/// with a note on stderr. Returns the files written. The figures find their runs by the roles
/// the manifests declare ([`roles::check`]).
pub fn draw_all(shelf: &Shelf, figures: &Path, roles: &Roles) -> anyhow::Result<Vec<PathBuf>> {
    draw_studies(shelf, figures, roles, None)
}

/// [`draw_all`] for the figures of some studies only (`None`: every figure).
pub fn draw_studies(shelf: &Shelf, figures: &Path, roles: &Roles, studies: Option<&[String]>) -> anyhow::Result<Vec<PathBuf>> {
    let keep = |figure: &str| studies.is_none_or(|s| study_of(figure).is_some_and(|st| s.iter().any(|x| x == st)));
    let outcome = draw_figures_where(shelf, figures, roles, &keep)?;
    for (name, why) in &outcome.skipped {
        model::base::note::line(format_args!("figures: skipped {name}: {why}"));
    }
    Ok(outcome.written)
}

/// Draw every figure whose results exist; report the files written and the figures skipped.
/// A figure that fails (unreadable record, drawing error) does not stop the others; the errors
/// are reported together at the end.
pub fn draw_figures(shelf: &Shelf, figures: &Path, roles: &Roles) -> anyhow::Result<Outcome> {
    draw_figures_where(shelf, figures, roles, &|_| true)
}

/// [`draw_figures`] for the figures `keep` accepts.
pub fn draw_figures_where(shelf: &Shelf, figures: &Path, roles: &Roles, keep: &dyn Fn(&str) -> bool) -> anyhow::Result<Outcome> {
    register_font()?;
    model::base::input::create_folder(figures)?;
    let mut outcome = Outcome::default();
    let mut errors = Vec::new();
    for name in FIGURES.into_iter().filter(|f| keep(f)) {
        match build(name, shelf, roles).and_then(|b| match b {
            Ok(fig) => write_figure(&fig, figures, name).map(Ok),
            Err(why) => Ok(Err(why)),
        }) {
            Ok(Ok(files)) => outcome.written.extend(files),
            Ok(Err(why)) => outcome.skipped.push((name.to_string(), why)),
            Err(e) => errors.push(format!("{name}: {e:#}")),
        }
    }
    if !errors.is_empty() {
        anyhow::bail!("{} figure(s) failed:\n  {}", errors.len(), errors.join("\n  "));
    }
    Ok(outcome)
}

fn register_font() -> anyhow::Result<()> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| plotters::style::register_font(font::FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    anyhow::ensure!(ok, "the bundled font DejaVuSans.ttf could not be loaded");
    Ok(())
}

/// Render as SVG (into a string, written atomically) and PNG (drawn into memory, encoded, written
/// to a temporary file in the same directory, then renamed).
fn write_figure(fig: &Figure, dir: &Path, name: &str) -> anyhow::Result<Vec<PathBuf>> {
    let size = fig.size();
    let svg = dir.join(format!("{name}.svg"));
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        fig.render(&root, rich::SVG)?;
    }
    store::records::write_atomic(&svg, text.as_bytes()).with_context(|| format!("writing {}", svg.display()))?;

    let png = dir.join(format!("{name}.png"));
    let tmp = dir.join(format!(".{name}.tmp{}.png", std::process::id()));
    model::base::failpoint::step("write", &tmp);
    let drawn = png_bytes(fig, size).and_then(|bytes| std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display())));
    model::base::failpoint::step("rename", &png);
    if let Err(e) = drawn.and_then(|()| std::fs::rename(&tmp, &png).with_context(|| format!("writing {}", png.display()))) {
        std::fs::remove_file(&tmp).ok();
        return Err(e);
    }
    Ok(vec![svg, png])
}

/// The bytes of a PNG file of `fig` drawn at `(w, h)`: 8-bit RGB, the pixels plotters' bitmap
/// backend draws (on black, where nothing is drawn, as its file-backed form starts).
fn png_bytes(fig: &Figure, (w, h): (u32, u32)) -> anyhow::Result<Vec<u8>> {
    let mut rgb = vec![0u8; 3 * w as usize * h as usize];
    {
        let backend = glyphs::Glyphs::new(BitMapBackend::with_buffer(&mut rgb, (w, h)), FONT_BYTES)?;
        fig.render(&backend.into_drawing_area(), rich::BITMAP)?;
    }
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // deflate at zlib's default level, each row's filter chosen adaptively
    encoder.set_compression(png::Compression::Balanced);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&rgb)?;
    writer.finish()?;
    Ok(bytes)
}

/// The y range of every line panel of figure `name` drawn from `results` against the range of
/// its data (what a test holds the axes to); empty for a mesh figure or one without results.
pub fn y_ranges(name: &str, shelf: &Shelf, roles: &Roles) -> anyhow::Result<Vec<render::YRange>> {
    register_font()?;
    let Ok(fig) = build(name, shelf, roles)? else { return Ok(Vec::new()) };
    let mut text = String::new();
    let root = SVGBackend::with_string(&mut text, fig.size()).into_drawing_area();
    fig.render(&root, rich::SVG)
}

/// A figure, or the reason it cannot be drawn yet.
type Built = Result<Figure, String>;

/// Figure `name` as drawn: in every panel of a line figure, a series with the same values as
/// another is marked and named ([`show_coincident`]).
fn build(name: &str, shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    let mut built = draw(name, shelf, roles)?;
    if let Ok(Figure::Lines(f)) = &mut built {
        f.panels.iter_mut().for_each(show_coincident);
    }
    Ok(built)
}

fn draw(name: &str, shelf: &Shelf, roles: &Roles) -> anyhow::Result<Built> {
    match name {
        "fig2a" => fig2a(shelf),
        "fig2b" => fig2b(shelf),
        "fig3a" => fig3a(shelf),
        "fig3b" => mesh_at_level_20(shelf, roles, roles::EX72_AS_WRITTEN),
        "fig3b_variant" => mesh_at_level_20(shelf, roles, roles::ABLATION_EX72_WFC),
        "fig4a" => fig4(shelf, roles, roles::EX71_AS_WRITTEN, "4a", 5),
        "fig4b" => fig4(shelf, roles, roles::EX72_AS_WRITTEN, "4b", 7),
        studies::C0_SWEEP => c0_sweep(shelf),
        studies::LOG_ABLATION => log_ablation(shelf),
        studies::CONTACT_TERM_ABLATION => contact_term_ablation(shelf),
        studies::ESTIMATOR_REPAIR => repair::estimator_repair(shelf, roles),
        studies::THETA_ABLATION => theta_ablation(shelf),
        "fb_error" => fb::fb_error(shelf),
        "fb_mesh" => fb::fb_mesh(shelf, roles),
        "hertz_pressure" => hertz::hertz_pressure(shelf),
        "hertz_mesh" => hertz::hertz_mesh(shelf, roles),
        "deep_error" => deep::deep_error(shelf),
        "deep_floor" => deep::deep_floor(shelf, roles),
        "ex72_large_error" => ex72_large::ex72_large_error(shelf),
        "ex72_rollers_error" => ex72_large::ex72_rollers_error(shelf),
        other => anyhow::bail!("unknown figure {other}"),
    }
}

// ---------------------------------------------------------------------------------------------
// reading and ordering records

/// The runs of a study, adaptive (by theta) before uniform, then by id; `Err` if there are none.
fn runs(shelf: &Shelf, study: &str) -> anyhow::Result<Result<Vec<RunRecord>, String>> {
    let mut runs = shelf.runs(study)?;
    runs.retain(|r| !r.levels.is_empty());
    if runs.is_empty() {
        return Ok(Err(format!("study {study} has no runs yet ({})", shelf.runs_folder(study)?.display())));
    }
    runs.sort_by(|a, b| order_key(a).partial_cmp(&order_key(b)).unwrap_or(std::cmp::Ordering::Equal).then_with(|| a.run.id.cmp(&b.run.id)));
    Ok(Ok(runs))
}

fn order_key(r: &RunRecord) -> (u8, f64) {
    match r.run.refine {
        Refine::Adaptive => (0, r.run.theta),
        Refine::Uniform => (1, 0.0),
    }
}

/// Runs grouped by problem (sorted by problem name), each group in `runs` order.
fn by_problem(runs: &[RunRecord]) -> BTreeMap<String, Vec<&RunRecord>> {
    let mut m: BTreeMap<String, Vec<&RunRecord>> = BTreeMap::new();
    for r in runs {
        m.entry(r.run.problem.clone()).or_default().push(r);
    }
    m
}

fn problem_title(problem: &str) -> String {
    match problem {
        problem_names::EX71 => "Example 7.1".to_string(),
        problem_names::EX72 => "Example 7.2".to_string(),
        other => other.to_string(),
    }
}

/// The run id without its problem prefix (`ex71_theta0.5` -> `theta0.5`).
fn short_id(r: &RunRecord) -> &str {
    r.run.id.strip_prefix(&format!("{}_", r.run.problem)).unwrap_or(&r.run.id)
}

fn refine_label(r: &RunRecord) -> String {
    match r.run.refine {
        Refine::Adaptive => format!("adaptive θ = {}", r.run.theta),
        Refine::Uniform => "uniform".to_string(),
    }
}

/// A suffix telling `r` apart from the other runs of `group` with the same `key`: the
/// refinement if that tells them apart, else the short id; empty if no other run has the key.
fn distinguish<K: PartialEq>(group: &[&RunRecord], r: &RunRecord, key: impl Fn(&RunRecord) -> K) -> String {
    let k = key(r);
    let same: Vec<&RunRecord> = group.iter().copied().filter(|o| key(o) == k).collect();
    if same.len() <= 1 {
        String::new()
    } else if same.iter().filter(|o| refine_label(o) == refine_label(r)).count() == 1 {
        format!(" ({})", refine_label(r))
    } else {
        format!(" ({})", short_id(r))
    }
}

fn series(r: &RunRecord, label: String, style: Style, y: impl Fn(&LevelRecord) -> Option<f64>) -> Series {
    Series { label, points: r.levels.iter().map(|l| (l.ndof as f64, y(l))).collect(), style, roundoff: false }
}

fn efficiency(l: &LevelRecord) -> Option<f64> {
    l.efficiency.or_else(|| l.err_quadrature.filter(|&e| e > 0.0).map(|e| l.terms.estimate / e))
}

fn slope() -> Slope {
    Slope { rate: -1.5, label: "NDF^{−3/2}".to_string(), anchor: SlopeAnchor::BelowAll }
}

fn eff_one() -> HLine {
    HLine { y: 1.0, label: "efficiency = 1".to_string() }
}

/// `1.23×10^{-4}` (markup for `rich`).
fn sci(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    let m = v / 10f64.powi(e);
    if (-2..=3).contains(&e) { format!("{v:.*}", (2 - e).max(0) as usize) } else { format!("{m:.2}×10^{{{e}}}") }
}

fn single(panel: Panel) -> Figure {
    Figure::Lines(LineFigure { title: None, panels: vec![panel], columns: None })
}

// ---------------------------------------------------------------------------------------------
// Fig. 2, 3, 4

const COLOR_ERROR: RGBColor = PALETTE[0];
const COLOR_ESTIMATE: RGBColor = PALETTE[1];

/// Error (blue circles) and estimate (red squares) per run; the first run solid, others dashed.
/// The first run as in the paper (error: blue circles, estimate: red squares, both solid); every
/// other run in a colour and marker of its own, its error solid and filled, its estimate dashed
/// and hollow, so that no two series share a style.
fn error_and_estimate(runs: &[RunRecord], panel: &mut Panel, error_label: &str) {
    for (k, r) in runs.iter().enumerate() {
        let id = &r.run.id;
        let (error_style, estimate_style) = if k == 0 {
            (
                Style { color: COLOR_ERROR, marker: Marker::Circle, dashed: false, filled: true, large: false },
                Style { color: COLOR_ESTIMATE, marker: Marker::Square, dashed: false, filled: true, large: false },
            )
        } else {
            // colours 0 and 1 of the palette are the first run's
            let own = Style::nth(k + 1);
            (own, own.dashed(true))
        };
        if r.levels.iter().any(|l| l.err_quadrature.is_some()) {
            panel.series.push(series(r, format!("{error_label}, {id}"), error_style, |l| l.err_quadrature));
        }
        panel.series.push(series(r, format!("{ESTIMATE}, {id}"), estimate_style, |l| Some(l.terms.estimate)));
    }
}

/// Two series whose values differ by at most this, relative, at every point draw one over the
/// other: 0.1 % is below a pixel on every axis of the figures (a log axis of a decade and more,
/// or a linear one from 0, over some 400 px).
pub const DRAWS_OVER_REL: f64 = 1e-3;

/// The largest relative difference between the values of two series at the same abscissae, at
/// every point; `None` where their abscissae differ or a value is missing in one only.
fn largest_difference(a: &Series, b: &Series) -> Option<f64> {
    if a.points.len() != b.points.len() {
        return None;
    }
    a.points.iter().zip(&b.points).try_fold(0.0f64, |d, (p, q)| {
        (p.0 == q.0).then_some(())?;
        match (p.1, q.1) {
            (Some(x), Some(y)) if x == y => Some(d),
            (Some(x), Some(y)) => Some(d.max((x - y).abs() / x.abs().max(y.abs()))),
            (None, None) => Some(d),
            _ => None,
        }
    })
}

/// Whether a series has a value that is drawn: a series that is 0 (or missing) everywhere draws
/// no curve on a log axis, and its legend says so.
fn drawn(s: &Series) -> bool {
    s.points.iter().any(|p| p.1.is_some_and(|y| y != 0.0 && y.is_finite()))
}

/// A series of `p` that coincides with a later one would hide under it: each such series gets
/// large hollow markers (drawn around the later one's), and the later one's legend names it
/// ([`told_apart`]): "(same values as X)" where their values agree to [`COINCIDE_REL`] at every
/// level, as the CLAIMS rows compare runs, and "(same values as X to 2×10⁻⁵)" where they differ
/// by at most that, relative, below [`DRAWS_OVER_REL`].
fn show_coincident(p: &mut Panel) {
    for j in 0..p.series.len() {
        if !drawn(&p.series[j]) {
            continue;
        }
        let same: Vec<(usize, f64)> = (0..j)
            .filter_map(|i| largest_difference(&p.series[i], &p.series[j]).filter(|&d| d <= DRAWS_OVER_REL).map(|d| (i, d)))
            .collect();
        if same.is_empty() {
            continue;
        }
        let names: Vec<String> = same
            .iter()
            .map(|&(i, d)| {
                let name = told_apart(&p.series[i].label, &p.series[j].label);
                if d <= COINCIDE_REL { name } else { format!("{name} to {}", sci(d)) }
            })
            .collect();
        for &(i, _) in &same {
            p.series[i].style = p.series[i].style.large();
        }
        p.series[j].label = format!("{} (same values as {})", p.series[j].label, names.join(", "));
    }
}

/// What names the series labelled `earlier` beside the one labelled `later`: its label without
/// the leading ", "-separated parts the two share ("error ‖u − u_h‖, uniform" beside "error
/// ‖u − u_h‖, uniform_cartesian" is "uniform"); the whole label where it shares none or all.
fn told_apart(earlier: &str, later: &str) -> String {
    let (a, b): (Vec<&str>, Vec<&str>) = (earlier.split(", ").collect(), later.split(", ").collect());
    let shared = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    if shared == 0 || shared == a.len() { earlier.to_string() } else { a[shared..].join(", ") }
}

fn fig2a(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::EX71)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut p = Panel::new("Example 7.1: error and estimate vs NDF", NDF_DESC, format!("error {ERR} and {ESTIMATE}"));
    error_and_estimate(&runs, &mut p, &format!("error {ERR}"));
    p.slopes.push(Slope { anchor: SlopeAnchor::Below(0), ..slope() });
    Ok(Ok(single(p)))
}

fn fig2b(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::EX71)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    // the efficiency, and the efficiency with eq. 6.3's log factor l_h divided out (the row
    // 7.1-efficiency judges the trend of both)
    type Eff = fn(&LevelRecord) -> Option<f64>;
    let kinds: [(&str, &str, Eff); 2] = [
        ("efficiency index", EFF_DESC, efficiency),
        ("efficiency / l_h", "efficiency index / l_{h},  l_{h} = 1 + |log h_{min}|^{2}", |l| efficiency(l).map(|e| e / l.terms.l_h)),
    ];
    let mut out = Vec::new();
    for (title, desc, y) in kinds {
        let mut p = Panel::new(title, NDF_DESC, desc);
        p.y_scale = YScale::Auto;
        for (k, r) in runs.iter().enumerate() {
            p.series.push(series(r, r.run.id.clone(), Style::nth(k).dashed(r.run.refine == Refine::Uniform), y));
        }
        p.hlines.push(eff_one());
        out.push(p);
    }
    if !out.iter().any(Panel::has_data) {
        return Ok(Err("study ex71 has no errors recorded".to_string()));
    }
    Ok(Ok(panels("Example 7.1: efficiency index (Fig. 2b), and with l_h divided out", out)))
}

fn fig3a(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::EX72)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut p = Panel::new("Example 7.2: estimate vs NDF", NDF_DESC, format!("{ESTIMATE} (and error vs reference solution)"));
    error_and_estimate(&runs, &mut p, &format!("error {ERR} vs reference"));
    let mut reference: Vec<usize> = runs.iter().filter_map(|r| r.reference_ndof).collect();
    reference.dedup();
    if !reference.is_empty() {
        let list = reference.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ");
        p.notes.push(format!("reference solution: NDF {list}"));
    }
    // anchor the slope at the estimate of the first run
    if let Some(i) = p.series.iter().position(|s| s.label.starts_with("estimate")) {
        p.slopes.push(Slope { anchor: SlopeAnchor::Below(i), ..slope() });
    }
    Ok(Ok(single(p)))
}

/// Fig. 4: the terms eta_1 .. eta_`terms` of the run of `role`.
fn fig4(shelf: &Shelf, roles: &Roles, role: Role, fig: &str, terms: usize) -> anyhow::Result<Built> {
    let study = role.study;
    let runs = match runs(shelf, study)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let Some(r) = roles.find(&runs, role) else {
        return Ok(Err(format!("study {study} has no run {} yet", roles.source(role))));
    };
    let etas = |l: &LevelRecord| [l.terms.eta1, l.terms.eta2, l.terms.eta3, l.terms.eta4, l.terms.eta5, l.terms.eta6, l.terms.eta7];
    let mut p = Panel::new(
        format!("{}: individual estimators ({}, Fig. {fig})", problem_title(&r.run.problem), refine_label(r)),
        NDF_DESC,
        "estimator contributions η_{i}",
    );
    let is_roundoff = |l: &LevelRecord, v: f64| v != 0.0 && v.abs() < ROUNDOFF * etas(l).iter().fold(0.0f64, |a, e| a.max(e.abs()));
    for i in 0..terms {
        let mut s =
            series(r, format!("η_{{{}}}", i + 1), Style::nth(i), |l| Some(if is_roundoff(l, etas(l)[i]) { 0.0 } else { etas(l)[i] }));
        s.roundoff = r.levels.iter().any(|l| is_roundoff(l, etas(l)[i]));
        p.series.push(s);
    }
    // the terms not plotted (Fig. 4(a) shows eta1..eta5): say what they are
    for i in terms..7 {
        let max = r.levels.iter().map(|l| etas(l)[i]).fold(0.0, f64::max);
        let eta = format!("η_{{{}}}", i + 1);
        p.notes.push(if max == 0.0 {
            format!("{eta} = 0 at all levels (not shown)")
        } else {
            format!("{eta} not shown (max {})", sci(max))
        });
    }
    p.slopes.push(Slope { anchor: SlopeAnchor::AboveAll, ..slope() });
    Ok(Ok(single(p)))
}

/// Fig. 3(b): a run's mesh at level 20 (`fig3b`: the paper's run, eta_5 as written; `fig3b_variant`:
/// eta_5 without full-contact nodes, where the free-boundary points are refinement centres).
fn mesh_at_level_20(shelf: &Shelf, roles: &Roles, role: Role) -> anyhow::Result<Built> {
    let study = role.study;
    let Some(run) = roles.id(role) else { return Ok(Err(format!("no run of {} declares role {}", role.study, role.name))) };
    let mut level = MESH_LEVEL;
    let mut note = String::new();
    let saved = shelf.saved_levels(study, run)?;
    if !saved.contains(&level) {
        // fall back to the finest saved level of the run, saying so in the title
        let Some(&l) = saved.last() else {
            return Ok(Err(format!("no mesh snapshot {}", shelf.mesh_path(study, run, level)?.display())));
        };
        note = format!(" (level {MESH_LEVEL} not saved)");
        level = l;
    }
    let snap = shelf.mesh(study, run, level).with_context(|| format!("reading the mesh snapshot of level {level}"))?;
    Ok(Ok(Figure::Mesh(mesh_figure(&snap, &note))))
}

fn mesh_figure(s: &MeshSnapshot, note: &str) -> MeshFigure {
    let p = |v: [f64; 2]| (v[0], v[1]);
    let mut bbox = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for v in &s.vertices {
        bbox = [bbox[0].min(v[0]), bbox[1].min(v[1]), bbox[2].max(v[0]), bbox[3].max(v[1])];
    }
    if !bbox[0].is_finite() {
        bbox = [0.0, 0.0, 1.0, 1.0];
    }
    MeshFigure {
        title: format!("{}: {} mesh at level {}{note}, NDF = {}", problem_title(&problem_of(s)), s.run, s.level, s.ndof),
        edges: edge_chains(&s.vertices, &s.triangles),
        active: s.contact_nodes.iter().filter(|c| c.active).map(|c| p(c.x)).collect(),
        inactive: s.contact_nodes.iter().filter(|c| !c.active).map(|c| p(c.x)).collect(),
        kinks: s.kinks.iter().map(|&k| p(k)).collect(),
        vlines: Vec::new(),
        bbox,
        n_triangles: s.triangles.len(),
        n_vertices: s.vertices.len(),
    }
}

/// The snapshot does not store its problem; the study name says it for the paper's studies.
fn problem_of(s: &MeshSnapshot) -> String {
    [problem_names::EX71, problem_names::EX72]
        .into_iter()
        .find(|p| s.study.starts_with(p) || s.run.starts_with(p))
        .map_or_else(|| s.study.clone(), str::to_string)
}

/// The mesh edges (each once) joined greedily into polylines.
fn edge_chains(vertices: &[[f64; 2]], triangles: &[[usize; 3]]) -> Vec<Vec<(f64, f64)>> {
    let n = vertices.len();
    let mut seen = HashSet::new();
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    let mut n_edges = 0;
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a >= n || b >= n || a == b {
                continue;
            }
            if seen.insert((a.min(b), a.max(b))) {
                adj[a].push((b, n_edges));
                adj[b].push((a, n_edges));
                n_edges += 1;
            }
        }
    }
    let mut used = vec![false; n_edges];
    let mut next = vec![0usize; n];
    let mut chains = Vec::new();
    // start at odd-degree vertices first: fewer, longer chains
    let mut starts: Vec<usize> = (0..n).filter(|&v| !adj[v].len().is_multiple_of(2)).collect();
    starts.extend((0..n).filter(|&v| adj[v].len().is_multiple_of(2)));
    for s in starts {
        loop {
            let mut cur = s;
            let mut chain = vec![cur];
            loop {
                while next[cur] < adj[cur].len() && used[adj[cur][next[cur]].1] {
                    next[cur] += 1;
                }
                let Some(&(to, e)) = adj[cur].get(next[cur]) else { break };
                used[e] = true;
                chain.push(to);
                cur = to;
            }
            if chain.len() < 2 {
                break;
            }
            chains.push(chain.into_iter().map(|v| (vertices[v][0], vertices[v][1])).collect());
        }
    }
    chains
}

// ---------------------------------------------------------------------------------------------
// ablations: one panel per problem

fn panels(title: &str, panels: Vec<Panel>) -> Figure {
    if panels.len() == 1 {
        let mut p = panels.into_iter().next().expect("one panel");
        p.title = format!("{title}: {}", p.title);
        single(p)
    } else {
        Figure::Lines(LineFigure { title: Some(title.to_string()), panels, columns: None })
    }
}

fn c0_sweep(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::C0_SWEEP)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut out = Vec::new();
    for (problem, group) in by_problem(&runs) {
        let mut p = Panel::new(problem_title(&problem), NDF_DESC, EFF_DESC);
        p.y_scale = YScale::Auto;
        for (k, r) in group.iter().enumerate() {
            let ratio = |l: &LevelRecord| l.err_quadrature.filter(|&e| e > 0.0 && l.terms.eta_h > 0.0).map(|e| l.terms.eta_h / e);
            let c0_min = r.levels.iter().filter_map(|l| ratio(l).map(|q| 1.0 / q)).fold(f64::NEG_INFINITY, f64::max);
            if !c0_min.is_finite() {
                p.notes.push(format!("{}: no errors recorded", short_id(r)));
                continue;
            }
            let st = Style::nth(k);
            p.series.push(series(r, format!("{}, C_{{0}} = {C0_PAPER}", short_id(r)), st, |l| ratio(l).map(|q| C0_PAPER * q)));
            p.series.push(series(r, format!("{}, C_{{0}} = {} (smallest reliable)", short_id(r), sci(c0_min)), st.dashed(true), |l| {
                ratio(l).map(|q| c0_min * q)
            }));
        }
        p.hlines.push(eff_one());
        out.push(p);
    }
    if !out.iter().any(Panel::has_data) {
        return Ok(Err("study c0_sweep has no errors recorded".to_string()));
    }
    Ok(Ok(panels(concat!("C_{0} sweep: efficiency for C_{0} = ", c0_paper!(), " and the smallest reliable C_{0}"), out)))
}

fn log_label(f: LogFactor) -> &'static str {
    match f {
        LogFactor::Squared => "l_{h} = 1 + |log h_{min}|^{2}",
        LogFactor::Linear => "l_{h} = 1 + |log h_{min}|",
        LogFactor::One => "l_{h} = 1",
    }
}

fn log_ablation(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::LOG_ABLATION)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut out = Vec::new();
    for (problem, mut group) in by_problem(&runs) {
        let mut p = Panel::new(problem_title(&problem), NDF_DESC, EFF_DESC);
        p.y_scale = YScale::Auto;
        group.sort_by_key(|r| r.run.estimator.log_factor as u8);
        for (k, r) in group.iter().enumerate() {
            let label = format!("{}{}", log_label(r.run.estimator.log_factor), distinguish(&group, r, |o| o.run.estimator.log_factor));
            p.series.push(series(r, label, Style::nth(k), efficiency));
        }
        p.hlines.push(eff_one());
        out.push(p);
    }
    if !out.iter().any(Panel::has_data) {
        return Ok(Err("study log_ablation has no errors recorded".to_string()));
    }
    Ok(Ok(panels("Log factor ablation (efficiency per level)", out)))
}

fn contact_label(c: ContactTerm) -> &'static str {
    match c {
        ContactTerm::AsWritten => "as written",
        ContactTerm::WithoutFullContact => "without full-contact nodes",
        ContactTerm::TensileOnFullContact => "repaired (tensile part at full contact)",
    }
}

fn contact_term_ablation(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::CONTACT_TERM_ABLATION)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut out = Vec::new();
    for (problem, group) in by_problem(&runs) {
        let mut p = Panel::new(problem_title(&problem), NDF_DESC, format!("{ESTIMATE} (solid) and η_{{5}} (dashed)"));
        for (k, r) in group.iter().enumerate() {
            let variant =
                format!("{}{}", contact_label(r.run.estimator.contact_term), distinguish(&group, r, |o| o.run.estimator.contact_term));
            let st = Style::nth(k);
            p.series.push(series(r, format!("estimate, {variant}"), st, |l| Some(l.terms.estimate)));
            let st5 = Style { marker: render::MARKERS[(k + 4) % render::MARKERS.len()], ..st }.dashed(true);
            p.series.push(series(r, format!("η_{{5}}, {variant}"), st5, |l| Some(l.terms.eta5)));
        }
        out.push(p);
    }
    Ok(Ok(panels("Contact term ablation: η_{5} with and without full-contact nodes", out)))
}

fn theta_ablation(shelf: &Shelf) -> anyhow::Result<Built> {
    let runs = match runs(shelf, studies::THETA_ABLATION)? {
        Ok(r) => r,
        Err(why) => return Ok(Err(why)),
    };
    let mut out = Vec::new();
    for (problem, group) in by_problem(&runs) {
        // the error where every run of the problem has some, else the estimate for all
        let errors = group.iter().all(|r| r.levels.iter().filter(|l| l.err_quadrature.is_some()).count() >= 2);
        let y_desc = if errors {
            if group.iter().any(|r| r.reference_ndof.is_some()) {
                format!("error {ERR} (vs reference solution)")
            } else {
                format!("error {ERR}")
            }
        } else {
            format!("{ESTIMATE} (errors not available)")
        };
        let mut p = Panel::new(problem_title(&problem), NDF_DESC, y_desc);
        for (k, r) in group.iter().enumerate() {
            let uniform = r.run.refine == Refine::Uniform;
            let theta =
                |o: &RunRecord| if o.run.refine == Refine::Uniform { "uniform".to_string() } else { format!("θ = {}", o.run.theta) };
            let label = format!("{}{}", theta(r), distinguish(&group, r, theta));
            let y = move |l: &LevelRecord| if errors { l.err_quadrature } else { Some(l.terms.estimate) };
            p.series.push(series(r, label, Style::nth(k).dashed(uniform), y));
        }
        p.slopes.push(slope());
        out.push(p);
    }
    Ok(Ok(panels("Marking parameter θ: error vs NDF", out)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_chains_cover_each_edge_once() {
        let v = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        let t = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let chains = edge_chains(&v, &t);
        let segments: usize = chains.iter().map(|c| c.len() - 1).sum();
        assert_eq!(segments, 8);
        let mut seen = HashSet::new();
        for c in &chains {
            for w in c.windows(2) {
                let key = |p: (f64, f64)| ((p.0 * 10.0) as i32, (p.1 * 10.0) as i32);
                let (a, b) = (key(w[0]), key(w[1]));
                assert!(seen.insert((a.min(b), a.max(b))), "edge drawn twice");
            }
        }
    }

    fn line(label: &str, ys: &[f64]) -> Series {
        Series {
            label: label.into(),
            points: ys.iter().enumerate().map(|(i, &y)| (i as f64, Some(y))).collect(),
            style: Style::nth(0),
            roundoff: false,
        }
    }

    #[test]
    fn a_series_that_coincides_with_another_is_named_in_the_legend() {
        let mut p = Panel::new("", "", "");
        p.series = vec![
            line("error, repaired", &[1.0, 0.5, 0.25]),
            line("error, without full contact", &[1.0, 0.5, 0.25 * (1.0 + 1e-14)]),
            line("error, uniform", &[1.0, 0.5, 0.3]),
            line("estimate, uniform", &[10.0, 5.0, 3.0]),
            line("estimate, repaired", &[10.0, 5.0, 3.0 * (1.0 + 2e-5)]),
            line("η_{6}", &[0.0, 0.0, 0.0]),
            line("η_{7}", &[0.0, 0.0, 0.0]),
        ];
        show_coincident(&mut p);
        let labels: Vec<&str> = p.series.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "error, repaired",
                "error, without full contact (same values as repaired)",
                "error, uniform",
                "estimate, uniform",
                "estimate, repaired (same values as uniform to 2.00×10^{-5})",
                "η_{6}",
                "η_{7}"
            ],
            "a series 0 everywhere draws nothing to hide"
        );
        let large: Vec<bool> = p.series.iter().map(|s| s.style.large).collect();
        assert_eq!(large, [true, false, false, true, false, false, false], "the hidden series is drawn around the other");
    }

    #[test]
    fn a_coinciding_series_is_named_by_what_tells_it_apart() {
        assert_eq!(told_apart("error ‖u‖, uniform", "error ‖u‖, uniform_cartesian"), "uniform");
        assert_eq!(told_apart("repaired", "without full contact"), "repaired");
        assert_eq!(told_apart("a, b", "a, b"), "a, b");
    }

    #[test]
    fn every_figure_has_its_study_and_a_caption_that_says_what_it_shows() {
        for f in FIGURES {
            assert!(study_of(f).is_some(), "figure {f}: no study");
            let c = caption(f).unwrap_or_else(|| panic!("figure {f}: no caption"));
            assert!(c.len() > 80 && c.ends_with('.'), "figure {f}: caption {c:?}");
            assert!(c.contains(" against ") || c.contains(" mesh "), "figure {f}: the caption names no axes: {c:?}");
        }
    }

    #[test]
    fn scientific() {
        assert_eq!(sci(1.234e-5), "1.23×10^{-5}");
        assert_eq!(sci(0.0123), "0.0123");
        assert_eq!(sci(0.45), "0.450");
    }
}
