// Bad input: a surface whose four corners lie on one line (zero area), which Gmsh's mesher
// cannot mesh.
lc = 0.05;
Point(1) = {0.2, 0.5, 0, lc};
Point(2) = {0.4, 0.5, 0, lc};
Point(3) = {0.6, 0.5, 0, lc};
Point(4) = {0.8, 0.5, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("plate") = {1};
