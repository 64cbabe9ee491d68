// Cattaneo-Mindlin in 3D, a half model (z >= 0; symmetry plane z = 0, which holds the
// tangential load's direction x): the lower half of a sphere of radius R = 1 centred at
// (0, 1, 0), touching at the origin the top y = 0 of a block [-2, 2] x [-2, 0] x [0, 2].
// Element size hc within rc of the contact point, growing to h away from it. With cap > 0
// the contact group sphere_arc is only the cap of that radius around the contact point.
// gmsh -3 -format msh41 -setnumber hc 0.01 cattaneo_sphere.geo
SetFactory("OpenCASCADE");
If (!Exists(hc))
  hc = 0.02;
EndIf
If (!Exists(rc))
  rc = 0.2;
EndIf
If (!Exists(h))
  h = 0.25;
EndIf
If (!Exists(cap))
  cap = 0;
EndIf
Sphere(1) = {0, 1, 0, 1};
Box(2) = {-1, 0, 0, 2, 1, 1};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {-2, -2, 0, 4, 2, 2};
e = 1e-6;
If (cap > 0)
  // the contact group only on the cap of radius cap around the contact point: the sphere
  // cut by the plane y = yc into the cap and the rest, meshed conforming as one body
  yc = 1 - Sqrt(1 - cap*cap);
  Box(5) = {-1, 0, 0, 2, yc, 1};
  BooleanIntersection(6) = { Volume{3}; }{ Volume{5}; };
  BooleanDifference(7) = { Volume{3}; Delete; }{ Volume{5}; Delete; };
  sv() = BooleanFragments{ Volume{6, 7}; Delete; }{};
  Physical Volume("sphere") = {sv()};
  Physical Volume("block") = {4};
  Physical Surface("sphere_top") = Surface In BoundingBox{-1 - e, 1 - e, -e, 1 + e, 1 + e, 1 + e};
  Physical Surface("sphere_z0") = Surface In BoundingBox{-1 - e, -e, -e, 1 + e, 1 + e, e};
  m = 0.1*cap;
  s_arc() = Surface In BoundingBox{-cap - m, -m, -m, cap + m, yc + m, cap + m};
  s_arc() -= Surface In BoundingBox{-1 - e, -e, -e, 1 + e, 1 + e, e};
  s_arc() -= Surface In BoundingBox{-1 - e, 0.99*yc, -e, 1 + e, 1.01*yc, 1 + e};
  Physical Surface("sphere_arc") = s_arc();
Else
  Physical Volume("sphere") = {3};
  Physical Volume("block") = {4};
  Physical Surface("sphere_top") = Surface In BoundingBox{-1 - e, 1 - e, -e, 1 + e, 1 + e, 1 + e};
  Physical Surface("sphere_z0") = Surface In BoundingBox{-1 - e, -e, -e, 1 + e, 1 + e, e};
  s_all() = Boundary{ Volume{3}; };
  s_arc() = s_all();
  s_arc() -= Surface In BoundingBox{-1 - e, 1 - e, -e, 1 + e, 1 + e, 1 + e};
  s_arc() -= Surface In BoundingBox{-1 - e, -e, -e, 1 + e, 1 + e, e};
  Physical Surface("sphere_arc") = s_arc();
EndIf
Physical Surface("block_top") = Surface In BoundingBox{-2 - e, -e, -e, 2 + e, e, 2 + e};
Physical Surface("block_bottom") = Surface In BoundingBox{-2 - e, -2 - e, -e, 2 + e, -2 + e, 2 + e};
Physical Surface("block_z0") = Surface In BoundingBox{-2 - e, -2 - e, -e, 2 + e, e, e};
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%g, %g + 0.3*Max(0, Sqrt(x*x + y*y + z*z) - %g))", h, hc, rc);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
