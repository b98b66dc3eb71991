// branching.geo: the dynamic crack-branching plate of Bobaru & Zhang (2015) (docs/theory.md C7):
// a 100 mm × 40 mm soda-lime glass plate with a 50 mm notch along its mid-line from the left
// edge (the notch is a pre-crack in branching.yaml, not a hole in the geometry), pulled by a
// traction on its top and bottom edges. Values below are defaults; branching.yaml overrides them.
DefineConstant[
  L  = {0.10,  Name "Parameters/length [m]"},
  H  = {0.04,  Name "Parameters/height [m]"},
  lc = {0.002, Name "Parameters/mesh size [m]"}
];

Point(1) = {0, 0, 0, lc};
Point(2) = {L, 0, 0, lc};
Point(3) = {L, H, 0, lc};
Point(4) = {0, H, 0, lc};
Line(1) = {1, 2};   // bottom edge
Line(2) = {2, 3};
Line(3) = {3, 4};   // top edge
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Names are the contract with the case file. The loaded edges appear twice: "top"/"bottom" (the
// edge row, which carries the traction) and "top_band"/"bottom_band" (a layer as deep as the
// horizon, whose bonds do not break).
Physical Surface("glass") = {1};
Physical Curve("top") = {3};
Physical Curve("bottom") = {1};
Physical Curve("top_band") = {3};
Physical Curve("bottom_band") = {1};
