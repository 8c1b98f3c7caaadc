"""NGSolve side of the cross-check: mesh import, P2 assembly, Lagrange change of basis, PDAS.

NGSolve's order-2 H1 basis on triangles is hierarchical (vertex hats plus one edge bubble per
edge), so its coefficients are not the nodal values the contact constraint is written in. We
therefore assemble with NGSolve and transform to the Lagrange nodal basis, U -> coefficients
c = T U, and solve the contact problem for U with the matrix T^T K T and load T^T F. The bubble's
midpoint value that T needs is measured, not assumed, and T is verified by point evaluation.
"""
import json
import os
import time
from dataclasses import dataclass, field

import meshio
import numpy as np
import netgen.meshing as nm
import ngsolve as ng
from ngsolve import (BilinearForm, BitArray, EDGE, GridFunction, InnerProduct, LinearForm,
                     NodeId, Sym, Trace, VERTEX, VectorH1, ds, dx)

from problems import problem as make_problem

BOUNDARY_NAMES = {1: "dirichlet", 2: "neumann", 3: "contact"}
LOAD_BONUS_INTORDER = 10  # ex71's loads are exponentials: integrate them (nearly) exactly
SPLIT_POINTS = 12  # Gauss points per direction of split_load (fb's f across x = a)
INVERSE = "sparsecholesky"


@dataclass
class Case:
    """One exported case directory (see README.md for the format)."""
    path: str
    meta: dict
    points: np.ndarray  # (npts, 2): vertices first, then edge midpoints
    tris: np.ndarray  # (nt, 6): v0 v1 v2 m01 m12 m20
    lines: np.ndarray  # (nl, 3): a b mid
    parts: np.ndarray  # (nl,): 1 Dirichlet, 2 Neumann, 3 contact
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)  # per triangle (e.g. `indicator`), `part` excepted

    @property
    def n_vertices(self):
        return int(self.tris[:, :3].max()) + 1


def read_case(path):
    m = meshio.read(os.path.join(path, "mesh.vtu"))
    with open(os.path.join(path, "case.json")) as fh:
        meta = json.load(fh)
    tris = lines = None
    parts = None
    cell_data = {}
    for b, (block, part) in enumerate(zip(m.cells, m.cell_data["part"])):
        if block.type == "triangle6":
            tris = block.data
            cell_data = {k: _flat(v[b]) for k, v in m.cell_data.items() if k != "part"}
        elif block.type == "line3":
            lines, parts = block.data, np.asarray(part).reshape(-1)
        else:
            raise ValueError(f"{path}: unexpected cell type {block.type}")
    if tris is None or lines is None:
        raise ValueError(f"{path}: need a triangle6 and a line3 block")
    point_data = {k: _flat(v) for k, v in m.point_data.items()}
    case = Case(path, meta, np.asarray(m.points[:, :2], float), np.asarray(tris, np.int64),
                np.asarray(lines, np.int64), parts, point_data, cell_data)
    _check_layout(case)
    return case


def _flat(v):
    """Scalar arrays written with NumberOfComponents="1" come back as (n, 1): flatten them."""
    v = np.asarray(v)
    return v.reshape(-1) if v.ndim == 2 and v.shape[1] == 1 else v


