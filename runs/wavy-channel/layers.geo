// Elastic wavy channel (Nagano et al. 2010; the paper's Sec. 4.1, Fig. 3): two elastic layers,
// one bonded to the wall y = 0 and one to the wall y = H, periodic in x with period L. The
// fluid-facing surfaces are mirror images about the channel's centre line,
//   lower: y = (H - h)/2 + delta cos(2 pi x / L),   upper: y = (H + h)/2 - delta cos(2 pi x / L),
// so the gap is h - 2 delta cos(2 pi x / L): narrowest at x = 0 (and L), widest at x = L/2.
// Each layer is a structured mesh of nx x ny quadrilaterals split into two triangles; the
// surface is the polyline through the nx + 1 nodes at x = i L / nx, which lie on the cosine.
// Physical groups: surface "layers", curves "wall" (fixed), "left" and "right" (periodic pair),
// "surface" (the fluid-facing interface).
DefineConstant[ H = 4.0, h = 2.0, delta = 0.3, L = 6.0, nx = 48, ny = 8, alternate = 0 ];

surfaces[] = {}; walls[] = {}; lefts[] = {}; rights[] = {}; interface[] = {};
For side In {0 : 1}
  // side 0: the lower layer (wall at y = 0); side 1: the upper layer (wall at y = H).
  sgn = 1 - 2 * side;
  yw = side * H;
  ym = 0.5 * H - sgn * 0.5 * h;
  pw0 = newp; Point(pw0) = {0, yw, 0};
  pw1 = newp; Point(pw1) = {L, yw, 0};
  ps[] = {};
  For i In {0 : nx}
    p = newp;
    Point(p) = {i * L / nx, ym + sgn * delta * Cos(2 * Pi * i / nx), 0};
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
  If (alternate)
    Transfinite Surface{s} = {pw0, pw1, ps[nx], ps[0]} Alternate;
  Else
    Transfinite Surface{s} = {pw0, pw1, ps[nx], ps[0]};
  EndIf
  surfaces[] += s;
  walls[] += lwall;
  lefts[] += lleft;
  rights[] += lright;
  interface[] += lsurf[];
EndFor

Physical Surface("layers") = {surfaces[]};
Physical Curve("wall") = {walls[]};
Physical Curve("left") = {lefts[]};
Physical Curve("right") = {rights[]};
Physical Curve("surface") = {interface[]};
