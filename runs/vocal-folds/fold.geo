// One vocal fold of the paper's Sec. 5.1 (Miyauchi et al.), lengths in units of the channel width
// D without clearance: the M5 profile of Scherer et al. (2001) with the inferior surface at 40
// degrees, scaled to D = 2 cm (so T = 3 mm -> 0.15, exit radius 0.987 mm -> 0.04935), half the
// channel high (H = D/2), attached to the wall. Two layers: a cover of constant thickness along
// the surface the flow wets, over the body. Flow along +x; side = 1 is the fold on the bottom
// wall y = 0, side = -1 its mirror image on the top wall y = 1 + h.
//
// M5 coordinates (u medial-lateral, u = 0 the medial surface, u < 0 into the fold; s along the
// flow, s = 0 the superior (downstream) face): B exit-arc start on the superior face, G its centre
// (radius R_psi = R_o / (1 - sin(psi/2))), C its end on the medial surface, D the medial surface's
// inferior end, H the centre of the entrance arc (radius T/2), E its end where the inferior surface
// leaves at `inferior_angle` to the wall, F where it meets the wall, A where the superior face does.
DefineConstant[
  h = {0, Name "clearance h/D"},
  cover = {0.025, Name "cover thickness"},
  lc = {0.024, Name "element size"},
  lc_cover = {0, Name "element size at the wetted surface (0: lc)"},
  side = {1, Name "1: bottom fold, -1: top fold"},
  x0 = {2.0, Name "x of the superior (downstream) face"},
  T = {0.15, Name "M5 axial glottal length T"},
  Ro = {0.04935, Name "M5 exit radius R_o"},
  psi_deg = {0, Name "M5 glottal angle (> 0 convergent)"},
  inferior_deg = {40, Name "M5 inferior surface angle"}
];
W = 0.5;                       // fold height H = D/2
psi = psi_deg * Pi / 180;
beta = inferior_deg * Pi / 180;
Rp = Ro / (1 - Sin(psi / 2));
If (cover <= 0 || cover >= Rp)
  Error("fold.geo: cover must be in (0, %g) (the exit radius), got %g", Rp, cover);
EndIf

// M5 points (u, s).
Bu = -Rp;                        Bs = 0;
Gu = -Rp;                        Gs = -Rp;
Cu = -Rp * (1 - Cos(psi / 2));   Cs = -Rp * (1 + Sin(psi / 2));
Du = -(T - Rp + T / 2 * Sin(psi / 2)) * Tan(psi / 2);
Ds = -(T + T / 2 * Sin(psi / 2));
Hu = Du - T / 2 * Cos(psi / 2);  Hs = -T;
Eu = Hu + T / 2 * Sin(beta);     Es = -T - T / 2 * Cos(beta);
L = (W + Eu) / Cos(beta);
Fu = -W;                         Fs = Es - L * Sin(beta);
Au = -W;                         As = 0;
// The cover's inner boundary: the same chain moved inwards by `cover` along its normals.
B2u = Bu;                        B2s = -cover;
C2u = Cu + cover * (Gu - Cu) / Rp;        C2s = Cs + cover * (Gs - Cs) / Rp;
D2u = Du + cover * (Hu - Du) / (T / 2);   D2s = Ds + cover * (Hs - Ds) / (T / 2);
E2u = Eu + cover * (Hu - Eu) / (T / 2);   E2s = Es + cover * (Hs - Es) / (T / 2);
L2 = (W + E2u) / Cos(beta);
F2u = -W;                        F2s = E2s - L2 * Sin(beta);
A2u = -W;                        A2s = -cover;

// (u, s) -> channel (x, y).
yc = (1 - side) / 2 * (1 + h);
Macro P
  Point(id) = {x0 + ps, yc + side * (W + pu), 0, lc};
Return
id = 1;  pu = Au;  ps = As;  Call P;
id = 2;  pu = Bu;  ps = Bs;  Call P;
id = 3;  pu = Gu;  ps = Gs;  Call P;
id = 4;  pu = Cu;  ps = Cs;  Call P;
id = 5;  pu = Du;  ps = Ds;  Call P;
id = 6;  pu = Hu;  ps = Hs;  Call P;
id = 7;  pu = Eu;  ps = Es;  Call P;
id = 8;  pu = Fu;  ps = Fs;  Call P;
id = 11; pu = A2u; ps = A2s; Call P;
id = 12; pu = B2u; ps = B2s; Call P;
id = 14; pu = C2u; ps = C2s; Call P;
id = 15; pu = D2u; ps = D2s; Call P;
id = 17; pu = E2u; ps = E2s; Call P;
id = 18; pu = F2u; ps = F2s; Call P;

// The surface the flow wets: superior face, exit arc, medial surface, entrance arc, inferior face.
Line(1) = {1, 2};
Circle(2) = {2, 3, 4};
Line(3) = {4, 5};
Circle(4) = {5, 6, 7};
Line(5) = {7, 8};
// The cover's inner boundary.
Line(11) = {11, 12};
Circle(12) = {12, 3, 14};
Line(13) = {14, 15};
Circle(14) = {15, 6, 17};
Line(15) = {17, 18};
// The wall: cover, body, cover.
Line(21) = {8, 18};
Line(22) = {18, 11};
Line(23) = {11, 1};

Curve Loop(1) = {1, 2, 3, 4, 5, 21, -15, -14, -13, -12, -11, 23};
Plane Surface(1) = {1};
Curve Loop(2) = {11, 12, 13, 14, 15, 22};
Plane Surface(2) = {2};

// A finer mesh at the surface the flow wets (lc_cover < lc): lc_cover within the cover's
// thickness of it, growing linearly to lc at three times that.
If (lc_cover > 0 && lc_cover < lc)
  Field[1] = Distance;
  Field[1].CurvesList = {1, 2, 3, 4, 5};
  Field[1].NumPointsPerCurve = 200;
  Field[2] = Threshold;
  Field[2].InField = 1;
  Field[2].SizeMin = lc_cover;
  Field[2].SizeMax = lc;
  Field[2].DistMin = cover;
  Field[2].DistMax = 3 * cover;
  Background Field = 2;
EndIf

Physical Surface("cover") = {1};
Physical Surface("body") = {2};
Physical Curve("wall") = {21, 22, 23};
Physical Curve("surface") = {1, 2, 3, 4, 5};
Physical Curve("medial") = {3};
