//! Hertz's plane-strain contact of an elastic cylinder on a rigid flat, the benchmark every contact
//! code checks, and its comparison with a discrete contact pressure.
//!
//! A cylinder of radius R (Young's modulus E, Poisson's ratio nu, plane strain) pressed onto a
//! rigid flat by a force F per unit length touches it on |x| <= a with the pressure
//!
//! p(x) = p0 sqrt(1 - x^2 / a^2),   a = sqrt(4 F R (1 - nu^2) / (pi E)),   p0 = 2 F / (pi a)
//!
//! (Johnson, *Contact Mechanics*, 1985, Section 4.3, with one body rigid). The formulas assume
//! a << R and a half-space below and above the contact; a finite body (here a half-disc held at
//! its flat side) deviates from them by terms that vanish as a / R -> 0, which a second, smaller
//! load measures.

use model::level::sample::ContactSample;
use model::problems::{Curve, Material, Problem};

/// The closed-form solution for a cylinder of radius `radius` with the plane-strain modulus
/// `e_star` = E / (1 - nu^2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz {
    pub radius: f64,
    pub e_star: f64,
}

impl Hertz {
    /// From the Lamé constants: E / (1 - nu^2) = 2 mu / (1 - nu) with nu = zeta / (2 (zeta + mu)).
    pub fn new(material: Material, radius: f64) -> Self {
        let nu = material.zeta / (2.0 * (material.zeta + material.mu));
        Hertz { radius, e_star: 2.0 * material.mu / (1.0 - nu) }
    }

    /// The contact half-width a = sqrt(4 F R / (pi E*)) for the force `force` per unit length.
    pub fn half_width(&self, force: f64) -> f64 {
        (4.0 * force * self.radius / (std::f64::consts::PI * self.e_star)).sqrt()
    }

    /// The peak pressure p0 = 2 F / (pi a).
    pub fn peak_pressure(&self, force: f64) -> f64 {
        2.0 * force / (std::f64::consts::PI * self.half_width(force))
    }

    /// The pressure p(x) = p0 sqrt(1 - x^2 / a^2) inside the contact, 0 outside; x from the
    /// first point of contact.
    pub fn pressure(&self, force: f64, x: f64) -> f64 {
        let a = self.half_width(force);
        self.peak_pressure(force) * (1.0 - (x / a).powi(2)).max(0.0).sqrt()
    }
}

/// The physical group of a Hertz problem's contact surface: a circle (`Problem::curve_of_group`).
pub const CONTACT_GROUP: &str = "contact";

/// Hertz's solution for a problem: its material and the radius of the circle its contact group
/// lies on; `None` if the problem has no circular contact group.
pub fn for_problem(problem: &dyn Problem) -> Option<Hertz> {
    match problem.curve_of_group(CONTACT_GROUP)? {
        Curve::Circle { radius, .. } => Some(Hertz::new(problem.material(), radius)),
    }
}

/// A discrete contact against Hertz's: the measured quantities, the closed form at the measured
/// force, and their relative deviations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// F = sum of the nodal contact forces.
    pub force: f64,
    /// The discrete half-width: on each side the midpoint between the outermost active node and
    /// the next, inactive, contact node; the mean of both sides.
    pub half_width: f64,
    /// Half the larger of the two sides' gaps between the outermost active and the next node: the
    /// resolution of `half_width`.
    pub half_width_resolution: f64,
    /// The largest nodal pressure.
    pub peak_pressure: f64,
    /// Hertz's a and p0 at the measured force.
    pub hertz_half_width: f64,
    pub hertz_peak_pressure: f64,
    /// max over active nodes of |p_h - p| / p0 (Hertz's p at the measured force).
    pub profile_deviation: f64,
    /// Where the contact is centred: the midpoint of the discrete zone (of the two sides' midpoints
    /// between the outermost active and the next node); the profile is compared about it.
    pub centre: f64,
}

impl Comparison {
    /// Relative deviation of the half-width from Hertz's.
    pub fn half_width_deviation(&self) -> f64 {
        self.half_width / self.hertz_half_width - 1.0
    }
    /// Relative deviation of the peak pressure from Hertz's.
    pub fn peak_deviation(&self) -> f64 {
        self.peak_pressure / self.hertz_peak_pressure - 1.0
    }
}

