// The Turek-Hron cylinder (centre (0.2, 0.2), radius 0.05) as a rigid body; element size lc.
DefineConstant[ lc = 0.005 ];
r = 0.05; cx = 0.2; cy = 0.2;
Point(1) = {cx, cy, 0, lc};
Point(2) = {cx + r, cy, 0, lc};
Point(3) = {cx, cy + r, 0, lc};
Point(4) = {cx - r, cy, 0, lc};
Point(5) = {cx, cy - r, 0, lc};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("cylinder") = {1};
Physical Curve("surface") = {1, 2, 3, 4};
