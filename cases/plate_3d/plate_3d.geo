// plate_3d.geo: a thick PMMA plate with a central through hole, pulled at both short ends: the 3D
// version of cases/plate_with_hole (thesis §5.2). Values below are defaults; plate_3d.yaml
// overrides them (geometry.parameters).
SetFactory("OpenCASCADE");
DefineConstant[
  L  = {0.04,  Name "Parameters/length along the load x [m]"},
  W  = {0.02,  Name "Parameters/width along y [m]"},
  T  = {0.003, Name "Parameters/thickness along z [m]"},
  a  = {0.003, Name "Parameters/hole radius [m]"},
  lc = {0.002, Name "Parameters/mesh size [m]"}
];

Box(1) = {0, 0, 0, L, W, T};
Cylinder(2) = {L/2, W/2, -T, 0, 0, 3*T, a};   // longer than the plate: a clean through hole
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.CharacteristicLengthMax = lc;
// The lattice fills what the mesh covers: 24 elements around the hole keep its faceted wall within
// 0.03 mm (a(1 − cos 7.5°)) of the circle instead of 0.17 mm at lc.
Mesh.MeshSizeFromCurvature = 24;

// The two ends, found by where they are (OpenCASCADE numbers the faces of a boolean itself).
e = 1e-6;
left() = Surface In BoundingBox{-e, -e, -e, e, W + e, T + e};
right() = Surface In BoundingBox{L - e, -e, -e, L + e, W + e, T + e};

// Names are the contract with the case file (pipeline/formats.md): the volume is the block.
Physical Volume("plate") = {3};
Physical Surface("left") = {left()};
Physical Surface("right") = {right()};
