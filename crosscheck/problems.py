"""Problem data of Examples 7.1 and 7.2, transcribed from the paper's Section 7, of the
free-boundary problem `fb` (beyond the paper), transcribed from its definition (the doc comment of `Fb` in crates/model/src/problems/builtin.rs),
and of Hertz contact `hertz` and Example 7.2 on rollers `ex72_rollers` (beyond the paper), transcribed
from experiments/problems/hertz.toml and ex72_rollers.toml.

Written independently of the Rust code on purpose: the cross-check is only worth something if the
data enter twice, once on each side. `check_data` verifies the transcribed f, g and contact stresses
of ex71 and fb against NGSolve's symbolic derivatives of the exact solution, so a typo here cannot
hide.
"""
from dataclasses import dataclass, replace

import numpy as np
from ngsolve import CF, IfPos, cos, exp, sin, sqrt, x, y

# Relative size of the deliberate data perturbation used by `crosscheck.py selftest`.
PERTURBATION = 1e-6


@dataclass
class Problem:
    name: str
    mu: float
    zeta: float  # Lame's lambda; called zeta as in the paper to keep lambda for the contact force
    f: CF | None  # volume load (None: zero)
    g: CF | None  # traction on the "neumann" boundary (None: zero)
    u_dirichlet: object  # Dirichlet value on the "dirichlet" boundary: a constant tuple or a CF
    normal: tuple  # outward unit normal of the (straight, axis-parallel) contact boundary
    chi: object  # gap function: numpy (x, y) -> array
    exact: CF | None  # exact displacement, if known
    load_breaks: tuple = ()  # lines x = c across which f is not smooth (fem.split_load integrates there)
    free: tuple = ()  # components the Dirichlet data leave free on Gamma_D (zero traction there: rollers)

    @property
    def normal_component(self):
        """Index and sign such that u . n = sign * u[index] (the contact normals are axis-parallel)."""
        k = int(np.argmax(np.abs(self.normal)))
        return k, float(np.sign(self.normal[k]))


def ex71_exact():
    return CF((y**2 * (y - 1), exp(y) * (1 - y) * y * (x - 2)))


def ex71_f():
    return CF((2 * exp(y) * (y**2 + y - 1) - 6 * y + 2, 3 * y * (x - 2) * (y + 3) * exp(y)))


def ex71_g():
    """sigma(u) n on the sides; the Neumann boundary is x = 0 (n = (-1,0)) and x = 1 (n = (1,0))."""
    g_left = CF((2 * (1 - y - y**2) * exp(y), y * (2 - 3 * y + (y - 1) * exp(y))))
    g_right = CF(((y**2 + y - 1) * exp(y), y * (3 * y - 2 - (y - 1) * exp(y))))
    return IfPos(x - 0.5, g_right, g_left)


# -- fb: free boundary with an exact solution (beyond the paper) ---------------------------------
# zeta = mu = 1, Gamma_C = bottom (n = (0,-1)), Gamma_D = top, Gamma_N = sides;
# a = sqrt(2) - 1, r = 0.05 sin(2 pi x), p = -((x - a)_+)^(5/2),
# u = (-y r', y p / 3 + r), chi = -r + ((a - x)_+)^(3/2); contact exactly on [a, 1].
FB_A = np.sqrt(2.0) - 1.0
_K = 2 * np.pi


def fb_r():
    """r and its first three derivatives as coefficient functions."""
    return (0.05 * sin(_K * x), 0.05 * _K * cos(_K * x), -0.05 * _K**2 * sin(_K * x), -0.05 * _K**3 * cos(_K * x))


def fb_p():
    """p and its first two derivatives; zero left of a (IfPos picks the branch: the square root of
    a negative number is never used)."""
    s = x - FB_A
    return (-IfPos(s, s * s * sqrt(s), 0), -IfPos(s, 2.5 * s * sqrt(s), 0), -IfPos(s, 3.75 * sqrt(s), 0))


def fb_exact():
    r, p = fb_r(), fb_p()
    return CF((-y * r[1], y * p[0] / 3 + r[0]))


def fb_f():
    """-div sigma(u) for zeta = mu = 1, written out by hand: (3 y r3 - 2 p1 / 3, r2 - y p2 / 3),
    rk and pk the k-th derivatives."""
    r, p = fb_r(), fb_p()
    return CF((3 * y * r[3] - 2 * p[1] / 3, r[2] - y * p[2] / 3))


def fb_g():
    """sigma(u) n on the sides, with sigma_11 = p/3 - 3 y r2 and sigma_12 = y p1 / 3:
    x = 0 (n = (-1,0)): -(sigma_11, sigma_12); x = 1 (n = (1,0)): (sigma_11, sigma_12)."""
    r, p = fb_r(), fb_p()
    s11, s12 = p[0] / 3 - 3 * y * r[2], y * p[1] / 3
    return IfPos(x - 0.5, CF((s11, s12)), CF((-s11, -s12)))


def fb_chi(px, py):
    return -0.05 * np.sin(_K * px) + np.maximum(FB_A - px, 0.0) ** 1.5


