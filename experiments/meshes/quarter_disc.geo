// A small test mesh: the quarter of the unit disc in x >= 0, y >= 0.
// Physical curves: "bottom" (y = 0), "arc" (the circle of radius 1 about the origin), "left"
// (x = 0); physical surface "body". Size 0.25: a few dozen triangles (tests/it/gmsh.rs).
// Regenerate with `make meshes`.
h = 0.25;
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Point(3) = {0, 1, 0, h};
Line(1) = {1, 2};
Circle(2) = {2, 1, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("arc") = {2};
Physical Curve("left") = {3};
Physical Surface("body") = {1};

Mesh.Algorithm = 6;
Mesh.ElementOrder = 1;
General.NumThreads = 1;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;
