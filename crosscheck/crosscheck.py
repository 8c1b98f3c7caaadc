"""Independent NGSolve cross-check of the Rust Signorini solver (see README.md).

    crosscheck.py compare DIR [DIR...]       same mesh, same data, our own PDAS: u and active set must match
    crosscheck.py rates DIR [DIR...]         ex71 and fb on structured:N: L-infinity errors and rates vs case.json
    crosscheck.py bench [--sizes 32,64,...]  NGSolve timings of Example 7.2's linear elasticity system
    crosscheck.py bench-cold --n N           one whole linear solve in a fresh process (for the Rust bench)
    crosscheck.py selftest [DIR...]          shows that `compare` fails when one side's data are perturbed
    crosscheck.py estimator DIR [DIR...]     eta_1..eta_7, eta_h, eta_{i,p} and eta_T recomputed from u_h: must match

Results go to results/crosscheck/ (JSON + Markdown, written atomically). Exit status 1 on any failure.
"""
import argparse
import concurrent.futures
import json
import math
import multiprocessing
import os
import statistics
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import ngsolve as ng  # noqa: E402

import estimator  # noqa: E402
import fem  # noqa: E402
import make_case  # noqa: E402
import problems  # noqa: E402

RESULTS = os.path.join(os.path.dirname(HERE), "results", "crosscheck")
TOL_U = 1e-8  # nodal displacements, relative to max |u|
TOL_LAMBDA = 1e-8  # nodal contact forces, relative to max |lambda| (a residual: its round-off grows ~1/h^2)
TOL_RATE = 0.02


