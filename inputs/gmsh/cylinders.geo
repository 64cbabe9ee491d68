// cylinders.geo: a steel cylinder pressed on an aluminium cylinder (robin_contact, units mm).
// Upper body: the lower half of a disc of radius 20 centred at (0, 20), split by its
// vertical axis into two quarters (ux = 0 on the axis holds its sideways motion and
// rotation); lower body: the upper half of a disc of radius 30 centred at (0, -30). They
// touch at the origin. Mesh size h within 2 mm of the contact point, growing to 3 mm.
// Physical surfaces "steel", "aluminium"; curves "steel_arc", "steel_top" (its flat side),
// "steel_axis" (inside the body), "alu_arc", "alu_bottom".
//   gmsh -2 -format msh41 -setnumber h 0.025 cylinders.geo -o cylinders.msh
Geometry.AutoCoherence = 0;
If (!Exists(h))
  h = 0.025;
EndIf
R1 = 20; R2 = 30; hmax = 3;

Point(1) = {0, R1, 0, hmax};  Point(2) = {-R1, R1, 0, hmax}; Point(3) = {0, 0, 0, h}; Point(4) = {R1, R1, 0, hmax};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4};
Line(3) = {4, 1}; Line(4) = {1, 3}; Line(5) = {1, 2};
Curve Loop(1) = {1, -4, 5};  Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4};   Plane Surface(2) = {2};

Point(11) = {0, -R2, 0, hmax}; Point(12) = {R2, -R2, 0, hmax}; Point(13) = {0, 0, 0, h}; Point(14) = {-R2, -R2, 0, hmax};
Circle(11) = {12, 11, 13}; Circle(12) = {13, 11, 14};
Line(13) = {14, 11}; Line(14) = {11, 12};
Curve Loop(3) = {11, 12, 13, 14}; Plane Surface(3) = {3};

Field[1] = Distance;
Field[1].PointsList = {3, 13};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = hmax;
Field[2].DistMin = 2;
Field[2].DistMax = 15;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("steel") = {1, 2};
Physical Surface("aluminium") = {3};
Physical Curve("steel_arc") = {1, 2};
Physical Curve("steel_top") = {3, 5};
Physical Curve("steel_axis") = {4};
Physical Curve("alu_arc") = {11, 12};
Physical Curve("alu_bottom") = {13, 14};
