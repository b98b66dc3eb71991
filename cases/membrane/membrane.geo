// membrane.geo: a square membrane, clamped on its four sides, with a central disk
// ("centre") that the case file sets in motion (thesis §5.1, figure 5.1).
// Values below are defaults; membrane.yaml overrides them (geometry.parameters).
DefineConstant[
  L  = {0.05,  Name "Parameters/side length [m]"},
  r  = {0.006, Name "Parameters/centre disk radius [m]"},
  lc = {0.002, Name "Parameters/mesh size [m]"}
];

Point(1) = {0, 0, 0, lc};
Point(2) = {L, 0, 0, lc};
Point(3) = {L, L, 0, lc};
Point(4) = {0, L, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};

// The centre disk, built from four arcs so that gmsh can mesh it.
Point(5) = {L/2, L/2, 0, lc};
Point(6) = {L/2 + r, L/2, 0, lc};
Point(7) = {L/2, L/2 + r, 0, lc};
Point(8) = {L/2 - r, L/2, 0, lc};
Point(9) = {L/2, L/2 - r, 0, lc};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};   // the membrane around the disk
Plane Surface(2) = {2};      // the disk

// Names are the contract with the case file (pipeline/formats.md).
Physical Surface("membrane") = {1, 2};
Physical Surface("centre") = {2};
Physical Curve("clamped") = {1, 2, 3, 4};
