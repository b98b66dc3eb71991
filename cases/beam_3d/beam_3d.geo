// beam_3d.geo: a notched PMMA beam in three-point bending, in 3D: the side profile of
// cases/three_point_bending (span S = 4W, support and load patches 2·p long) extruded through
// the thickness B along z. The notch is a pre-crack in the .yaml (`cracks:`), not a hole in the
// geometry. Values below are defaults; beam_3d.yaml overrides them (geometry.parameters).
DefineConstant[
  L  = {0.20,  Name "Parameters/beam length [m]"},
  W  = {0.04,  Name "Parameters/beam depth W along y [m]"},
  B  = {0.016, Name "Parameters/beam thickness B along z [m]"},
  S  = {0.16,  Name "Parameters/span S between the supports [m]"},
  p  = {0.002, Name "Parameters/half-width of the support and load patches [m]"},
  lc = {0.004, Name "Parameters/mesh size [m]"}
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

// Extruded through the thickness: out[0] is the far face, out[1] the volume, out[2 + k] the side
// face swept by line k + 1.
out[] = Extrude {0, 0, B} { Surface{1}; };

// Names are the contract with the case file: the volume is the block, the patches are faces.
Physical Volume("beam") = {out[1]};
Physical Surface("support_left") = {out[3]};
Physical Surface("support_right") = {out[5]};
Physical Surface("load") = {out[9]};
