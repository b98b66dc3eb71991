// plate_with_hole.geo: a rectangular plate with a central circular hole, pulled at both short ends
// (thesis §5.2, figure 5.10). Values below are defaults; plate_with_hole.yaml overrides them.
DefineConstant[
  L  = {0.10,  Name "Parameters/length along the load x [m]"},
  W  = {0.05,  Name "Parameters/width [m]"},
  a  = {0.005, Name "Parameters/hole radius [m]"},
  lc = {0.002, Name "Parameters/mesh size [m]"}
];

Point(1) = {0, 0, 0, lc};
Point(2) = {L, 0, 0, lc};
Point(3) = {L, W, 0, lc};
Point(4) = {0, W, 0, lc};
Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // right end
Line(3) = {3, 4};   // top
Line(4) = {4, 1};   // left end

// The hole, centred: four arcs so that gmsh can mesh it.
Point(5) = {L/2, W/2, 0, lc};
Point(6) = {L/2 + a, W/2, 0, lc};
Point(7) = {L/2, W/2 + a, 0, lc};
Point(8) = {L/2 - a, W/2, 0, lc};
Point(9) = {L/2, W/2 - a, 0, lc};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

// Names are the contract with the case file (pipeline/formats.md).
Physical Surface("plate") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Curve("hole") = {5, 6, 7, 8};
