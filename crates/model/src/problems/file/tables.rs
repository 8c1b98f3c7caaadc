//! The tables of a problem file read one by one: `[material]`, `[parts]`, `[curves]`,
//! `[contact] normal`, `[exact]`, the point lists and the constants a study overrides.

use super::*;

/// What `[parts]` declares.
pub(super) struct Parts {
    pub groups: BTreeMap<String, Part>,
    /// where each group is named in `[parts]`, for errors that belong there
    pub group_keys: BTreeMap<String, (&'static str, std::ops::Range<usize>)>,
    pub contact_predicate: Option<Predicate>,
    pub dirichlet_predicate: Option<Predicate>,
    pub declared_parts: Vec<String>,
}

impl Reader<'_> {
    /// Constants a study sets (its run's `constants` table), each one the file must declare.
    pub(super) fn override_constants(&mut self, raw: &mut FileToml, overrides: &BTreeMap<String, f64>) -> Result<(), ProblemFileError> {
        for (name, value) in overrides {
            if raw.constants.remove(name).is_none() || !value.is_finite() {
                let declared = raw.constants.keys().filter(|k| !overrides.contains_key(*k)).cloned().collect::<Vec<_>>();
                return Err(self.error(
                    &format!("constants.{name}"),
                    0..0,
                    format!(
                        "a study sets the constant `{name}` = {value}, but {} (the file declares: {})",
                        if value.is_finite() { "the file does not declare it" } else { "a constant must be a finite number" },
                        if declared.is_empty() { "none".to_string() } else { declared.join(", ") }
                    ),
                ));
            }
            self.constants.insert(name.clone(), *value);
        }
        Ok(())
    }

    /// `[material]`: E, nu and a model, or the Lamé constants mu and lambda.
    pub(super) fn material(&self, m: &MaterialToml) -> Result<Material, ProblemFileError> {
        let material_span = [&m.e, &m.nu, &m.mu, &m.lambda].iter().find_map(|v| v.as_ref().map(|v| v.span())).unwrap_or(0..0);
        let material = match (&m.e, &m.nu, &m.mu, &m.lambda) {
            (Some(e), Some(nu), None, None) => {
                let (e, nu) = (self.number("material.E", e)?, self.number("material.nu", nu)?);
                let model = m.model.as_ref().ok_or_else(|| {
                    self.error(
                        "material.model",
                        material_span.clone(),
                        "model = \"plane_strain\" or \"plane_stress\" with E and nu (missing)",
                    )
                })?;
                if !(e > 0.0) {
                    return Err(self.error(
                        "material.E",
                        m.e.as_ref().map_or(0..0, |v| v.span()),
                        format!("a positive Young's modulus, got {e}"),
                    ));
                }
                let nu_span = m.nu.as_ref().map_or(0..0, |v| v.span());
                let model_name = model.get_ref().as_str();
                if matches!(model_name, "plane_strain" | "plane_stress") && !(nu > -1.0 && nu < 0.5) {
                    return Err(self.error("material.nu", nu_span, poisson_ratio_refused(model_name, nu)));
                }
                match model_name {
                    "plane_strain" => Material::from_young(e, nu),
                    "plane_stress" => Material::from_young_plane_stress(e, nu),
                    other => {
                        return Err(self.error(
                            "material.model",
                            model.span(),
                            format!("\"plane_strain\" or \"plane_stress\", got {other:?}"),
                        ));
                    }
                }
            }
            (None, None, Some(mu), Some(lambda)) => {
                if let Some(model) = &m.model {
                    return Err(self.error(
                        "material.model",
                        model.span(),
                        "no model with Lamé constants (mu and lambda are the plane ones)",
                    ));
                }
                let material = Material { mu: self.number("material.mu", mu)?, zeta: self.number("material.lambda", lambda)? };
                if !(material.mu > 0.0 && material.zeta + material.mu > 0.0) {
                    return Err(self.error(
                        "material",
                        mu.span(),
                        format!("mu > 0 and lambda + mu > 0 (coercive), got mu = {}, lambda = {}", material.mu, material.zeta),
                    ));
                }
                material
            }
            _ => {
                return Err(self.error(
                    "material",
                    material_span,
                    "either E, nu and model (\"plane_strain\" or \"plane_stress\"), or the Lamé constants mu and lambda",
                ));
            }
        };
        Ok(material)
    }

