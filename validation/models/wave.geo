// bar.geo: a rectangle Lx × H for the validation-only runs of validation/ (wave speed, static
// tension). With H = dx the lattice holds a single row of nodes: the 1D chain of docs/theory.md C2.
DefineConstant[
  Lx = {0.1,   Name "Parameters/length [m]"},
  H  = {0.001, Name "Parameters/height [m]"},
  lc = {0.001, Name "Parameters/mesh size [m]"}
];
Point(1) = {0, 0, 0, lc};
Point(2) = {Lx, 0, 0, lc};
Point(3) = {Lx, H, 0, lc};
Point(4) = {0, H, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("bar") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Curve("bottom") = {1};
Physical Curve("top") = {3};
