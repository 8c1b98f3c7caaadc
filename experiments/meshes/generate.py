"""Regenerate every experiments/meshes/*.msh from its .geo with gmsh's Python module (`make meshes`).

Each .geo sets its own options (MSH 4.1 ASCII, one thread, the meshing algorithm), so the same
.geo gives the same .msh byte for byte.
"""
import pathlib
import sys

import gmsh

here = pathlib.Path(__file__).resolve().parent
geos = sorted(here.glob("*.geo")) if len(sys.argv) == 1 else [pathlib.Path(a).resolve() for a in sys.argv[1:]]
for geo in geos:
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(str(geo))
    gmsh.model.mesh.generate(2)
    msh = geo.with_suffix(".msh")
    gmsh.write(str(msh))
    n_nodes = len(gmsh.model.mesh.getNodes()[0])
    n_tri = sum(len(t) for t in gmsh.model.mesh.getElements(2)[1])
    gmsh.finalize()
    print(f"{msh.relative_to(here.parent.parent)}: {n_nodes} nodes, {n_tri} triangles, {msh.stat().st_size} bytes")