def problem(name, perturb=None):
    """The problem's data; perturb = "f" or "dirichlet" scales that datum by 1 + PERTURBATION
    (only where the datum is nonzero: f for ex71 and fb, the Dirichlet value for ex72)."""
    fscale = 1 + PERTURBATION if perturb == "f" else 1.0
    dscale = 1 + PERTURBATION if perturb == "dirichlet" else 1.0
    if perturb not in (None, "f", "dirichlet"):
        raise ValueError(f"unknown perturbation {perturb!r}")
    if name == "ex71":
        return Problem(
            name="ex71", mu=1.0, zeta=1.0,
            f=fscale * ex71_f(), g=ex71_g(),
            u_dirichlet=(0.0 * dscale, 0.0 * dscale),
            normal=(0.0, -1.0),
            chi=lambda px, py: np.zeros_like(px),
            exact=ex71_exact(),
        )
    if name == "ex72":
        E, nu = 500.0, 0.3
        return Problem(
            name="ex72",
            mu=E / (2 * (1 + nu)),
            zeta=E * nu / ((1 + nu) * (1 - 2 * nu)),
            f=None, g=None,
            u_dirichlet=(0.1 * dscale, 0.0),
            normal=(1.0, 0.0),
            chi=lambda px, py: -0.2 + 0.5 * np.abs(py - 0.5),
            exact=None,
        )
    if name == "fb":
        return Problem(
            name="fb", mu=1.0, zeta=1.0,
            f=fscale * fb_f(), g=fb_g(),
            u_dirichlet=fb_exact(),
            normal=(0.0, -1.0),
            chi=fb_chi,
            exact=fb_exact(),
            load_breaks=(FB_A,),
        )
    if name == "ex72_rollers":
        # experiments/problems/ex72_rollers.toml: Example 7.2 with u_1 = 0.1 on x = 0 and u_2 free
        # there (zero shear traction), u_2 = 0 at the point (0, 1/2); read by `estimator` only
        # (the PDAS of fem.py prescribes both components on Gamma_D and has no point constraint)
        return replace(problem("ex72", perturb), name="ex72_rollers", free=(1,))
    if name == "hertz":
        # experiments/problems/hertz.toml: the lower half of the unit disc centred at (0, 1),
        # plane strain E = 1000, nu = 0.3, u = (0, -delta) on the flat side y = 1, delta = 0.005,
        # no body force, zero traction on the free arc, fixed direction n = (0, -1), chi = y
        E, nu, delta = 1000.0, 0.3, 0.005
        return Problem(
            name="hertz",
            mu=E / (2 * (1 + nu)),
            zeta=E * nu / ((1 + nu) * (1 - 2 * nu)),
            f=None, g=None,
            u_dirichlet=(0.0, -delta * dscale),
            normal=(0.0, -1.0),
            chi=lambda px, py: np.asarray(py, float).copy(),
            exact=None,
        )
    raise ValueError(f"unknown problem {name!r} (expected ex71, ex72, fb, ex72_rollers or hertz)")


def stress(p, grad_u):
    """sigma(u) = 2 mu eps(u) + zeta tr(eps(u)) I, for a 2x2 gradient coefficient function."""
    from ngsolve import Id, Trace
    eps = 0.5 * (grad_u + grad_u.trans)
    return 2 * p.mu * eps + p.zeta * Trace(eps) * Id(2)


# The normal stress sigma_22 on Gamma_C (y = 0) that each problem's definition states.
SIGMA_NN = {"ex71": lambda px: 3 * px - 6, "fb": lambda px: -max(px - FB_A, 0.0) ** 2.5}


def check_data(name, mesh):
    """Max deviation of the transcribed f and g from -div sigma(u) and sigma(u) n of the exact u.

    NGSolve differentiates the exact coefficient function symbolically (CF.Diff), which is an
    independent route to the same formulas. Returns (err_f, err_g, err_contact) where err_contact is
    the deviation of the tangential stress on y = 0 from 0 and of sigma_22 from the stated normal
    stress (ex71: 3x - 6, from the exact solution; fb: p(x) = -((x - a)_+)^(5/2)).
    """
    p = problem(name)
    u = p.exact
    grad_u = CF((u[0].Diff(x), u[0].Diff(y), u[1].Diff(x), u[1].Diff(y)), dims=(2, 2))
    s = stress(p, grad_u)
    div_s = CF((s[0, 0].Diff(x) + s[0, 1].Diff(y), s[1, 0].Diff(x) + s[1, 1].Diff(y)))
    pts = np.linspace(0.0, 1.0, 21)
    err_f = err_g = err_c = 0.0
    for px in pts:
        for py in pts:
            mp = mesh(px, py)
            err_f = max(err_f, np.max(np.abs(np.array(p.f(mp)) + np.array(div_s(mp)))))
    for py in pts:
        for px, n in ((0.0, (-1.0, 0.0)), (1.0, (1.0, 0.0))):
            mp = mesh(px, py)
            sn = np.array(s(mp)).reshape(2, 2) @ np.array(n)
            err_g = max(err_g, np.max(np.abs(np.array(p.g(mp)) - sn)))
    for px in pts:
        sm = np.array(s(mesh(px, 0.0))).reshape(2, 2)
        err_c = max(err_c, abs(sm[0, 1]), abs(sm[1, 1] - SIGMA_NN[name](px)))
    return err_f, err_g, err_c
