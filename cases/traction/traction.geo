// traction.geo: a flat dog-bone tensile specimen (thesis §5.3, figure 5.11): wide grips at both
// ends, fillets of radius Rf, and a gauge section whose width narrows slightly towards the middle
// (wge at the gauge ends, wc at the centre, along a shallow arc) so that the smallest section,
// and so the highest stress, is in the middle of the gauge rather than at the fillets.
// Values below are defaults; traction.yaml overrides them.
DefineConstant[
  L   = {0.12,  Name "Parameters/total length [m]"},
  Wg  = {0.02,  Name "Parameters/grip width [m]"},
  Lgs = {0.04,  Name "Parameters/gauge length [m]"},
  wge = {0.012, Name "Parameters/gauge width at its ends [m]"},
  wc  = {0.010, Name "Parameters/gauge width at the centre [m]"},
  Rf  = {0.02,  Name "Parameters/fillet radius [m]"},
  lc  = {0.002, Name "Parameters/mesh size [m]"}
];

yc = Wg/2;              // the specimen's axis
x2 = L/2 - Lgs/2;       // gauge starts
x3 = L/2 + Lgs/2;       // gauge ends
step = (Wg - wge)/2;    // grip-to-gauge step on each side
dxf = Sqrt(Rf^2 - (Rf - step)^2);  // x-extent of the fillet arc
x1 = x2 - dxf;          // fillet starts (end of the grip)
x4 = x3 + dxf;
// The gauge edge: the arc through the gauge ends and the centre (half-chord c, sagitta s).
c = Lgs/2;
s = (wge - wc)/2;
Rw = (c^2 + s^2)/(2*s);

// Upper edge, left to right
Point(1) = {0, Wg, 0, lc};
Point(2) = {x1, Wg, 0, lc};
Point(3) = {x2, yc + Rf + wge/2, 0, lc};      // fillet centre
Point(4) = {x2, yc + wge/2, 0, lc};
Point(5) = {L/2, yc + wc/2 + Rw, 0, lc};      // gauge-arc centre
Point(6) = {L/2, yc + wc/2, 0, lc};
Point(7) = {x3, yc + wge/2, 0, lc};
Point(8) = {x3, yc + Rf + wge/2, 0, lc};
Point(9) = {x4, Wg, 0, lc};
Point(10) = {L, Wg, 0, lc};
// Lower edge, mirrored
Point(11) = {L, 0, 0, lc};
Point(12) = {x4, 0, 0, lc};
Point(13) = {x3, yc - Rf - wge/2, 0, lc};
Point(14) = {x3, yc - wge/2, 0, lc};
Point(15) = {L/2, yc - wc/2 - Rw, 0, lc};
Point(16) = {L/2, yc - wc/2, 0, lc};
Point(17) = {x2, yc - wge/2, 0, lc};
Point(18) = {x2, yc - Rf - wge/2, 0, lc};
Point(19) = {x1, 0, 0, lc};
Point(20) = {0, 0, 0, lc};

Line(1) = {1, 2};
Circle(2) = {2, 3, 4};
Circle(3) = {4, 5, 6};
Circle(4) = {6, 5, 7};
Circle(5) = {7, 8, 9};
Line(6) = {9, 10};
Line(7) = {10, 11};     // right end
Line(8) = {11, 12};
Circle(9) = {12, 13, 14};
Circle(10) = {14, 15, 16};
Circle(11) = {16, 15, 17};
Circle(12) = {17, 18, 19};
Line(13) = {19, 20};
Line(14) = {20, 1};     // left end

Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
Plane Surface(1) = {1};

// Names are the contract with the case file (pipeline/formats.md).
Physical Surface("specimen") = {1};
Physical Curve("left") = {14};
Physical Curve("right") = {7};
