// Hertz contact: the lower half of the disc of radius R = 1 centred at (0, 1) (the points with
// y <= 1), a cylinder's cross-section pressed onto a flat foundation at y = 0 (plane strain).
// Physical curves: "top" (the flat side y = 1), "contact" (the arc with |x| <= 0.3), "free" (the
// rest of the arc); physical surface "body". The mesh is graded towards the lowest point (0, 0):
// size 0.005 there, growing linearly to 0.1 at distance 0.6; the adaptive loop refines further.
// Regenerate with `make meshes` (gmsh's Python module; MSH 4.1 ASCII, one thread: deterministic).
R = 1;
a = 0.3;                       // the contact group's half-width (Hertz's a is about 0.05 R)
yc = 1 - Sqrt(R * R - a * a);  // height of the arc at x = +-a

Point(1) = {0, 1, 0};          // centre
Point(2) = {-R, 1, 0};
Point(3) = {R, 1, 0};
Point(4) = {-a, yc, 0};
Point(5) = {a, yc, 0};
Point(6) = {0, 0, 0};          // lowest point

Line(1) = {3, 2};              // top, right to left (counter-clockwise around the body)
Circle(2) = {2, 1, 4};         // free, left
Circle(3) = {4, 1, 6};         // contact, left half
Circle(4) = {6, 1, 5};         // contact, right half
Circle(5) = {5, 1, 3};         // free, right
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Physical Curve("top") = {1};
Physical Curve("contact") = {3, 4};
Physical Curve("free") = {2, 5};
Physical Surface("body") = {1};

// size field: distance to the lowest point, 0.005 within 0.002 of it, 0.1 beyond 0.6
Field[1] = Distance;
Field[1].PointsList = {6};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.005;
Field[2].SizeMax = 0.1;
Field[2].DistMin = 0.002;
Field[2].DistMax = 0.6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Mesh.Algorithm = 6;            // Frontal-Delaunay
Mesh.ElementOrder = 1;
General.NumThreads = 1;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;
