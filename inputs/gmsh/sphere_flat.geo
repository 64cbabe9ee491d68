// sphere_flat.geo: a sphere pressed on a flat, axisymmetric (robin_contact, &scene plane =
// 'axisymmetric': x = r >= 0, y = z). Body "sphere": the meridian section of the lower half of
// the sphere of centre (0, R) and radius R = 1, its quarter disc [0, R] x ..., touching the
// block at the origin. Body "block": the section [0, 4] x [-4, 0] of a cylinder wide and deep
// compared with the contact radius (about 0.1). Linear triangles, size h within 0.2 of the
// contact point on both bodies, growing to R/4 at distance 2. Each body has its own node at
// the origin (they share no point).
// Physical surfaces "sphere", "block"; physical curves "sphere_top" (the equator plane z = R),
// "sphere_arc" (the surface), "sphere_axis", "block_top", "block_bottom", "block_axis",
// "block_side".
// `make meshes` writes sphere_flat_h0.02.msh, _h0.01.msh, _h0.005.msh:
//   gmsh -2 -format msh41 -setnumber h 0.01 sphere_flat.geo -o sphere_flat_h0.01.msh
Geometry.AutoCoherence = 0;
If (!Exists(h))
  h = 0.01;   // mesh size at the contact point
EndIf
R = 1;
hmax = R/4;

Point(1) = {0, R, 0, hmax};          // centre, on the axis
Point(2) = {0, 0, 0, h};             // lowest point
Point(3) = {R, R, 0, hmax};          // equator
Circle(1) = {2, 1, 3};
Line(2) = {3, 1};
Line(3) = {1, 2};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

Point(11) = {0, -4, 0, hmax};  Point(12) = {4, -4, 0, hmax};
Point(13) = {4, 0, 0, hmax};   Point(14) = {0, 0, 0, h};
Line(11) = {11, 12};  Line(12) = {12, 13};  Line(13) = {13, 14};  Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

Field[1] = Distance;
Field[1].PointsList = {2, 14};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = hmax;
Field[2].DistMin = 0.2;
Field[2].DistMax = 2;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("sphere") = {1};
Physical Surface("block") = {2};
Physical Curve("sphere_arc") = {1};
Physical Curve("sphere_top") = {2};
Physical Curve("sphere_axis") = {3};
Physical Curve("block_bottom") = {11};
Physical Curve("block_side") = {12};
Physical Curve("block_top") = {13};
Physical Curve("block_axis") = {14};