    /// `[parts]`: the contact, Dirichlet and Neumann parts as predicates or physical groups.
    pub(super) fn parts(&self, raw: &PartsToml) -> Result<Parts, ProblemFileError> {
        let mut groups = BTreeMap::new();
        // where each group is named in [parts], for errors that belong there
        let mut group_keys = BTreeMap::new();
        let mut predicates = [None, None];
        let mut declared_parts = Vec::new();
        for (key, part, value) in [
            ("parts.contact", Part::Contact, Some(&raw.contact)),
            ("parts.dirichlet", Part::Dirichlet, raw.dirichlet.as_ref()),
            ("parts.neumann", Part::Neumann, raw.neumann.as_ref()),
        ] {
            let Some(value) = value else { continue };
            declared_parts.push(match value.get_ref() {
                PartToml::Predicate(p) => format!("{key} = {p:?}"),
                PartToml::Groups(list) => format!("{key} = {list:?}"),
            });
            match value.get_ref() {
                PartToml::Predicate(_) if part == Part::Neumann => {
                    return Err(self.error(
                    key,
                    value.span(),
                    "a list of physical groups (with predicates, the edges neither the contact nor the Dirichlet predicate takes are Neumann)",
                ));
                }
                PartToml::Predicate(p) => predicates[(part == Part::Dirichlet) as usize] = Some(self.predicate(key, value.span(), p)?),
                PartToml::Groups(list) if list.is_empty() && part == Part::Contact => {
                    return Err(self.error(
                        key,
                        value.span(),
                        "at least one physical group: parts.contact is empty, so nothing could be in contact (a mesh's groups would all be reported as named by no part)",
                    ));
                }
                PartToml::Groups(list) => {
                    for g in list {
                        if let Some(other) = groups.insert(g.clone(), part) {
                            return Err(self.error(key, value.span(), format!("physical group {g:?} is already in the {other:?} part")));
                        }
                        group_keys.insert(g.clone(), (key, value.span()));
                    }
                }
            }
        }
        let [contact_predicate, dirichlet_predicate] = predicates;
        Ok(Parts { groups, group_keys, contact_predicate, dirichlet_predicate, declared_parts })
    }

    /// `[curves]`: a circle for physical groups named in `[parts]`.
    pub(super) fn curves(
        &self,
        raw: &BTreeMap<String, Spanned<CurveToml>>,
        parts: &Parts,
    ) -> Result<BTreeMap<String, Curve>, ProblemFileError> {
        let mut curves = BTreeMap::new();
        for (group, curve) in raw {
            let key = format!("curves.{group}");
            // a near miss in [parts] ("contct" for "contact") is where the mistake most likely is
            let near = parts.groups.keys().find(|g| strsim::levenshtein(g, group) <= 2 && !raw.contains_key(*g));
            if let (false, Some(near)) = (parts.groups.contains_key(group), near) {
                let (parts_key, span) = parts.group_keys[near].clone();
                return Err(self.error(
                parts_key,
                span,
                format!("the physical group [curves] gives a circle for, {group:?}; {near:?} is named here instead: one of the two is misspelt (the mesh's groups decide)"),
            ));
            }
            if !parts.groups.contains_key(group) {
                return Err(self.error(
                    &key,
                    curve.span(),
                    format!(
                        "a physical group named in [parts]; {group:?} is referenced nowhere (groups there: {})",
                        if parts.groups.is_empty() {
                            "none".to_string()
                        } else {
                            parts.groups.keys().cloned().collect::<Vec<_>>().join(", ")
                        }
                    ),
                ));
            }
            let c = &curve.get_ref().circle;
            if !(c.radius > 0.0 && c.radius.is_finite() && c.centre.iter().all(|v| v.is_finite())) {
                return Err(self.error(
                    &format!("{key}.circle"),
                    curve.span(),
                    format!(
                        "a finite centre and a positive radius, got centre [{}, {}] and radius {}",
                        c.centre.0[0], c.centre.0[1], c.radius
                    ),
                ));
            }
            curves.insert(group.clone(), Curve::Circle { centre: c.centre.0, radius: c.radius });
        }
        Ok(curves)
    }

