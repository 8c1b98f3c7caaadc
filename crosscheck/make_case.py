"""Write case directories in the Rust exporter's format, for structured:N meshes.

Used to develop and test the cross-check without the Rust binary, and by `crosscheck.py selftest`.
With --solve the point data come from our own NGSolve solve (so a self-comparison passes);
without it u, lambda and active are zero (reading and solving can still be exercised).

    python make_case.py --problem ex71 --mesh structured:8 --out DIR [--solve]
"""
import argparse
import json
import os

import meshio
import numpy as np

# Which side of the unit square is which boundary part (1 Dirichlet, 2 Neumann, 3 contact).
SIDES = {
    "ex71": {"bottom": 3, "top": 1, "left": 2, "right": 2},
    "ex72": {"left": 1, "right": 3, "bottom": 2, "top": 2},
    "fb": {"bottom": 3, "top": 1, "left": 2, "right": 2},
}


def structured_triangles(n):
    """The harness's structured:N mesh (README, 'The command line'): unit square, N x N squares, each cut by the diagonal
    from its lower-left to its upper-right corner. Returns vertices (n+1)^2 x 2, CCW triangles."""
    t = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(t, t)  # vertex (i, j) -> index j * (n + 1) + i
    vertices = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    v00 = (j * (n + 1) + i).ravel()
    v10, v01, v11 = v00 + 1, v00 + n + 1, v00 + n + 2
    tris = np.concatenate([np.column_stack([v00, v10, v11]), np.column_stack([v00, v11, v01])])
    return vertices, tris


def boundary_segments(vertices, tris, sides):
    """Boundary edges of a unit-square mesh (edges of exactly one triangle), with their part."""
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    segs = uniq[count == 1]
    mid = 0.5 * (vertices[segs[:, 0]] + vertices[segs[:, 1]])
    side = np.where(mid[:, 1] < 1e-12, "bottom", np.where(mid[:, 1] > 1 - 1e-12, "top",
                    np.where(mid[:, 0] < 1e-12, "left", "right")))
    return segs, np.array([sides[s] for s in side], np.int32)


def p2_mesh(vertices, tris, segs):
    """Add edge-midpoint nodes: points (vertices first), triangle6 and line3 connectivity."""
    nv = len(vertices)
    local = ((0, 1), (1, 2), (2, 0))
    e = np.sort(np.concatenate([tris[:, list(p)] for p in local]), axis=1)
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    mid_of_tri_edge = (nv + inv.ravel()).reshape(3, len(tris)).T
    points = np.concatenate([vertices, 0.5 * (vertices[uniq[:, 0]] + vertices[uniq[:, 1]])])
    lookup = {tuple(pair): nv + k for k, pair in enumerate(uniq)}
    seg_mid = np.array([lookup[tuple(sorted(s))] for s in segs])
    return points, np.column_stack([tris, mid_of_tri_edge]), np.column_stack([segs, seg_mid])


def write_case(out, problem, mesh_desc, points, tris6, lines3, parts, data=None, meta_extra=None):
    """Write mesh.vtu and case.json. data: dict with u (npts,2), lambda, active, contact."""
    npts = len(points)
    data = data or {}
    u = np.zeros((npts, 3))
    if "u" in data:
        u[:, :2] = data["u"]
    point_data = {
        "u": u,
        "lambda": np.asarray(data.get("lambda", np.zeros(npts)), float),
        "active": np.asarray(data.get("active", np.zeros(npts)), np.int32),
        "contact": np.asarray(data.get("contact", np.zeros(npts)), np.int32),
    }
    m = meshio.Mesh(
        np.column_stack([points, np.zeros(npts)]),
        [("triangle6", tris6), ("line3", lines3)],
        cell_data={"part": [np.zeros(len(tris6), np.int32), np.asarray(parts, np.int32)]},
        point_data=point_data,
    )
    os.makedirs(out, exist_ok=True)
    # Binary (base64) keeps every digit; meshio's ASCII writer keeps only 12 significant ones.
    meshio.write(os.path.join(out, "mesh.vtu"), m, binary=True)
    meta = {"problem": problem, "mesh": mesh_desc, "ndof": 2 * npts}
    meta.update(meta_extra or {})
    with open(os.path.join(out, "case.json"), "w") as fh:
        json.dump(meta, fh, indent=1)


def make_case(problem, mesh_desc, out, solve=False):
    kind, _, n = mesh_desc.partition(":")
    if kind != "structured":
        raise ValueError("only structured:N meshes are generated here")
    vertices, tris = structured_triangles(int(n))
    segs, parts = boundary_segments(vertices, tris, SIDES[problem])
    points, tris6, lines3 = p2_mesh(vertices, tris, segs)
    write_case(out, problem, mesh_desc, points, tris6, lines3, parts)
    if solve:
        from fem import read_case, solve_case  # NGSolve only when needed
        disc, res, _ = solve_case(read_case(out))
        npts = len(points)
        nodes = disc.contact_nodes
        lam, active, contact = np.zeros(npts), np.zeros(npts), np.zeros(npts)
        lam[nodes], active[nodes[res["active"]]], contact[nodes] = res["lambda"], 1, 1
        extra = {"pdas_iterations": res["iterations"], "generated_by": "crosscheck/make_case.py"}
        if disc.prob.exact is not None:
            extra["error"] = disc.errors(res["U"])
        write_case(out, problem, mesh_desc, points, tris6, lines3, parts,
                   {"u": res["U"].reshape(2, npts).T, "lambda": lam, "active": active,
                    "contact": contact}, extra)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--problem", required=True, choices=sorted(SIDES))
    ap.add_argument("--mesh", required=True, help="structured:N")
    ap.add_argument("--out", required=True)
    ap.add_argument("--solve", action="store_true", help="fill the point data with our NGSolve solution")
    a = ap.parse_args()
    make_case(a.problem, a.mesh, a.out, a.solve)


if __name__ == "__main__":
    main()
