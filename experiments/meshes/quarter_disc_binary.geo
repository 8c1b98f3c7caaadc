// The tests' quarter disc (quarter_disc.geo) written as binary MSH 4.1: the reader must give the
// same mesh from both encodings (tests/it/gmsh.rs). Regenerate with `make meshes`.
Merge "quarter_disc.geo";
Mesh.Binary = 1;
