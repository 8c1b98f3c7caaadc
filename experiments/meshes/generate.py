"""Mesh .geo scripts with gmsh's Python module: every experiments/meshes/*.geo without arguments
(`make meshes`), or the .geo files given, wherever they are (`make mesh GEO=path/to/disc.geo`
writes path/to/disc.msh beside it).

Each .geo sets its own options (MSH 4.1 ASCII, one thread, the meshing algorithm), so the same
.geo gives the same .msh byte for byte.
"""
import pathlib
import sys

import gmsh

here = pathlib.Path(__file__).resolve().parent
geos = sorted(here.glob("*.geo")) if len(sys.argv) == 1 else [pathlib.Path(a).resolve() for a in sys.argv[1:]]
for geo in geos:
    if not geo.is_file():
        sys.exit(f"error: {geo}: no such .geo file")
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(str(geo))
    gmsh.model.mesh.generate(2)
    msh = geo.with_suffix(".msh")
    gmsh.write(str(msh))
    n_nodes = len(gmsh.model.mesh.getNodes()[0])
    n_tri = sum(len(t) for t in gmsh.model.mesh.getElements(2)[1])
    gmsh.finalize()
    try:
        shown = msh.relative_to(pathlib.Path.cwd())
    except ValueError:  # outside the working directory: the whole path
        shown = msh
    print(f"{shown}: {n_nodes} nodes, {n_tri} triangles, {msh.stat().st_size} bytes")
