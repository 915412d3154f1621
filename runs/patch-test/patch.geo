// The patch: the unit square meshed with unstructured triangles of mixed shapes (Gmsh's default
// mesher with a size that varies over the square), left and right nodes matched for periodicity.
DefineConstant[ h = 0.12 ];
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, 0.6 * h};
Point(3) = {1, 1, 0, h};
Point(4) = {0, 1, 0, 1.5 * h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {4, 3};
Line(4) = {1, 4};
Curve Loop(1) = {1, 2, -3, -4};
Plane Surface(1) = {1};
Periodic Curve{2} = {4} Translate{1, 0, 0};
Physical Surface("patch") = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Point("origin") = {1};
Physical Point("corner") = {2};
