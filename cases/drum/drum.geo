// drum.geo: a square membrane of free side L inside a clamping frame of width w (the "clamped"
// layer, as deep as the horizon), so that the vibrating span is exactly L between the frame's
// inner edges. drum.yaml pre-strains it and sets it vibrating out of plane.
// Values below are defaults; drum.yaml overrides them (geometry.parameters).
DefineConstant[
  L  = {0.05,   Name "Parameters/free side length [m]"},
  w  = {0.0015, Name "Parameters/clamping frame width [m]"},
  lc = {0.002,  Name "Parameters/mesh size [m]"}
];

S = L + 2*w;   // outer side
Point(1) = {0, 0, 0, lc};
Point(2) = {S, 0, 0, lc};
Point(3) = {S, S, 0, lc};
Point(4) = {0, S, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Names are the contract with the case file (pipeline/formats.md).
Physical Surface("membrane") = {1};
Physical Curve("clamped") = {1, 2, 3, 4};   // with node_sets.clamped.layer = w: the frame
