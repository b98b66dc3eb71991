// impact.geo: the 2D impact of the thesis (§5.4): a rigid-ish disk projectile ("projectile")
// above a thin plate ("plate") whose two ends ("left", "right") are clamped.
// Values below are defaults; impact.yaml overrides them (geometry.parameters).
DefineConstant[
  W   = {0.04,   Name "Parameters/plate width [m]"},
  H   = {0.003,  Name "Parameters/plate depth [m]"},
  R   = {0.0025, Name "Parameters/projectile radius [m]"},
  gap = {0.0006, Name "Parameters/gap between projectile and plate [m] (> horizon)"},
  lc  = {0.001,  Name "Parameters/mesh size [m]"}
];

// The plate.
Point(1) = {0, 0, 0, lc};
Point(2) = {W, 0, 0, lc};
Point(3) = {W, H, 0, lc};
Point(4) = {0, H, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// The projectile: a disk of radius R centred gap + R above the middle of the plate.
yc = H + gap + R;
Point(5) = {W/2, yc, 0, lc};
Point(6) = {W/2 + R, yc, 0, lc};
Point(7) = {W/2, yc + R, 0, lc};
Point(8) = {W/2 - R, yc, 0, lc};
Point(9) = {W/2, yc - R, 0, lc};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};

// Names are the contract with the case file (pipeline/formats.md): each surface is a block.
Physical Surface("plate") = {1};
Physical Surface("projectile") = {2};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
