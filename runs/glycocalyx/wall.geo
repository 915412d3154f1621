// Elastic wavy wall of the glycocalyx channel (the paper's Sec. 5.2, Fig. 16; its shape is not in
// the paper's text, runs/glycocalyx/README.md states the choice): one layer bonded to the wall
// y = 0, periodic in x with period L, its fluid-facing surface one cosine wavelength,
//   y = T + delta cos(2 pi x / L),
// a structured mesh of nx x ny quadrilaterals split into two triangles (nx = 64, ny = 16: the
// paper's 1 105 nodes and 2 048 elements). The surface is the polyline through the nx + 1 nodes
// at x = i L / nx, which lie on the cosine. Physical groups: surface "wall_layer", curves "wall"
// (fixed), "left" and "right" (periodic pair), "surface" (the fluid-facing interface).
DefineConstant[ T = 0.25, delta = 0.05, L = 1.0, nx = 64, ny = 16 ];

pw0 = newp; Point(pw0) = {0, 0, 0};
pw1 = newp; Point(pw1) = {L, 0, 0};
ps[] = {};
For i In {0 : nx}
  p = newp;
  Point(p) = {i * L / nx, T + delta * Cos(2 * Pi * i / nx), 0};
  ps[] += p;
EndFor
lwall = newl; Line(lwall) = {pw0, pw1};
lright = newl; Line(lright) = {pw1, ps[nx]};
lsurf[] = {};
For i In {0 : nx - 1}
  l = newl; Line(l) = {ps[nx - i], ps[nx - i - 1]};
  lsurf[] += l;
EndFor
lleft = newl; Line(lleft) = {ps[0], pw0};
Transfinite Curve{lwall} = nx + 1;
Transfinite Curve{lright, lleft} = ny + 1;
Transfinite Curve{lsurf[]} = 2;
cl = newll; Curve Loop(cl) = {lwall, lright, lsurf[], lleft};
s = news; Plane Surface(s) = {cl};
Transfinite Surface{s} = {pw0, pw1, ps[nx], ps[0]};

Physical Surface("wall_layer") = {s};
Physical Curve("wall") = {lwall};
Physical Curve("left") = {lleft};
Physical Curve("right") = {lright};
Physical Curve("surface") = {lsurf[]};
