// three_point_bending.geo: a single-edge-notched steel beam in three-point bending (SENB, the
// ASTM E399 geometry with span S = 4W). The beam is L × W; the notch is a pre-crack in the .yaml
// (`cracks:`), not a hole in the geometry. The supports and the load are short segments of the
// bottom and top edges (2·p long, centred at the support and load lines), so each is a small patch
// of nodes rather than a single node.
DefineConstant[
  L  = {0.10,  Name "Parameters/beam length [m]"},
  W  = {0.02,  Name "Parameters/beam depth W [m]"},
  S  = {0.08,  Name "Parameters/span S between the supports [m]"},
  p  = {0.001, Name "Parameters/half-width of the support and load patches [m]"},
  lc = {0.002, Name "Parameters/mesh size [m]"}
];

xl = L/2 - S/2;   // left support line
xr = L/2 + S/2;   // right support line
Point(1) = {0, 0, 0, lc};
Point(2) = {xl - p, 0, 0, lc};
Point(3) = {xl + p, 0, 0, lc};
Point(4) = {xr - p, 0, 0, lc};
Point(5) = {xr + p, 0, 0, lc};
Point(6) = {L, 0, 0, lc};
Point(7) = {L, W, 0, lc};
Point(8) = {L/2 + p, W, 0, lc};
Point(9) = {L/2 - p, W, 0, lc};
Point(10) = {0, W, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};    // left support
Line(3) = {3, 4};
Line(4) = {4, 5};    // right support
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 9};    // load
Line(9) = {9, 10};
Line(10) = {10, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
Plane Surface(1) = {1};

// Names are the contract with the case file.
Physical Surface("beam") = {1};
Physical Curve("support_left") = {2};
Physical Curve("support_right") = {4};
Physical Curve("load") = {8};
