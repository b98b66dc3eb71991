// plate_hole.geo: a plate L × W with a central circular hole of radius r, and a grip strip
// x ∈ [L − g, L] meshed as its own surface (tests/preprocess). Units: m.
DefineConstant[
  L = {0.1, Name "L"}, W = {0.05, Name "W"}, r = {0.01, Name "r"}, g = {0.01, Name "g"},
  lc = {0.002, Name "lc"}, lc_hole = {0.0005, Name "lc_hole"}
];
xc = (L - g) / 2; yc = W / 2;
Point(1) = {0, 0, 0, lc};
Point(2) = {L - g, 0, 0, lc};
Point(3) = {L, 0, 0, lc};
Point(4) = {L, W, 0, lc};
Point(5) = {L - g, W, 0, lc};
Point(6) = {0, W, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Line(5) = {5, 6}; Line(6) = {6, 1}; Line(7) = {2, 5};
Point(10) = {xc, yc, 0, lc_hole};
Point(11) = {xc + r, yc, 0, lc_hole};
Point(12) = {xc, yc + r, 0, lc_hole};
Point(13) = {xc - r, yc, 0, lc_hole};
Point(14) = {xc, yc - r, 0, lc_hole};
Circle(11) = {11, 10, 12}; Circle(12) = {12, 10, 13}; Circle(13) = {13, 10, 14}; Circle(14) = {14, 10, 11};
Curve Loop(1) = {1, 7, 5, 6};
Curve Loop(2) = {11, 12, 13, 14};
Curve Loop(3) = {2, 3, 4, -7};
Plane Surface(1) = {1, 2};
Plane Surface(2) = {3};
Physical Surface("plate") = {1, 2};
Physical Surface("main") = {1};
Physical Surface("grip") = {2};
Physical Curve("left") = {6};
Physical Curve("right") = {3};
Physical Curve("hole") = {11, 12, 13, 14};
Physical Point("origin") = {1};
