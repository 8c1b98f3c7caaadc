//! A user's own contact problem through the public API: an elastic block (E = 200, nu = 0.3,
//! plane strain) pushed down by 0.02 at its top onto a parabolic rigid foundation below its
//! bottom, solved by the adaptive loop with the paper's estimator.
//!
//! `cargo run --release --example own_problem`

use signorini::adapt::{self, AdaptTermination};
use signorini::mesh::MeshSpec;
use signorini::problems::{Material, Part, Problem, contact_bottom_dirichlet_top};
use signorini::settings::adapt::AdaptConfig;
use std::ops::ControlFlow;

/// The block [0, 1]^2: contact on the bottom y = 0, pushed at the top y = 1, free sides.
struct Foundation;

impl Problem for Foundation {
    fn name(&self) -> &str {
        "foundation"
    }
    fn description(&self) -> &str {
        "block pressed onto a parabolic foundation"
    }
    fn material(&self) -> Material {
        Material::from_young(200.0, 0.3)
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        contact_bottom_dirichlet_top(x)
    }
    fn body_force(&self, _: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn traction(&self, _: [f64; 2], _: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn dirichlet(&self, _: [f64; 2]) -> [f64; 2] {
        [0.0, -0.02]
    }
    /// The foundation's direction (the body's outward normal, the second argument, is not needed).
    fn contact_normal(&self, _: [f64; 2], _: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    /// The foundation lies chi(x) below the bottom: u . n = -u_y <= chi.
    fn gap(&self, x: [f64; 2]) -> f64 {
        0.01 + 0.2 * (x[0] - 0.5).powi(2)
    }
}

fn main() -> anyhow::Result<()> {
    let problem = Foundation;
    let mesh = MeshSpec::parse("structured:4")?.build(&problem)?;
    let config = AdaptConfig { levels: 12, max_ndof: Some(20_000), ..Default::default() };
    config.validate()?;
    println!("{:>5} {:>7} {:>10} {:>6} {:>15}", "level", "ndof", "estimate", "active", "contact zone");
    let result = adapt::run(&problem, mesh, &config, None, &mut |l| {
        let (r, zone) = (l.record, l.solution.contact_zone());
        let zone = zone.map_or("-".into(), |[a, b]| format!("[{a:.4}, {b:.4}]"));
        println!("{:>5} {:>7} {:>10.3e} {:>6} {:>15}", r.level, r.ndof, r.terms.estimate, r.active_nodes, zone);
        ControlFlow::Continue(())
    })?;
    let why = match result.termination {
        AdaptTermination::LevelsReached => "all levels solved",
        AdaptTermination::MaxNdofReached => "the next level would exceed max_ndof",
        AdaptTermination::StopNdofReached => "a level reached stop_ndof",
        AdaptTermination::StoppedByObserver => "stopped by the observer",
        AdaptTermination::NothingMarked => "the estimate is zero: nothing to mark",
        AdaptTermination::FarFromOrigin { .. } => "the next mesh is too fine for its coordinates (far from the origin)",
    };
    let kkt = result.solution.kkt();
    println!("stopped: {why}; final mesh {} triangles, max penetration {:.1e}", result.mesh.n_triangles(), kkt.max_penetration);
    Ok(())
}