def _check_layout(case):
    """The format's promises we rely on: vertices first, midpoints really at the midpoints, CCW."""
    nv = case.n_vertices
    if case.tris[:, 3:].min() < nv or case.lines[:, 2].min() < nv or case.lines[:, :2].max() >= nv:
        raise ValueError(f"{case.path}: vertices must come before edge midpoints")
    p = case.points
    for conn in (case.tris[:, [0, 1, 3]], case.tris[:, [1, 2, 4]], case.tris[:, [2, 0, 5]], case.lines):
        dev = np.abs(0.5 * (p[conn[:, 0]] + p[conn[:, 1]]) - p[conn[:, 2]]).max()
        if dev > 1e-9:
            raise ValueError(f"{case.path}: a midpoint node is off its edge's midpoint by {dev:g}")
    a, b, c = p[case.tris[:, 0]], p[case.tris[:, 1]], p[case.tris[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    if area2.min() <= 0:
        raise ValueError(f"{case.path}: triangles must be counter-clockwise and non-degenerate")
    if not set(np.unique(case.parts)) <= set(BOUNDARY_NAMES):
        raise ValueError(f"{case.path}: boundary parts must be in {sorted(BOUNDARY_NAMES)}")


def build_ngmesh(vertices, triangles, segments, seg_parts):
    """An NGSolve mesh with exactly these vertices (same numbering) and straight triangles.

    Boundary segments get the names of BOUNDARY_NAMES; only parts that occur are registered.
    """
    ngm = nm.Mesh(dim=2)
    ngm.AddPoints(np.column_stack([vertices, np.zeros(len(vertices))]).copy())
    fd = ngm.Add(nm.FaceDescriptor(surfnr=1, domin=1, bc=1))
    ngm.SetMaterial(1, "body")
    ngm.AddElements(dim=2, index=fd, data=np.ascontiguousarray(triangles, dtype=np.int32), base=0)
    for i, part in enumerate(sorted(BOUNDARY_NAMES)):
        sel = seg_parts == part
        # Segment index i+1 <-> boundary name number i (netgen numbers bc names from 0).
        ngm.SetBCName(i, BOUNDARY_NAMES[part])
        if sel.any():
            ngm.AddElements(dim=1, index=i + 1,
                            data=np.ascontiguousarray(segments[sel], dtype=np.int32), base=0)
    mesh = ng.Mesh(ngm)
    # AddPoints keeps the order, but check it: everything below indexes vertices by our numbers.
    coords = np.array([mesh[ng.NodeId(VERTEX, i)].point for i in range(mesh.nv)])
    if mesh.nv != len(vertices) or np.abs(coords - vertices).max() > 0:
        raise RuntimeError("NGSolve renumbered the mesh vertices")
    return mesh


def stiffness_form(fes, p, symmetric=False):
    """The elasticity form; `symmetric=True` stores the matrix as symmetric, which tells a solver
    that can exploit it (MKL PARDISO: LL^T / LDL^T instead of LU) that it may."""
    u, v = fes.TnT()
    eu, ev = Sym(ng.Grad(u)), Sym(ng.Grad(v))
    a = BilinearForm(fes, symmetric=symmetric)
    a += 2 * p.mu * InnerProduct(eu, ev) * dx + p.zeta * Trace(eu) * Trace(ev) * dx
    return a


def load_form(fes, p, skip=None):
    """f and g; f not on the elements of the BitArray `skip` (integrated by `split_load`)."""
    v = fes.TestFunction()
    lf = LinearForm(fes)
    if p.f is not None:
        if skip is None:
            lf += InnerProduct(p.f, v) * dx(bonus_intorder=LOAD_BONUS_INTORDER)
        else:
            keep = ~skip  # a new BitArray
            lf += InnerProduct(p.f, v) * dx(bonus_intorder=LOAD_BONUS_INTORDER, definedonelements=keep)
    if p.g is not None:
        lf += InnerProduct(p.g, v) * ds("neumann", bonus_intorder=LOAD_BONUS_INTORDER)
    return lf


def split_load(case, prob, mesh, n=SPLIT_POINTS):
    """The Lagrange-basis load of the triangles crossed by a line x = c of prob.load_breaks, where f
    is not smooth (fb: terms in ((x - a)_+)^(1/2), ^(3/2)); NGSolve's rules converge only
    algebraically there. Returns (element numbers, load vector in the U numbering).

    Iterated integral per triangle: the x-range is cut at the vertices' x and at c, so that the
    section [y_lo(x), y_hi(x)] is linear on each piece; Gauss in y; Gauss in x after the
    substitution x = c +- (x_r - x_l) s^2 on the two pieces next to c (the root becomes smooth in s).
    The P2 Lagrange basis from barycentric coordinates: l_i (2 l_i - 1) at vertices, 4 l_i l_j at
    the midpoint of edge ij (node order v0 v1 v2 m01 m12 m20)."""
    gs, gw = np.polynomial.legendre.leggauss(n)
    gs, gw = 0.5 * (gs + 1), 0.5 * gw
    npts = len(case.points)
    elems, pts, wts, owner = [], [], [], []
    for e, tri in enumerate(case.tris):
        V = case.points[tri[:3]]
        cs = [c for c in prob.load_breaks if V[:, 0].min() < c < V[:, 0].max()]
        if not cs:
            continue
        c = cs[0]
        elems.append(e)
        xs = np.unique(np.r_[V[:, 0], c])
        for xl, xr in zip(xs[:-1], xs[1:]):
            for s, ws in zip(gs, gw):
                if xl == c:
                    x, jac = xl + (xr - xl) * s * s, 2 * (xr - xl) * s
                elif xr == c:
                    x, jac = xr - (xr - xl) * s * s, 2 * (xr - xl) * s
                else:
                    x, jac = xl + (xr - xl) * s, xr - xl
                ys = [p[1] + (x - p[0]) / (q[0] - p[0]) * (q[1] - p[1])
                      for p, q in ((V[0], V[1]), (V[1], V[2]), (V[2], V[0])) if (p[0] - x) * (q[0] - x) < 0]
                lo, hi = min(ys), max(ys)
                for t, wt in zip(gs, gw):
                    pts.append((x, lo + (hi - lo) * t))
                    wts.append(ws * jac * wt * (hi - lo))
                    owner.append(e)
    F = np.zeros(2 * npts)
    if not elems:
        return elems, F
    pts, wts, owner = np.array(pts), np.array(wts), np.array(owner)
    fx = eval_points(mesh, prob.f, pts)  # (m, 2)
    tris = case.tris[owner]
    V = case.points[tris[:, :3]]  # (m, 3, 2)
    # barycentric coordinates of each point in its triangle
    d = V[:, 1:] - V[:, :1]  # (m, 2, 2): rows b - a, c - a
    det = d[:, 0, 0] * d[:, 1, 1] - d[:, 0, 1] * d[:, 1, 0]
    r = pts - V[:, 0]
    l1 = (r[:, 0] * d[:, 1, 1] - r[:, 1] * d[:, 1, 0]) / det
    l2 = (d[:, 0, 0] * r[:, 1] - d[:, 0, 1] * r[:, 0]) / det
    lam = np.stack([1 - l1 - l2, l1, l2], axis=1)
    phi = np.concatenate([lam * (2 * lam - 1), 4 * lam[:, [0, 1, 2]] * lam[:, [1, 2, 0]]], axis=1)  # (m, 6)
    for k in range(2):
        np.add.at(F, k * npts + tris, (wts * fx[:, k])[:, None] * phi)
    return elems, F


def eval_points(mesh, cf, pts):
    """Evaluate a coefficient function at points (n, 2); returns (n, dim)."""
    mips = mesh(pts[:, 0], pts[:, 1])
    return np.asarray(cf(mips)).reshape(len(pts), -1)


class Discretisation:
    """P2 elasticity on a Case's mesh, in the Lagrange nodal basis of the case's P2 nodes.

    Unknown numbering: U[k * npts + p] is component k at node p (node numbering of mesh.vtu).
    """

    def __init__(self, case, prob, assemble=True):
        """assemble=False: the mesh, the space and the change of basis only (no K, no F)."""
        self.case, self.prob = case, prob
        nv, npts = case.n_vertices, len(case.points)
        self.npts = npts
        # (a, b) with a < b -> the node at the midpoint of edge ab, from the triangles' edge lists
        self.midpoint = {}
        for t in case.tris:
            for (i, j, m) in ((0, 1, 3), (1, 2, 4), (2, 0, 5)):
                self.midpoint[tuple(sorted((int(t[i]), int(t[j]))))] = int(t[m])
        self.mesh = build_ngmesh(case.points[:nv], case.tris[:, :3], case.lines[:, :2], case.parts)
        self.fes = VectorH1(self.mesh, order=2, dirichlet="dirichlet")
        self._build_basis_change()
        self._classify_nodes()
        if assemble:
            self._assemble(case, prob)

    def _assemble(self, case, prob):
        a = stiffness_form(self.fes, prob).Assemble()
        # f on triangles crossed by a line where it is not smooth: our own rule (split_load)
        split, F_split = split_load(case, prob, self.mesh) if prob.f is not None else ([], 0.0)
        skip = None
        if split:
            skip = BitArray(self.mesh.ne)
            skip.Clear()
            for e in split:
                if sorted(v.nr for v in self.mesh[ng.ElementId(ng.VOL, e)].vertices) != sorted(case.tris[e, :3]):
                    raise RuntimeError("NGSolve element numbers differ from the case's triangles")
                skip.Set(e)
        f = load_form(self.fes, prob, skip).Assemble()
        T, Tt = self.T, self.T.CreateTranspose()
        self.K = Tt @ a.mat @ T  # Lagrange-basis stiffness (a SparseMatrixd)
        self.F = (Tt * f.vec).Evaluate().FV().NumPy().copy() + F_split
        self.split_elements = len(split)

    # -- change of basis ---------------------------------------------------------------------
    def _build_basis_change(self):
        case, mesh, fes = self.case, self.mesh, self.fes
        npts, nv = self.npts, case.n_vertices
        # midpoint node -> (a, b, NGSolve edge number)
        mid = {}
        for e in mesh.edges:
            a, b = sorted(v.nr for v in e.vertices)
            mid[self.midpoint[(a, b)]] = (a, b, e.nr)
        if sorted(mid) != list(range(nv, npts)) or len(mid) != mesh.nedge:
            raise ValueError(f"{case.path}: P2 nodes do not match the mesh's vertices and edges")
        mids = np.arange(nv, npts)
        ends = np.array([mid[m][:2] for m in mids])
        edges = np.array([mid[m][2] for m in mids])

        # The edge bubble's value at its midpoint, measured on the scalar space: with all edge
        # coefficients 1 and vertex coefficients 0, at a midpoint only that edge's bubble is
        # nonzero (the others vanish on edges not their own; T's check below confirms this).
        scal = ng.H1(mesh, order=2)
        gf = GridFunction(scal)
        gf.vec[:] = 0
        for e in range(mesh.nedge):
            (d,) = scal.GetDofNrs(NodeId(EDGE, e))
            gf.vec[d] = 1.0
        beta = eval_points(mesh, gf, case.points[mids])[:, 0]
        if np.abs(beta).min() < 1e-3:
            raise RuntimeError("edge bubble vanishes at a midpoint?")
        self.bubble_midpoint_values = (float(beta.min()), float(beta.max()))

        rows, cols, vals = [], [], []
        for k in range(2):
            for v in range(nv):
                rows.append(fes.GetDofNrs(NodeId(VERTEX, v))[k])
                cols.append(k * npts + v)
                vals.append(1.0)
            for m, (a, b), e, bt in zip(mids, ends, edges, beta):
                d = fes.GetDofNrs(NodeId(EDGE, int(e)))[k]
                rows += [d, d, d]
                cols += [k * npts + m, k * npts + a, k * npts + b]
                vals += [1 / bt, -0.5 / bt, -0.5 / bt]
        self.T = ng.la.SparseMatrixd.CreateFromCOO(rows, cols, vals, fes.ndof, 2 * npts)
        if fes.ndof != 2 * npts:
            raise RuntimeError("P2 space dimension differs from 2 x number of P2 nodes")

        # Verify T: random nodal values -> coefficients -> point evaluation at every node.
        rng = np.random.default_rng(1)
        U = rng.standard_normal(2 * npts)
        back = self.point_values(U)
        self.basis_change_error = float(np.abs(back - U.reshape(2, npts).T).max() / np.abs(U).max())
        if self.basis_change_error > 1e-11:
            raise RuntimeError(f"Lagrange change of basis is wrong: error {self.basis_change_error:g}")

    def gridfunction(self, U):
        gf = GridFunction(self.fes)
        tmp = self.T.CreateColVector()
        tmp.FV().NumPy()[:] = U
        gf.vec.data = self.T * tmp
        return gf

    def point_values(self, U, pts=None):
        """NGSolve point evaluation of the P2 function with nodal values U; (n, 2)."""
        return eval_points(self.mesh, self.gridfunction(U), self.case.points if pts is None else pts)

    # -- node classes --------------------------------------------------------------------------
    def _classify_nodes(self):
        case, npts = self.case, self.npts
        dirichlet = np.zeros(npts, bool)
        dirichlet[case.lines[case.parts == 1].ravel()] = True
        contact = np.zeros(npts, bool)
        contact[case.lines[case.parts == 3].ravel()] = True
        contact &= ~dirichlet  # nodes on the closure of Gamma_D are Dirichlet nodes
        self.dirichlet, self.contact_nodes = dirichlet, np.flatnonzero(contact)

        # Cross-check our Dirichlet node set with NGSolve's own (dirichlet="dirichlet").
        free = self.fes.FreeDofs()
        ng_fixed = np.zeros(npts, bool)
        for v in range(case.n_vertices):
            ng_fixed[v] = not free[self.fes.GetDofNrs(NodeId(VERTEX, v))[0]]
        for e in self.mesh.edges:
            a, b = sorted(v.nr for v in e.vertices)
            ng_fixed[self.midpoint[(a, b)]] = not free[self.fes.GetDofNrs(NodeId(EDGE, e.nr))[0]]
        if not np.array_equal(ng_fixed, dirichlet):
            raise RuntimeError("our Dirichlet nodes differ from NGSolve's Dirichlet dofs")

        pts = case.points[self.contact_nodes]
        self.chi = np.asarray(self.prob.chi(pts[:, 0], pts[:, 1]), float)

    # -- solving -----------------------------------------------------------------------------
    def solve_fixed(self, fixed_mask, fixed_values):
        """Solve K U = F for the entries not in fixed_mask, with U = fixed_values on fixed_mask."""
        U = np.where(fixed_mask, fixed_values, 0.0)
        vec = self.K.CreateColVector()
        vec.FV().NumPy()[:] = self.F - self._apply(U)
        inv = self.K.Inverse(freedofs=BitArray(list(~fixed_mask)), inverse=INVERSE)
        sol = (inv * vec).Evaluate()
        U[~fixed_mask] += sol.FV().NumPy()[~fixed_mask]
        return U

    def _apply(self, U):
        vec = self.K.CreateColVector()
        vec.FV().NumPy()[:] = U
        return (self.K * vec).Evaluate().FV().NumPy().copy()

    def residual(self, U):
        return self.F - self._apply(U)

    def pdas(self, c_scale=1.0, max_iter=100, start=None):
        """Primal-dual active set method (Hueber-Mair-Wohlmuth) on the nodal constraints
        sign * U[k, p] <= chi(p), p a contact node. Returns a dict with U, lambda, active, its.

        lambda_p = L(phi_p n) - a(u_h, phi_p n) = sign * residual[k, p]; c is scaled to the
        stiffness diagonal at the constrained entries so both terms of the criterion are forces.
        """
        npts, prob = self.npts, self.prob
        k, sign = prob.normal_component
        cdofs = k * npts + self.contact_nodes
        fixed_base = np.zeros(2 * npts, bool)
        values = np.zeros(2 * npts)
        # Dirichlet values at the Dirichlet nodes: a constant, or a coefficient function evaluated there
        if isinstance(prob.u_dirichlet, ng.CoefficientFunction):
            ud = eval_points(self.mesh, prob.u_dirichlet, self.case.points[self.dirichlet])
        else:
            ud = np.tile(np.asarray(prob.u_dirichlet, float), (int(self.dirichlet.sum()), 1))
        for comp in range(2):
            fixed_base[comp * npts:(comp + 1) * npts] = self.dirichlet
            values[comp * npts:(comp + 1) * npts][self.dirichlet] = ud[:, comp]
        values[cdofs] = sign * self.chi
        diag = self._diagonal()
        c = c_scale * float(np.mean(diag[cdofs]))

        active = np.zeros(len(cdofs), bool) if start is None else np.asarray(start, bool).copy()
        seen = []
        for it in range(1, max_iter + 1):
            fixed = fixed_base.copy()
            fixed[cdofs[active]] = True
            U = self.solve_fixed(fixed, values)
            lam = sign * self.residual(U)[cdofs]
            lam[~active] = 0.0  # exactly zero there up to round-off; don't let round-off vote
            gap = sign * U[cdofs] - self.chi
            new_active = lam + c * gap > 0
            if np.array_equal(new_active, active):
                break
            if any(np.array_equal(new_active, s) for s in seen):
                raise RuntimeError("PDAS cycles")
            seen.append(active)
            active = new_active
        else:
            raise RuntimeError("PDAS did not converge")
        lam_full = sign * self.residual(U)[cdofs]
        return {
            "U": U, "active": active, "lambda": lam_full, "iterations": it,
            "kkt": {
                "max_penetration": float(max(0.0, np.max(gap, initial=0.0))),
                "min_lambda": float(np.min(lam_full, initial=0.0)),
                "max_complementarity": float(np.max(np.abs(lam_full * gap), initial=0.0)),
            },
        }

    def _diagonal(self):
        rows, cols, vals = self.K.COO()
        rows, cols, vals = np.array(rows), np.array(cols), np.array(vals)
        d = np.zeros(self.K.height)
        on = rows == cols
        np.add.at(d, rows[on], vals[on])
        return d

    # -- errors (problems with an exact solution) ----------------------------------------------
    def errors(self, U, lattice=6):
        """L-infinity errors, |u - u_h| measured as the larger component (crates/numerics/src/contact/norms.rs convention):
        nodal = max over P2 nodes; dense = max over a barycentric lattice with `lattice`
        subdivisions per triangle (order 6 = 28 points, as LATTICE_ORDER in crates/model/src/settings/sampling.rs),
        evaluated element by element through NGSolve."""
        exact = self.prob.exact
        ue = eval_points(self.mesh, exact, self.case.points)
        nodal = float(np.abs(U.reshape(2, self.npts).T - ue).max())
        pts = [(i / lattice, j / lattice) for i in range(lattice + 1) for j in range(lattice + 1 - i)]
        ir = ng.IntegrationRule(pts, [0.0] * len(pts))
        err = self.gridfunction(U) - exact
        vals = np.asarray(err(self.mesh.MapToAllElements(ir, ng.VOL)))
        return {"linf_nodal": nodal, "linf_dense": float(np.abs(vals).max())}


# Cases with more unknowns than this start NGSolve's PDAS from the exported active set (see
# solve_case); smaller ones from the empty set.
WARM_START_NDOF = 100_000


def solve_case(case, perturb=None):
    """Assemble and solve a case's problem with NGSolve; returns (Discretisation, result, seconds).

    A case above WARM_START_NDOF (the Example 7.2 reference, 250k unknowns) starts the PDAS from
    the active set the Rust solver exported rather than from the empty set: a dozen sparse
    factorisations of 250k unknowns on one thread (45 s) become one or two. What is checked
    stays a certificate: the PDAS stops only at its fixed point, where NGSolve's own solution
    satisfies NGSolve's own discrete KKT conditions, and the discrete Signorini problem has one
    solution, so agreement with it is agreement with THE solution. The smaller cases start from
    the empty set, so NGSolve's own path to the active set is still exercised on 17 cases.
    """
    t0 = time.perf_counter()
    disc = Discretisation(case, make_problem(case.meta["problem"], perturb))
    start = None
    if 2 * disc.npts > WARM_START_NDOF:
        start = np.asarray(case.point_data["active"])[disc.contact_nodes] != 0
    res = disc.pdas(start=start)
    return disc, res, time.perf_counter() - t0
