// Turek-Hron CFD obstacle (Turek & Hron 2006): the cylinder (centre (0.2, 0.2), radius 0.05) and
// the bar behind it (to x = 0.6, y in [0.19, 0.21]) as one rigid body, meshed from their common
// outline with unstructured triangles of size lc (override with mesh_parameters in the scene).
DefineConstant[ lc = 0.005 ];
r = 0.05; cx = 0.2; cy = 0.2; h = 0.01;
x0 = cx + Sqrt(r * r - h * h);  // 0.24899: where the bar's edges meet the circle
Point(1) = {cx, cy, 0, lc};
Point(2) = {x0, cy - h, 0, lc};
Point(3) = {0.6, cy - h, 0, lc};
Point(4) = {0.6, cy + h, 0, lc};
Point(5) = {x0, cy + h, 0, lc};
Point(6) = {cx - r, cy, 0, lc};
Line(1) = {2, 3};
Line(2) = {3, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 6};
Circle(5) = {6, 1, 2};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Surface("obstacle") = {1};
Physical Curve("cylinder") = {4, 5};
Physical Curve("bar") = {1, 2, 3};