/// Compare the contact nodes of a discrete solution with Hertz's solution. The abscissa of a
/// node is its x; the contact is assumed to be one interval around the lowest point of the
/// cylinder. `None` without active nodes or without inactive nodes on both sides (the contact
/// zone is not resolved).
pub fn compare(hertz: &Hertz, nodes: &[ContactSample]) -> Option<Comparison> {
    let force: f64 = nodes.iter().map(|n| n.lambda).sum();
    let mut sorted: Vec<&ContactSample> = nodes.iter().collect();
    sorted.sort_by(|a, b| a.x[0].total_cmp(&b.x[0]));
    let first = sorted.iter().position(|n| n.active)?;
    let last = sorted.iter().rposition(|n| n.active)?;
    if first == 0 || last + 1 == sorted.len() {
        return None;
    }
    let (lo_in, lo_out) = (sorted[first].x[0], sorted[first - 1].x[0]);
    let (hi_in, hi_out) = (sorted[last].x[0], sorted[last + 1].x[0]);
    let half_width = 0.25 * ((hi_in + hi_out) - (lo_in + lo_out));
    let half_width_resolution = 0.5 * (lo_in - lo_out).max(hi_out - hi_in);
    let peak = sorted.iter().copied().max_by(|a, b| a.pressure.total_cmp(&b.pressure))?;
    let mid = 0.25 * (lo_in + lo_out + hi_in + hi_out);
    let p0 = hertz.peak_pressure(force);
    let profile_deviation =
        sorted.iter().filter(|n| n.active).map(|n| (n.pressure - hertz.pressure(force, n.x[0] - mid)).abs() / p0).fold(0.0, f64::max);
    Some(Comparison {
        force,
        half_width,
        half_width_resolution,
        peak_pressure: peak.pressure,
        hertz_half_width: hertz.half_width(force),
        hertz_peak_pressure: p0,
        profile_deviation,
        centre: mid,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel_like() -> Hertz {
        Hertz::new(Material::from_young(1000.0, 0.3), 1.0)
    }

    #[test]
    fn plane_strain_modulus_from_lame_constants() {
        let h = steel_like();
        assert!((h.e_star - 1000.0 / (1.0 - 0.09)).abs() < 1e-9 * h.e_star, "{}", h.e_star);
    }

    #[test]
    fn the_pressure_integrates_to_the_force() {
        let h = steel_like();
        let f = 2.0;
        let a = h.half_width(f);
        // composite midpoint rule in the angle: x = a sin t, p dx = p0 a cos^2 t dt
        let n = 20000;
        let total: f64 = (0..n)
            .map(|k| {
                let t = -std::f64::consts::FRAC_PI_2 + (k as f64 + 0.5) * std::f64::consts::PI / n as f64;
                h.pressure(f, a * t.sin()) * a * t.cos() * std::f64::consts::PI / n as f64
            })
            .sum();
        assert!((total - f).abs() < 1e-6 * f, "{total} vs {f}");
        // a / R = 0.05 needs F = pi E* a^2 / (4 R)
        let f05 = std::f64::consts::PI * h.e_star * 0.0025 / 4.0;
        assert!((h.half_width(f05) - 0.05).abs() < 1e-14);
    }

    /// Nodes sampling Hertz's pressure exactly: the comparison recovers a within the node spacing
    /// and p0 and the profile exactly.
    #[test]
    fn exact_samples_give_no_deviation() {
        let h = steel_like();
        let f = 2.0;
        let a = h.half_width(f);
        let dx = a / 40.5;
        let nodes: Vec<ContactSample> = (-100..=100)
            .map(|k| {
                let x = k as f64 * dx;
                let p = h.pressure(f, x);
                ContactSample { x: [x, 0.0], lambda: if k == 0 { f } else { 0.0 }, pressure: p, active: p > 0.0 }
            })
            .collect();
        let c = compare(&h, &nodes).unwrap();
        assert_eq!(c.force, f);
        assert!(c.half_width_deviation().abs() <= c.half_width_resolution / a + 1e-12, "{c:?}");
        assert!(c.peak_deviation().abs() < 1e-14 && c.profile_deviation < 1e-14, "{c:?}");
        // a zone touching the end of the contact nodes is not resolved
        assert!(compare(&h, &nodes[90..]).is_none());
    }
}