    /// `[contact] normal`: a direction, or "outward": the body's outward normal on each contact
    /// edge, its `[curves]` circle's or the straight edge's (found on the mesh, edge by edge: no
    /// part of the file decides it for another).
    pub(super) fn normal(&self, normal_value: &Spanned<NormalToml>) -> Result<Normal, ProblemFileError> {
        let xy = ["x", "y"];
        let normal = match normal_value.get_ref() {
            NormalToml::Pair(p) => {
                let n = self.pair("contact.normal", normal_value.span(), p, &xy)?;
                if let [Expr::Const(a), Expr::Const(b)] = &n
                    && !(a.hypot(*b) > 0.0 && a.is_finite() && b.is_finite())
                {
                    return Err(self.error("contact.normal", normal_value.span(), format!("a nonzero direction, got [{a}, {b}]")));
                }
                Normal::Fixed(n)
            }
            NormalToml::Word(w) if w == "outward" => Normal::Outward,
            NormalToml::Word(w) => {
                return Err(self.error("contact.normal", normal_value.span(), format!("\"outward\" or [nx, ny], got {w:?}")));
            }
        };
        Ok(normal)
    }

    /// `required_vertices` and `load_breaks`: lists of numbers.
    pub(super) fn lists(&self, raw: &FileToml) -> Result<(Vec<[f64; 2]>, Vec<f64>), ProblemFileError> {
        let mut required_vertices = Vec::new();
        if let Some(v) = &raw.required_vertices {
            for (i, p) in v.get_ref().iter().enumerate() {
                let key = format!("required_vertices[{i}]");
                let s = |k: usize| Spanned::new(v.span(), p[k].clone());
                required_vertices.push([self.number(&key, &s(0))?, self.number(&key, &s(1))?]);
            }
        }
        let mut load_breaks = Vec::new();
        if let Some(v) = &raw.load_breaks {
            for (i, c) in v.get_ref().iter().enumerate() {
                load_breaks.push(self.number(&format!("load_breaks[{i}]"), &Spanned::new(v.span(), c.clone()))?);
            }
        }
        Ok((required_vertices, load_breaks))
    }

    /// `dirichlet`: the data and the components they prescribe; a component written `"free"` is
    /// not prescribed (zero traction there, rollers), and at least one must be.
    pub(super) fn dirichlet(
        &self,
        value: Option<&Spanned<VectorToml>>,
        has_exact: bool,
    ) -> Result<(VectorData, [bool; 2]), ProblemFileError> {
        if let Some(v) = value
            && let VectorToml::Pair(pair) = v.get_ref()
        {
            let free = [0, 1].map(|i| is_free(&pair[i]));
            if free == [true, true] {
                return Err(self.error(
                    "dirichlet",
                    v.span(),
                    "at least one component prescribed (a number or an expression; \"free\" leaves one free): a side with both free is Neumann, leave it out of parts.dirichlet",
                ));
            }
            let data = [0, 1].map(|i| if free[i] { Scalar::Number(0.0) } else { pair[i].clone() });
            return Ok((VectorData::Exprs(self.pair("dirichlet", v.span(), &data, &["x", "y"])?), free.map(|f| !f)));
        }
        Ok((self.vector("dirichlet", value, &["x", "y"], has_exact)?, [true, true]))
    }

