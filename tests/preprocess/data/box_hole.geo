// box_hole.geo: a box L × W × H with a cylindrical hole of radius r through its thickness
// (tests/preprocess). Units: m.
SetFactory("OpenCASCADE");
DefineConstant[
  L = {0.04, Name "L"}, W = {0.02, Name "W"}, H = {0.01, Name "H"}, r = {0.004, Name "r"},
  lc = {0.002, Name "lc"}, lc_hole = {0.0007, Name "lc_hole"}
];
Box(1) = {0, 0, 0, L, W, H};
Cylinder(2) = {L / 2, W / 2, 0, 0, 0, H, r};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
e = 1e-6;
Physical Volume("body") = {3};
Physical Surface("bottom") = Surface In BoundingBox{-e, -e, -e, L + e, W + e, e};
hole() = Surface In BoundingBox{L/2 - r - e, W/2 - r - e, -e, L/2 + r + e, W/2 + r + e, H + e};
Physical Surface("hole") = {hole()};
Physical Curve("edge") = Curve In BoundingBox{-e, -e, -e, e, e, H + e};
MeshSize{ PointsOf{ Volume{3}; } } = lc;
MeshSize{ PointsOf{ Surface{hole()}; } } = lc_hole;
