"""The a posteriori estimator of the paper (Section 6, eq. 6.3), evaluated on NGSolve's side from an
exported case's mesh and u_h: a second implementation of crates/numerics/src/estimator/, written from the paper's
formulas and the Rust code's declared choices (README.md, "The estimator"), sharing no code with it.

Per P2 node p, with Omega_p the elements containing p and h_p the diameter of Omega_p:

    eta_{1,p} = h_p^2 ||f + div sigma(u_h)||_Linf(Omega_p)
    eta_{2,p} = h_p   ||[sigma(u_h)] n||_Linf(Gamma_{p,I})     Gamma_{p,I}: the interior edges through p
    eta_{3,p} = h_p   ||g - sigma(u_h) n||_Linf(Gamma_{p,N})   p a Neumann node (and the traction of
                                                              components Gamma_D leaves free, p a Dirichlet node)
    eta_{4,p} = h_p   ||t . sigma(u_h) n||_Linf(Gamma_{p,C})   p a contact node
    eta_{5,p} = h_p   ||n . sigma(u_h) n||_Linf(Gamma_{p,C})   p a contact node (contact_term: see below)
    eta_i = max_p eta_{i,p} (i = 1..5),  Psi = eta_1 + ... + eta_5,  l_h = 1 + |log h_min|^2,
    eta_6 = ||(u_h.n - chi)^+||_Linf(Gamma_C),  eta_7 = ||(chi - u_h.n)^+||_Linf(Lambda_h^C),
    eta_h = l_h Psi + eta_6 + eta_7 (eq. 6.3),  estimate = C_0 eta_h.

sigma(u_h), div sigma(u_h) (from the Hessians of the components) and u_h are NGSolve's evaluations
of a GridFunction holding u_h, element by element; each edge's values come from the elements on
both of its sides. Norms are maxima over the declared sampling points.
"""
import math

import numpy as np
import ngsolve as ng
from ngsolve import CF, Grad, VOL, x, y

import fem
import problems

# Lambda_h^C takes the contact nodes whose force lambda_p is above its own round-off bound
# (`lambda_floor`, exported) and above this fraction of the largest contact force.
LAMBDA_POSITIVE = 1e-10
CONTACT_TERMS = ("as_written", "without_full_contact", "tensile_on_full_contact")
PART_DIRICHLET, PART_NEUMANN, PART_CONTACT = 1, 2, 3
# Which part a node at the junction of two parts belongs to: the closure of Gamma_D first, then
# Gamma_C, then Gamma_N.
PART_RANK = {PART_DIRICHLET: 3, PART_CONTACT: 2, PART_NEUMANN: 1}
LOCAL_EDGES = ((0, 1), (1, 2), (2, 0))  # local edge le joins vertices LOCAL_EDGES[le]; midpoint 3 + le


def element_points():
    """Barycentric points of Radon's symmetric 7-point degree-5 rule: the centroid and the orbits of
    (a, a, 1 - 2a), a = (6 -+ sqrt 15) / 21. Symmetric, so the mapped set does not depend on which
    vertex NGSolve's reference element puts first."""
    r = math.sqrt(15.0)
    pts = [(1 / 3, 1 / 3, 1 / 3)]
    for a in ((6 - r) / 21, (6 + r) / 21):
        b = 1 - 2 * a
        pts += [(a, a, b), (b, a, a), (a, b, a)]
    return np.array(pts)


def edge_parameters():
    """The 3 Gauss-Legendre points on [0, 1] (symmetric about 1/2)."""
    g = np.polynomial.legendre.leggauss(3)[0]
    return np.sort(0.5 * (g + 1))


