// Turek-Hron elastic bar (Turek & Hron 2006): length to x = 0.6, thickness 0.02, y in
// [0.19, 0.21], its left end the arc of the cylinder (centre (0.2, 0.2), radius 0.05) where it
// is clamped. Structured triangles, diagonals alternating; ny across, nx along (override with
// mesh_parameters in the scene).
DefineConstant[ ny = 4, nx = 70 ];
r = 0.05; cx = 0.2; cy = 0.2; h = 0.01;
x0 = cx + Sqrt(r * r - h * h);
Point(1) = {cx, cy, 0};
Point(2) = {x0, cy - h, 0};
Point(3) = {0.6, cy - h, 0};
Point(4) = {0.6, cy + h, 0};
Point(5) = {x0, cy + h, 0};
Line(1) = {2, 3};
Line(2) = {3, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1} = {2, 3, 4, 5} Alternate;
Physical Surface("bar") = {1};
Physical Curve("clamp") = {4};
Physical Curve("bottom") = {1};
Physical Curve("tip") = {2};
Physical Curve("top") = {3};