    /// `[[point_constraints]]`: each a point `at` (numbers or expressions of the constants) and
    /// the components `u` prescribed there (numbers or expressions of the constants, or
    /// `"free"`; at least one prescribed); no point twice.
    pub(super) fn point_constraints(&self, raw: &[PointToml]) -> Result<Vec<super::super::PointConstraint>, ProblemFileError> {
        let mut out: Vec<super::super::PointConstraint> = Vec::new();
        for (i, c) in raw.iter().enumerate() {
            let key = format!("point_constraints[{i}]");
            let number = |k: &str, v: &Spanned<Two<Scalar>>, j: usize| {
                self.number(&format!("{key}.{k}[{j}]"), &Spanned::new(v.span(), v.get_ref()[j].clone()))
            };
            let at = [number("at", &c.at, 0)?, number("at", &c.at, 1)?];
            let mut u = [None, None];
            for (j, uj) in u.iter_mut().enumerate() {
                if !is_free(&c.u.get_ref()[j]) {
                    *uj = Some(number("u", &c.u, j)?);
                }
            }
            if u == [None, None] {
                return Err(self.error(
                    &format!("{key}.u"),
                    c.u.span(),
                    "at least one component prescribed (a number or an expression of the constants; \"free\" leaves one free)",
                ));
            }
            if let Some(j) = out.iter().position(|o| (o.at[0] - at[0]).hypot(o.at[1] - at[1]) < 1e-12) {
                return Err(self.error(
                    &format!("{key}.at"),
                    c.at.span(),
                    format!(
                        "a point not constrained before: ({}, {}) is point_constraints[{j}] too (give both components in one entry)",
                        at[0], at[1]
                    ),
                ));
            }
            out.push(super::super::PointConstraint { at, u });
        }
        Ok(out)
    }

    /// `[exact]`: the exact displacement and its gradient (derived when not given).
    pub(super) fn exact(&self, raw: &Option<ExactToml>) -> Result<Option<ExactExprs>, ProblemFileError> {
        let xy = ["x", "y"];
        Ok(match raw {
            None => None,
            Some(e) => {
                let u = self.pair("exact.u", e.u.span(), e.u.get_ref(), &xy)?;
                let grad = match &e.grad {
                    Some(g) => {
                        let [g0, g1] = &g.get_ref().0;
                        [self.pair("exact.grad[0]", g.span(), g0, &xy)?, self.pair("exact.grad[1]", g.span(), g1, &xy)?]
                    }
                    None => {
                        let d = |i: usize, var: &str| {
                            u[i].derivative(var).map_err(|m| {
                                self.error(
                                    &format!("exact.u[{i}]"),
                                    e.u.span(),
                                    format!("cannot differentiate it ({m}): give exact.grad = [[du1/dx, du1/dy], [du2/dx, du2/dy]]"),
                                )
                            })
                        };
                        [[d(0, "x")?, d(0, "y")?], [d(1, "x")?, d(1, "y")?]]
                    }
                };
                Some(ExactExprs { u, grad, grad_written: e.grad.is_some() })
            }
        })
    }
}

/// Whether a component is written `"free"` (not prescribed).
fn is_free(value: &Scalar) -> bool {
    matches!(value, Scalar::Text(t) if t.trim() == "free")
}

/// Why a Poisson ratio `nu` outside (-1, 0.5) is refused, whatever the `model`: E and nu
/// describe a 3-D material (plane strain is a long body of it, plane stress a thin plate), whose
/// bulk modulus E / (3 (1 - 2 nu)) is infinite at nu = 0.5 and negative beyond, and whose shear
/// modulus E / (2 (1 + nu)) is not positive at nu <= -1. (The plane-stress operator alone would
/// stay coercive up to nu < 1, but no material has such a ratio.)
fn poisson_ratio_refused(model: &str, nu: f64) -> String {
    let why = if nu >= 0.5 {
        "at 0.5 and beyond, the bulk modulus E / (3 (1 - 2 nu)) of the 3-D material E and nu describe is infinite or negative"
    } else {
        "at -1 and below, the shear modulus E / (2 (1 + nu)) is not positive"
    };
    format!("a Poisson ratio in (-1, 0.5) in {}, got {nu}: {why}", model.replace('_', " "))
}