class Evaluator:
    """One case's mesh on NGSolve's side, and the estimator of any u_h on it (`terms`)."""

    def __init__(self, case, prob):
        self.case, self.prob = case, prob
        cfg = case.meta.get("estimator_config", {})
        if cfg.get("sampling", "quadrature") != "quadrature" or cfg.get("stress_frame", "normal") != "normal":
            raise ValueError(f"{case.path}: only the quadrature sampling and the normal stress frame are implemented")
        self.disc = fem.Discretisation(case, prob, assemble=False)
        self.mesh = self.disc.mesh
        tris, pts = case.tris, case.points
        nt, self.npts = len(tris), len(pts)
        ngv = np.array([sorted(v.nr for v in el.vertices) for el in self.mesh.Elements(VOL)])
        if not np.array_equal(ngv, np.sort(tris[:, :3], axis=1)):
            raise RuntimeError("NGSolve element numbers differ from the case's triangles")

        # the sampling points in NGSolve's reference triangle (its vertices (1,0), (0,1), (0,0)):
        # element points, then the Gauss points on each of the three edges; the set is symmetric
        # under the vertices' permutations, so each mapped point is matched to our edges by position
        s = edge_parameters()
        bary = [tuple(b) for b in element_points()]
        for i, j in ((0, 1), (1, 2), (2, 0)):
            for sk in s:
                b = [0.0, 0.0, 0.0]
                b[i], b[j] = 1 - sk, sk
                bary.append(tuple(b))
        self.n_el = 7
        ir = ng.IntegrationRule([(b[0], b[1]) for b in bary], [0.0] * len(bary))
        self.mips = self.mesh.MapToAllElements(ir, VOL)
        nq = len(bary)
        self.nq = nq
        X = np.asarray(CF((x, y))(self.mips)).reshape(nt, nq, 2)
        self.X = X  # the sampling points, as NGSolve maps them
        # per element and local edge: the indices (into the nq points) of its Gauss points in the
        # order of increasing parameter from the edge's lower-numbered end
        Xe = X[:, self.n_el:]  # (nt, 9, 2)
        order = np.zeros((nt, 3, len(s)), np.int64)
        h = np.zeros(nt)
        for le, (i, j) in enumerate(LOCAL_EDGES):
            lo = np.minimum(tris[:, i], tris[:, j])
            hi = np.maximum(tris[:, i], tris[:, j])
            a, b = pts[lo], pts[hi]
            d = b - a
            L2 = np.einsum("ij,ij->i", d, d)
            h = np.maximum(h, np.sqrt(L2))
            r = Xe - a[:, None, :]
            par = np.einsum("ikj,ij->ik", r, d) / L2[:, None]
            off = np.abs(r[:, :, 0] * d[:, None, 1] - r[:, :, 1] * d[:, None, 0]) / L2[:, None]
            for k, sk in enumerate(s):
                hit = (off < 1e-9) & (np.abs(par - sk) < 1e-9)
                if not np.all(hit.sum(axis=1) == 1):
                    raise RuntimeError("an edge's Gauss points were not found among the mapped points")
                order[:, le, k] = self.n_el + np.argmax(hit, axis=1)
        self.edge_idx = order
        self.h_T = h  # element diameters (longest edge)
        self._topology()

    # -- mesh topology ---------------------------------------------------------------------------
    def _topology(self):
        case, tris, npts = self.case, self.case.tris, self.npts
        nt = len(tris)
        # boundary line of each (element, local edge), by the edge's midpoint node
        line_of_mid = {int(m): k for k, m in enumerate(case.lines[:, 2])}
        self.elem_line = np.array([[line_of_mid.get(int(t[3 + le]), -1) for le in range(3)] for t in tris])
        # the two elements of every edge (by midpoint node)
        owners = {}
        for t in range(nt):
            for le in range(3):
                owners.setdefault(int(tris[t, 3 + le]), []).append((t, le))
        inner = [(m, *o[0], *o[1]) for m, o in owners.items() if len(o) == 2]
        self.interior = np.array(inner, np.int64).reshape(-1, 5)  # midpoint, t1, le1, t2, le2
        # node part: the highest-ranked part of the boundary lines through the node
        part = np.zeros(npts, np.int64)
        for line, pr in zip(case.lines, case.parts):
            for q in line:
                if part[q] == 0 or PART_RANK[int(pr)] > PART_RANK[int(part[q])]:
                    part[q] = int(pr)
        self.part = part
        # node -> elements (CSR) and h_p, the diameter of the patch's vertices
        counts = np.bincount(tris.ravel(), minlength=npts)
        self.start = np.r_[0, np.cumsum(counts)]
        order = np.argsort(tris.ravel(), kind="stable")
        self.patch = order // 6
        P = case.points
        hp = np.zeros(npts)
        for p in range(npts):
            verts = np.unique(tris[self.patch[self.start[p]:self.start[p + 1]], :3])
            V = P[verts]
            d = V[:, None, :] - V[None, :, :]
            hp[p] = np.sqrt(np.einsum("ijk,ijk->ij", d, d).max())
        self.h_p = hp
        # outward unit normal of every boundary line (away from its element's third vertex)
        a, b = P[case.lines[:, 0]], P[case.lines[:, 1]]
        d = b - a
        n = np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
        own = {}
        for t in range(nt):
            for le in range(3):
                if self.elem_line[t, le] >= 0:
                    own[self.elem_line[t, le]] = (t, le)
        self.line_owner = np.array([own[k] for k in range(len(case.lines))])
        third = P[tris[self.line_owner[:, 0], (self.line_owner[:, 1] + 2) % 3]]
        flip = np.einsum("ij,ij->i", third - a, n) > 0
        n[flip] *= -1
        self.line_normal = n

    # -- the estimator -----------------------------------------------------------------------------
    def locals(self, U):
        """Per element and edge: the maxima over the sampling points of what the terms take."""
        case, prob, tris = self.case, self.prob, self.case.tris
        nt, nq = len(tris), self.nq
        gf = self.disc.gridfunction(np.concatenate([U[:, 0], U[:, 1]]))
        mu, zeta = prob.mu, prob.zeta
        sig = np.asarray(problems.stress(prob, Grad(gf))(self.mips)).reshape(nt, nq, 2, 2)
        H = [np.asarray(gf.components[k].Operator("hesse")(self.mips)).reshape(nt, nq, 2, 2) for k in range(2)]
        # div sigma = (sum_j d_j sigma_ij)_i, sigma_ij = mu (d_j u_i + d_i u_j) + zeta delta_ij div u
        div = np.stack([mu * (H[i][..., 0, 0] + H[i][..., 1, 1]) + (mu + zeta) * (H[0][..., i, 0] + H[1][..., i, 1])
                        for i in range(2)], axis=-1)  # (nt, nq, 2)
        uh = np.asarray(gf(self.mips)).reshape(nt, nq, 2)
        f = np.zeros((nt, nq, 2)) if prob.f is None else np.asarray(prob.f(self.mips)).reshape(nt, nq, 2)
        residual = np.abs(f[:, :self.n_el] + div[:, :self.n_el]).max(axis=(1, 2))

        # interior edges: |[sigma] n| at the Gauss points, both sides at the same points
        jump = np.zeros(self.npts)
        P = case.points
        m, t1, l1, t2, l2 = self.interior.T
        ends = np.array(LOCAL_EDGES)
        d = P[tris[t1, ends[l1, 1]]] - P[tris[t1, ends[l1, 0]]]
        n = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
        s1 = np.einsum("ekij,ej->eki", sig[t1[:, None], self.edge_idx[t1, l1]], n)  # (edges, 3, 2)
        s2 = np.einsum("ekij,ej->eki", sig[t2[:, None], self.edge_idx[t2, l2]], n)
        jump[m] = np.abs(s1 - s2).max(axis=(1, 2))

        # boundary edges, from the element that owns them
        nl = len(case.lines)
        neumann, tangential, normal, tensile = (np.zeros(nl) for _ in range(4))
        penetration, separation = np.zeros(nl), np.zeros(nl)
        g = None if prob.g is None else np.asarray(prob.g(self.mips)).reshape(nt, nq, 2)
        nc = np.asarray(prob.normal, float)
        tc = np.array([-nc[1], nc[0]])
        for k, (t, le) in enumerate(self.line_owner):
            idx = self.edge_idx[t, le]
            tr = sig[t, idx] @ self.line_normal[k]  # (3, 2)
            part = case.parts[k]
            if part == PART_NEUMANN:
                gk = np.zeros_like(tr) if g is None else g[t, idx]
                neumann[k] = np.abs(gk - tr).max()
            elif part == PART_CONTACT:
                s_n, s_t = tr @ nc, tr @ tc
                normal[k], tangential[k] = np.abs(s_n).max(), np.abs(s_t).max()
                tensile[k] = max(0.0, s_n.max())
                Xk = self.X[t, idx]
                gap = np.asarray(prob.chi(Xk[:, 0], Xk[:, 1]), float) - uh[t, idx] @ nc
                penetration[k] = max(0.0, (-gap).max())
                separation[k] = max(0.0, gap.max())
            elif prob.free:
                # Gamma_D: a component the Dirichlet data leave free carries zero traction (rollers),
                # so its traction is a Neumann residual, taken by eta_3 at Dirichlet nodes
                neumann[k] = np.abs(tr[:, list(prob.free)]).max()
        return {"residual": residual, "jump": jump, "neumann": neumann, "tangential": tangential,
                "normal": normal, "tensile": tensile, "penetration": penetration, "separation": separation}

    def terms(self, U, lam, floor, active, contact, contact_term, c0, loc=None):
        """eta_1..eta_7, l_h, Psi, eta_h, the estimate, eta_{i,p} per node and eta_T per element
        (and `locals`, which another variant of the same u_h may be given as loc)."""
        if contact_term not in CONTACT_TERMS:
            raise ValueError(f"unknown contact_term {contact_term!r}")
        loc = self.locals(U) if loc is None else loc
        case, tris, npts = self.case, self.case.tris, self.npts
        lines, parts = case.lines, case.parts
        active, contact = np.asarray(active) != 0, np.asarray(contact) != 0

        # Lambda_h^C: contact nodes with positive discrete contact force (Theorem 6.1)
        largest = max(0.0, float(np.max(lam[contact], initial=0.0)))
        positive = contact & (lam > np.maximum(floor, LAMBDA_POSITIVE * largest))
        is_contact_line = parts == PART_CONTACT
        full_line = is_contact_line & active[lines].all(axis=1)
        if contact_term == "tensile_on_full_contact":
            on_full = np.zeros(npts, bool)
            on_full[lines[full_line].ravel()] = True
            isolated = positive & ~on_full
            lam_line = is_contact_line & (full_line | isolated[lines].any(axis=1))
        else:
            lam_line = None

        e = np.zeros((npts, 5))
        np.maximum.at(e[:, 0], tris.ravel(), np.repeat(loc["residual"], 6))
        # eta_2: a midpoint takes its own edge, a vertex every edge through it
        mids = tris[:, 3:]
        e[:, 1] = np.maximum(e[:, 1], np.where(np.arange(npts) >= case.n_vertices, loc["jump"], 0.0))
        for le, (i, j) in enumerate(LOCAL_EDGES):
            np.maximum.at(e[:, 1], tris[:, i], loc["jump"][mids[:, le]])
            np.maximum.at(e[:, 1], tris[:, j], loc["jump"][mids[:, le]])
        has_contact = np.zeros(npts, bool)
        all_active = np.ones(npts, bool)
        tens = np.zeros(npts)
        pen, sep = np.zeros(npts), np.zeros(npts)
        # the boundary edges of each node's patch (the patch's elements' edges on Gamma_N, Gamma_C)
        for k, (t, le) in enumerate(self.line_owner):
            for p in tris[t]:
                if parts[k] == self.part[p] in (PART_NEUMANN, PART_DIRICHLET):
                    e[p, 2] = max(e[p, 2], loc["neumann"][k])
                elif parts[k] == PART_CONTACT and self.part[p] == PART_CONTACT:
                    has_contact[p] = True
                    e[p, 3] = max(e[p, 3], loc["tangential"][k])
                    e[p, 4] = max(e[p, 4], loc["normal"][k])
                    tens[p] = max(tens[p], loc["tensile"][k])
                    all_active[p] &= bool(full_line[k])
                    pen[p] = max(pen[p], loc["penetration"][k])
                    if (positive[p] if lam_line is None else lam_line[k]):
                        sep[p] = max(sep[p], loc["separation"][k])
        full = has_contact & all_active  # N_h^FC: u_h.n = chi_h on all of Gamma_{p,C}
        if contact_term == "without_full_contact":
            e[full, 4] = 0.0
        elif contact_term == "tensile_on_full_contact":
            e[full, 4] = tens[full]
        hp = self.h_p
        scaled = e * np.column_stack([hp * hp, hp, hp, hp, hp])
        h_min = self.h_T.min()
        l_h = 1 + math.log(h_min) ** 2
        eta = scaled.max(axis=0)
        out = {f"eta{i + 1}": float(eta[i]) for i in range(5)}
        out["eta6"], out["eta7"] = float(pen.max(initial=0.0)), float(sep.max(initial=0.0))
        out["l_h"] = l_h
        out["psi"] = float(sum(eta))
        out["eta_h"] = l_h * out["psi"] + out["eta6"] + out["eta7"]
        out["c0"] = c0
        out["estimate"] = c0 * out["eta_h"]
        # eta_T: the largest l_h (eta_{1,p} + ... + eta_{5,p}) over T's six nodes, plus eta_6 and
        # eta_7 on T's contact edges (eta_7 where Lambda_h^C takes the edge: one of T's nodes with
        # positive force, or the narrower edge set of the repaired variant)
        node_sum = l_h * scaled.sum(axis=1)
        eta_T = node_sum[tris].max(axis=1)
        contact_part = np.zeros(len(tris))
        for k, (t, le) in enumerate(self.line_owner):
            if parts[k] == PART_CONTACT:
                takes = positive[tris[t]].any() if lam_line is None else lam_line[k]
                contact_part[t] = max(contact_part[t], loc["penetration"][k] + (loc["separation"][k] if takes else 0.0))
        out["eta_T"] = eta_T + contact_part
        out["eta_p"] = scaled
        out["full_contact_nodes"] = int(full.sum())
        out["locals"] = loc
        return out
