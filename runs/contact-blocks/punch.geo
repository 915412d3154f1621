// The upper block of the contact case: [0.25, 0.75] x [0.5, 0.9], unstructured triangles
// (Gmsh's default mesher) so that its nodes do not match the lower block's.
DefineConstant[ h = 0.035 ];
Point(1) = {0.25, 0.5, 0, h};
Point(2) = {0.75, 0.5, 0, h};
Point(3) = {0.75, 0.9, 0, h};
Point(4) = {0.25, 0.9, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("punch") = {1};
Physical Curve("bottom") = {1};
Physical Curve("top") = {3};
Physical Curve("sides") = {2, 4};