# -- output --------------------------------------------------------------------------------------
def write_atomic(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".tmp-")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def markdown_table(columns, rows):
    fmt = lambda v: f"{v:.3e}" if isinstance(v, float) else "" if v is None else str(v)  # noqa: E731
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(fmt(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def report(name, title, columns, rows, extra, out_dir, more=""):
    """Print a table and write it as NAME.json and NAME.md under out_dir (with the markdown `more`
    after the table)."""
    table = markdown_table(columns, rows) + more
    print(table)
    if out_dir:
        doc = {"title": title, "ngsolve": ng.__version__, "rows": rows, **extra}
        write_atomic(os.path.join(out_dir, name + ".json"), json.dumps(doc, indent=1) + "\n")
        write_atomic(os.path.join(out_dir, name + ".md"), f"# {title}\n\nNGSolve {ng.__version__}\n\n{table}")


# -- compare -------------------------------------------------------------------------------------
def compare_case(path, perturb=None):
    """Solve the case with NGSolve and compare with the exported solution; returns a table row."""
    case = fem.read_case(path)
    disc, res, seconds = fem.solve_case(case, perturb)
    npts, pd = disc.npts, case.point_data
    ours_nodal = res["U"].reshape(2, npts).T
    ours_eval = disc.point_values(res["U"])  # same function through NGSolve's own basis
    theirs = np.asarray(pd["u"])[:, :2]
    scale_u = np.linalg.norm(ours_nodal, axis=1).max()
    du = max(np.linalg.norm(ours_nodal - theirs, axis=1).max(), np.linalg.norm(ours_eval - theirs, axis=1).max())

    active = np.zeros(npts, bool)
    active[disc.contact_nodes[res["active"]]] = True
    contact = np.zeros(npts, bool)
    contact[disc.contact_nodes] = True
    lam = np.zeros(npts)
    lam[disc.contact_nodes] = res["lambda"]
    scale_l = np.abs(lam).max()
    # How decisively each contact node is classified (lambda on active nodes, the gap on inactive
    # ones, both relative): a tiny margin would explain an active-set mismatch by round-off.
    k, sign = disc.prob.normal_component
    gap = sign * res["U"][k * npts + disc.contact_nodes] - disc.chi
    margins = np.where(res["active"], res["lambda"] / max(scale_l, 1e-300), -gap / max(scale_u, 1e-300))
    dl = np.abs(lam - np.asarray(pd["lambda"])).max()

    row = {
        "case": os.path.basename(os.path.normpath(path)),
        "problem": case.meta["problem"],
        "mesh": case.meta.get("mesh", "?"),
        "ndof": 2 * npts,
        "pdas_its_rust": case.meta.get("pdas_iterations", "?"),
        "pdas_its_ngsolve": res["iterations"],
        "active_rust": int(np.sum(np.asarray(pd["active"]) != 0)),
        "active_ngsolve": int(active.sum()),
        "u_rel_diff": float(du / scale_u) if scale_u > 0 else float(du),
        "lambda_rel_diff": float(dl / scale_l) if scale_l > 0 else float(dl),
        "active_mismatch": int(np.sum(active != (np.asarray(pd["active"]) != 0))),
        "contact_mismatch": int(np.sum(contact != (np.asarray(pd["contact"]) != 0))),
        "active_margin": float(margins.min()) if len(margins) else None,
        "basis_change_err": disc.basis_change_error,
        "kkt": res["kkt"],
        "seconds": round(seconds, 3),
    }
    failures = []
    if row["ndof"] != case.meta.get("ndof", row["ndof"]):
        failures.append(f"ndof {case.meta['ndof']} != 2 x nodes {row['ndof']}")
    if not row["u_rel_diff"] <= TOL_U:
        failures.append(f"u differs by {row['u_rel_diff']:.2e} > {TOL_U:g}")
    if not row["lambda_rel_diff"] <= TOL_LAMBDA:
        failures.append(f"lambda differs by {row['lambda_rel_diff']:.2e} > {TOL_LAMBDA:g}")
    if row["active_mismatch"]:
        failures.append(f"active sets differ at {row['active_mismatch']} nodes")
    if row["contact_mismatch"]:
        failures.append(f"contact node sets differ at {row['contact_mismatch']} nodes")
    row["result"] = "PASS" if not failures else "FAIL: " + "; ".join(failures)
    return row


COMPARE_COLUMNS = ["case", "problem", "mesh", "ndof", "pdas_its_rust", "pdas_its_ngsolve", "active_rust",
                   "active_ngsolve", "u_rel_diff", "lambda_rel_diff", "active_mismatch", "active_margin", "seconds",
                   "result"]


def in_parallel(fn, dirs):
    """[fn(d) for d in dirs], the cases solved in two processes at a time (NGSolve solves them on
    one thread each), the largest mesh first: the Example 7.2 reference (250k unknowns, a dozen
    factorisations) takes most of the time, and the other cases are solved beside it."""
    workers = min(2, os.cpu_count() or 1)
    if workers < 2 or len(dirs) < 2:
        return [fn(d) for d in dirs]
    size = {d: os.path.getsize(os.path.join(d, "mesh.vtu")) for d in dirs}
    # a fresh interpreter per worker: NGSolve is not forked with its state
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        futures = {d: pool.submit(fn, d) for d in sorted(dirs, key=lambda d: -size[d])}
        return [futures[d].result() for d in dirs]


def cmd_compare(args):
    rows = in_parallel(compare_case, args.dirs)
    tol = {"u_rel": TOL_U, "lambda_rel": TOL_LAMBDA, "active": "identical", "contact": "identical"}
    report("compare", "NGSolve cross-check: same mesh, same data, independent PDAS", COMPARE_COLUMNS, rows,
           {"tolerances": tol}, args.out_dir)
    return all(r["result"] == "PASS" for r in rows)


# -- rates ---------------------------------------------------------------------------------------
def observed_rates(ns, errs):
    """Rates in h = 1/N between consecutive meshes: log(e_i / e_i+1) / log(N_i+1 / N_i)."""
    return [None] + [math.log(errs[i] / errs[i + 1]) / math.log(ns[i + 1] / ns[i]) for i in range(len(ns) - 1)]


def cmd_rates(args):
    by_problem = {}
    for d in args.dirs:
        case = fem.read_case(d)
        kind, _, n = case.meta.get("mesh", "").partition(":")
        if case.meta["problem"] not in RATE_PROBLEMS or kind != "structured":
            sys.exit(f"rates: {d} is not a case of {' or '.join(RATE_PROBLEMS)} on a structured:N mesh")
        disc, res, _ = fem.solve_case(case)
        by_problem.setdefault(case.meta["problem"], []).append((int(n), d, case.meta.get("error", {}), disc.errors(res["U"])))
    all_rows, ok = [], True
    for problem in sorted(by_problem):
        rows, good = problem_rates(problem, sorted(by_problem[problem]))
        all_rows += rows
        ok = ok and good
    for row in all_rows:
        row.setdefault("result", "PASS")
    cols = ["case", "problem", "N"] + [f"{p}{k}_{s}" for k in ("linf_nodal", "linf_dense")
                                       for p in ("", "rate_") for s in ("rust", "ngsolve")] + ["result"]
    report("rates", "Examples with an exact solution (ex71, fb): L-infinity errors and observed rates (in h), Rust vs NGSolve",
           cols, all_rows,
           {"tolerance_rate": TOL_RATE,
            "norm": "max over points and both components of |u - u_h|; "
                    "dense = barycentric lattice of order 6 per triangle (as crates/model/src/settings/sampling.rs)"},
           args.out_dir)
    return ok


# Problems with an exact solution, whose rates `rates` compares.
RATE_PROBLEMS = ("ex71", "fb")


def problem_rates(problem, cases):
    """Rows of one problem's cases (sorted by N) and whether the Rust and NGSolve rates agree."""
    ns = [c[0] for c in cases]
    rows = [{"case": os.path.basename(os.path.normpath(d)), "problem": problem, "N": n} for n, d, _, _ in cases]
    ok = True
    for key in ("linf_nodal", "linf_dense"):
        ours = [c[3][key] for c in cases]
        r_ours = observed_rates(ns, ours)
        have = all(key in c[2] for c in cases)
        theirs = [c[2][key] for c in cases] if have else [None] * len(cases)
        r_theirs = observed_rates(ns, theirs) if have else [None] * len(cases)
        for row, e_o, e_t, q_o, q_t in zip(rows, ours, theirs, r_ours, r_theirs):
            row[f"{key}_ngsolve"], row[f"{key}_rust"] = e_o, e_t
            row[f"rate_{key}_ngsolve"], row[f"rate_{key}_rust"] = q_o, q_t
            if q_o is not None and q_t is not None and abs(q_o - q_t) > TOL_RATE:
                ok = False
                row["result"] = f"FAIL: {key} rate {q_t:.3f} vs {q_o:.3f}"
        if not have:
            print(f"rates: case.json lacks error.{key} in some {problem} case: not compared")
    return rows, ok


# -- bench ---------------------------------------------------------------------------------------
def bench_once(mesh, prob, inverse=fem.INVERSE):
    """One assembly + factorisation + solve of Example 7.2 without contact with NGSolve's sparse direct
    solver `inverse`; returns (times, fes, err)."""
    t0 = time.perf_counter()
    fes = ng.VectorH1(mesh, order=2, dirichlet="dirichlet")
    # PARDISO gets the matrix stored as symmetric and is told it is positive definite
    # ("pardisospd": MKL's LL^T; "pardiso" on a general matrix would factorise it by LU), as a user
    # who knows the system would give it; sparsecholesky assumes symmetry anyway
    a = fem.stiffness_form(fes, prob, symmetric=inverse == "pardisospd").Assemble()
    f = fem.load_form(fes, prob).Assemble()
    t1 = time.perf_counter()
    inv = a.mat.Inverse(fes.FreeDofs(), inverse=inverse)
    t2 = time.perf_counter()
    gf = ng.GridFunction(fes)
    gf.Set(ng.CF(prob.u_dirichlet), definedon=mesh.Boundaries("dirichlet"))
    r = f.vec.CreateVector()
    r.data = f.vec - a.mat * gf.vec
    gf.vec.data += inv * r
    t3 = time.perf_counter()
    # Without contact the exact solution is the translation u_D: a cheap sanity check.
    err = ng.Integrate(ng.Norm(gf - ng.CF(prob.u_dirichlet)), mesh, order=4)
    return (t1 - t0, t2 - t1, t3 - t2), fes, err


def bench_size(n, repeats, threads):
    """All repeats of one size, in this process; returns the row (peak memory of this process)."""
    import resource
    ng.SetNumThreads(threads)
    prob = problems.problem("ex72")
    with ng.TaskManager():
        vertices, tris = make_case.structured_triangles(n)
        segs, parts = make_case.boundary_segments(vertices, tris, make_case.SIDES["ex72"])
        mesh = fem.build_ngmesh(vertices, tris, segs, parts)
        runs = [bench_once(mesh, prob) for _ in range(repeats)]
        used = ng.GetNumThreads()  # inside the TaskManager: the threads actually used
    fes, err = runs[-1][1], runs[-1][2]
    med = [statistics.median(r[0][i] for r in runs) for i in range(3)]
    return {"N": n, "ndof": fes.ndof, "ndof_free": sum(fes.FreeDofs()),
            "assembly_s": med[0], "factorisation_s": med[1], "solve_s": med[2],
            "total_s": sum(med), "first_factorisation_s": runs[0][0][1],
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
            "threads": used, "l1_error_vs_translation": err}


def bench_cold(n, threads, inverse=fem.INVERSE):
    """One whole linear solve in this fresh process (what a user of NGSolve sees, Python's start and
    the imports excepted): NGSolve mesh, assembly, factorisation with `inverse` ("sparsecholesky", or
    "pardisospd": MKL PARDISO's LL^T, which needs the bench venv's pinned mkl), solve; with the process's peak memory."""
    import resource
    ng.SetNumThreads(threads)
    prob = problems.problem("ex72")
    with ng.TaskManager():
        vertices, tris = make_case.structured_triangles(n)
        segs, parts = make_case.boundary_segments(vertices, tris, make_case.SIDES["ex72"])
        t0 = time.perf_counter()
        mesh = fem.build_ngmesh(vertices, tris, segs, parts)
        mesh_s = time.perf_counter() - t0
        (assembly, factorisation, solve), fes, err = bench_once(mesh, prob, inverse)
        whole = time.perf_counter() - t0
        used = ng.GetNumThreads()
    return {"N": n, "inverse": inverse, "ndof_free": sum(fes.FreeDofs()), "whole_s": whole, "mesh_s": mesh_s, "assembly_s": assembly,
            "factorisation_s": factorisation, "solve_s": solve,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
            "threads": used, "l1_error_vs_translation": err}


def cmd_bench_cold(args):
    row = bench_cold(args.n, args.threads or os.cpu_count(), args.inverse)
    print("ROW " + json.dumps(row))
    return row["l1_error_vs_translation"] <= 1e-8


def cmd_bench_one(args):
    print("ROW " + json.dumps(bench_size(args.n, args.repeats, args.threads or os.cpu_count())))
    return True


def cmd_bench(args):
    # every size in a fresh process: its peak memory is its own, and its first factorisation
    # pays the first touch of its memory as ours does
    import subprocess
    sizes = [int(s) for s in args.sizes.split(",")]
    threads = args.threads or os.cpu_count()
    rows = []
    load_before = os.getloadavg()[0]  # timings on a busy machine are not worth much: record it
    for n in sizes:
        out = subprocess.run([sys.executable, os.path.abspath(__file__), "bench-one", "--n", str(n),
                              "--repeats", str(args.repeats), "--threads", str(threads)],
                             check=True, capture_output=True, text=True).stdout
        row = json.loads(next(line[4:] for line in out.splitlines() if line.startswith("ROW ")))
        rows.append(row)
        print(f"NGSolve N={n}: assembly {row['assembly_s']:.3f} s, factorisation {row['factorisation_s']:.3f} s, "
              f"solve {row['solve_s']:.3f} s, peak {row['peak_rss_mb']:.0f} MB", flush=True)
        err = row["l1_error_vs_translation"]
        if err > 1e-8:
            print(f"bench: N={n}: solution is not the translation (L1 error {err:g})")
            return False
    used = rows[-1]["threads"] if rows else threads
    cols = ["N", "ndof", "ndof_free", "assembly_s", "factorisation_s", "solve_s", "total_s", "peak_rss_mb"]
    table = markdown_table(cols, rows)
    print(table)
    doc = {"title": "NGSolve: Example 7.2 linear elasticity (no contact), P2, structured:N",
           "ngsolve": ng.__version__, "inverse": fem.INVERSE, "threads": used, "repeats": args.repeats,
           "cpu_count": os.cpu_count(), "loadavg_1min_before": load_before,
           "loadavg_1min_after": os.getloadavg()[0],
           "statistic": "median", "mesh": "structured:N, diagonal lower-left to upper-right",
           "timed": {"assembly": "space + stiffness matrix + load vector",
                     "factorisation": "sparse factorisation on the free dofs",
                     "solve": "Dirichlet values, residual, forward/back substitution",
                     "peak_rss_mb": "peak resident memory of the process that ran the size (one process per size)"},
           "rows": rows}
    if args.out_dir:
        write_atomic(os.path.join(args.out_dir, "ngsolve_bench.json"), json.dumps(doc, indent=1) + "\n")
    return True


# -- estimator -----------------------------------------------------------------------------------
TOL_ETA = 1e-9  # every estimator quantity, relative to its largest value in the case (see _scale)
GLOBAL_TERMS = ("eta1", "eta2", "eta3", "eta4", "eta5", "eta6", "eta7", "l_h", "psi", "eta_h", "estimate")
ETA_PERTURBATION = 1e-6  # the failure demonstration: u_h at one node moved by this times max |u_h|


def estimator_diffs(case, ours, scale_u):
    """Relative differences between our estimator and the exported one: each global term against
    case.json's `estimator`, eta_{i,p} (point data eta1..eta5) node by node, eta_T (cell data
    `indicator`) element by element; each relative to the quantity's largest value (over both
    codes, and at least the round-off scale _scale gives it)."""
    theirs = case.meta["estimator"]
    d = {}
    for k in GLOBAL_TERMS:
        d[k] = abs(ours[k] - theirs[k]) / _scale(k, max(abs(ours[k]), abs(theirs[k])), scale_u)
    pd = case.point_data
    for i in range(5):
        a, b = ours["eta_p"][:, i], np.asarray(pd[f"eta{i + 1}"], float)
        d[f"eta{i + 1}_p"] = float(np.abs(a - b).max() / _scale(None, max(np.abs(a).max(), np.abs(b).max()), scale_u))
    a, b = ours["eta_T"], np.asarray(case.cell_data["indicator"], float)
    d["eta_T"] = float(np.abs(a - b).max() / _scale(None, max(np.abs(a).max(), np.abs(b).max()), scale_u))
    return d


def _scale(key, largest, scale_u):
    """The denominator of a relative difference: the quantity's largest value; for eta_6 and eta_7
    (maxima of u_h.n - chi, differences of displacements that vanish where u_h.n = chi at the
    nodes) at least max |u_h|, whose round-off they carry; never zero."""
    if key in ("eta6", "eta7"):
        largest = max(largest, scale_u)
    return largest if largest > 0 else 1.0


def estimator_case(path):
    """Recompute the case's estimator on NGSolve's side and compare; then show that the comparison
    fails when u_h is perturbed at one node and under the contact-term variants that differ."""
    t0 = time.perf_counter()
    case = fem.read_case(path)
    name = case.meta["problem"]
    prob = problems.problem(name)
    cfg = case.meta["estimator_config"]
    pd = case.point_data
    missing = [k for k in ("lambda_floor", "eta1", "eta5") if k not in pd]
    if missing or "indicator" not in case.cell_data:
        raise ValueError(f"{path}: mesh.vtu lacks {missing or 'indicator'} (export it with this `signorini export`)")
    ev = estimator.Evaluator(case, prob)
    U = np.asarray(pd["u"], float)[:, :2]
    scale_u = float(np.abs(U).max())
    inputs = (np.asarray(pd["lambda"], float), np.asarray(pd["lambda_floor"], float), pd["active"], pd["contact"])
    ours = ev.terms(U, *inputs, cfg["contact_term"], cfg["c0"])
    d = estimator_diffs(case, ours, scale_u)
    worst = max(d, key=d.get)
    row = {"case": os.path.basename(os.path.normpath(path)), "problem": name, "contact_term": cfg["contact_term"],
           "elements": len(case.tris), "full_contact": ours["full_contact_nodes"],
           **{k: ours[k] for k in ("eta1", "eta5", "eta6", "eta7", "eta_h")},
           "diff": d, "max_rel_diff": d[worst], "worst": worst}
    failures = [f"{k} differs by {v:.2e}" for k, v in d.items() if not v <= TOL_ETA]
    if case.meta.get("full_contact_nodes", ours["full_contact_nodes"]) != ours["full_contact_nodes"]:
        failures.append(f"full-contact nodes {case.meta['full_contact_nodes']} vs {ours['full_contact_nodes']}")

    # the comparison can fail: u_h moved at the node of the largest eta_T's element, by
    # ETA_PERTURBATION max |u_h| in both components, must be noticed
    p0 = int(case.tris[int(np.argmax(ours["eta_T"])), 0])
    Up = U.copy()
    Up[p0] += ETA_PERTURBATION * scale_u
    dp = estimator_diffs(case, ev.terms(Up, *inputs, cfg["contact_term"], cfg["c0"]), scale_u)
    row["perturbed_u_max_rel_diff"] = max(dp.values())
    if not row["perturbed_u_max_rel_diff"] > TOL_ETA:
        failures.append("u_h perturbed at one node went unnoticed")
    # ... and so must another contact-term variant, wherever it gives other numbers than the declared one
    noticed = []
    for term in estimator.CONTACT_TERMS:
        if term == cfg["contact_term"]:
            continue
        other = ev.terms(U, *inputs, term, cfg["c0"], loc=ours["locals"])
        differs = any(abs(other[k] - ours[k]) > TOL_ETA * _scale(k, abs(ours[k]), scale_u) for k in GLOBAL_TERMS) \
            or np.abs(other["eta_T"] - ours["eta_T"]).max() > TOL_ETA * np.abs(ours["eta_T"]).max()
        if not differs:
            continue
        dv = max(estimator_diffs(case, other, scale_u).values())
        noticed.append(f"{term} {dv:.1e}")
        if not dv > TOL_ETA:
            failures.append(f"contact_term {term} instead of {cfg['contact_term']} went unnoticed")
    row["other_contact_terms"] = ", ".join(noticed) if noticed else "same numbers"
    row["seconds"] = round(time.perf_counter() - t0, 3)
    row["result"] = "PASS" if not failures else "FAIL: " + "; ".join(failures)
    return row


ESTIMATOR_COLUMNS = ["case", "problem", "contact_term", "elements", "full_contact", "eta_h", "max_rel_diff", "worst",
                     "perturbed_u_max_rel_diff", "other_contact_terms", "seconds", "result"]


def cmd_estimator(args):
    rows = in_parallel(estimator_case, args.dirs)
    keys = list(rows[0]["diff"]) if rows else []
    per_quantity = [{"case": r["case"], **{k: r["diff"][k] for k in keys}} for r in rows]
    more = (f"\nRelative differences per quantity (tolerance {TOL_ETA:g}; `_p`: node by node, eta_T: element "
            "by element):\n\n" + markdown_table(["case"] + keys, per_quantity))
    report("estimator", "NGSolve cross-check of the estimator (eq. 6.3): eta_1..eta_7, eta_h, eta_{i,p}, eta_T "
           "recomputed from the exported u_h", ESTIMATOR_COLUMNS, rows,
           {"tolerance_rel": TOL_ETA, "perturbation": ETA_PERTURBATION,
            "largest_rel_diff_per_quantity": {k: max(r["diff"][k] for r in rows) for k in keys}},
           args.out_dir, more)
    return all(r["result"] == "PASS" for r in rows)


# -- selftest ------------------------------------------------------------------------------------
# The datum we perturb for each problem: one that is nonzero there.
PERTURB = {"ex71": "f", "ex72": "dirichlet", "fb": "f"}


def cmd_selftest(args):
    ok = True
    mesh = fem.build_ngmesh(*_unit_square_for_data_check())
    rows = []
    for name in ("ex71", "fb"):
        ef, eg, ec = problems.check_data(name, mesh)
        print(f"{name} data vs symbolic derivatives of the exact u: f {ef:.1e}, g {eg:.1e}, contact stress {ec:.1e}")
        rows.append({"case": f"{name} data", "check": "f, g, sigma on Gamma_C vs exact u", "value": max(ef, eg, ec),
                     "result": "PASS" if max(ef, eg, ec) < 1e-10 else "FAIL"})

    with tempfile.TemporaryDirectory() as tmp:
        dirs = args.dirs
        if not dirs:  # no Rust export given: make cases holding our own solution
            dirs = []
            for prob in ("ex71", "ex72"):
                d = os.path.join(tmp, f"{prob}-structured-8")
                make_case.make_case(prob, "structured:8", d, solve=True)
                dirs.append(d)
        for d in dirs:
            name = os.path.basename(os.path.normpath(d))
            base = compare_case(d)
            rows.append({"case": name, "check": "unperturbed compare passes", "value": base["u_rel_diff"],
                         "result": "PASS" if base["result"] == "PASS" else "FAIL: " + base["result"]})
            kind = PERTURB[fem.read_case(d).meta["problem"]]
            pert = compare_case(d, perturb=kind)
            rows.append({"case": name, "check": f"{kind} x (1+{problems.PERTURBATION:g}): compare fails",
                         "value": pert["u_rel_diff"],
                         "result": "PASS" if pert["result"] != "PASS" else "FAIL: perturbation went unnoticed"})
    ok = all(r["result"] == "PASS" for r in rows)
    report("selftest", "NGSolve cross-check self-test: the comparison can fail", ["case", "check", "value", "result"],
           rows, {}, args.out_dir)
    return ok


def _unit_square_for_data_check():
    vertices, tris = make_case.structured_triangles(4)
    segs, parts = make_case.boundary_segments(vertices, tris, make_case.SIDES["ex71"])
    return vertices, tris, segs, parts


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out-dir", default=RESULTS, help="where to write results (default results/crosscheck; '' for none)")
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("compare")
    p.add_argument("dirs", nargs="+")
    p.set_defaults(func=cmd_compare)
    p = sub.add_parser("rates")
    p.add_argument("dirs", nargs="+")
    p.set_defaults(func=cmd_rates)
    p = sub.add_parser("bench")
    p.add_argument("--sizes", default="32,64,128,256")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--threads", type=int, default=0, help="NGSolve threads (default: all cores)")
    p.set_defaults(func=cmd_bench)
    p = sub.add_parser("bench-one", help="one size of bench, in this process (bench runs it per size)")
    p.add_argument("--n", type=int, required=True)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--threads", type=int, default=0)
    p.set_defaults(func=cmd_bench_one)
    p = sub.add_parser("bench-cold", help="one whole linear solve of structured:N in this fresh process (the Rust bench runs it)")
    p.add_argument("--n", type=int, required=True)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--inverse", default=fem.INVERSE, choices=["sparsecholesky", "pardisospd"],
                   help="NGSolve's sparse direct solver (pardisospd: MKL PARDISO's LL^T on the symmetric "
                        "matrix, in crosscheck/.venv-bench)")
    p.set_defaults(func=cmd_bench_cold)
    p = sub.add_parser("estimator")
    p.add_argument("dirs", nargs="+")
    p.set_defaults(func=cmd_estimator)
    p = sub.add_parser("selftest")
    p.add_argument("dirs", nargs="*", help="exported cases to perturb (default: generated structured:8 cases)")
    p.set_defaults(func=cmd_selftest)
    args = ap.parse_args()
    ok = args.func(args)
    if not ok:
        print(f"crosscheck {args.cmd}: FAILED")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
