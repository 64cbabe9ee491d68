// hertz.geo: Hertz contact of a half-disc on a block (robin_contact).
// Body "disc": the lower half of the disc of centre (0,2) and radius R = 1 (curved side
// down, flat side on y = 2), touching the block at (0,1). Body "block" = (-4,4)x(-3,1),
// wide and deep compared with the contact half-width (about 0.1-0.2). Linear TRIANGLES,
// refined near the contact point on both bodies: size h within 0.25 of (0,1), growing to
// R/4 at distance 2. The bodies share no point (each has its own node at (0,1)).
// Physical surfaces "disc", "block"; physical curves "disc_top" (flat side), "disc_arc"
// (curved side), "block_top", "block_bottom", "block_left", "block_right".
// `make meshes` writes hertz_h0.04.msh, hertz_h0.02.msh, hertz_h0.01.msh, hertz_h0.005.msh:
//   gmsh -2 -format msh41 -setnumber h 0.02 hertz.geo -o hertz_h0.02.msh
Geometry.AutoCoherence = 0;
If (!Exists(h))
  h = 0.02;   // mesh size at the contact point
EndIf
R = 1;
hmax = R/4;

// disc
Point(1) = {0, 1 + R, 0, hmax};      // centre
Point(2) = {-R, 1 + R, 0, hmax};
Point(3) = {0, 1, 0, h};             // lowest point
Point(4) = {R, 1 + R, 0, hmax};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 2};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

// block, with a point of its own at the contact point
Point(11) = {-4, -3, 0, hmax};  Point(12) = {4, -3, 0, hmax};
Point(13) = {4, 1, 0, hmax};    Point(14) = {0, 1, 0, h};   Point(15) = {-4, 1, 0, hmax};
Line(11) = {11, 12};  Line(12) = {12, 13};  Line(13) = {13, 14};  Line(14) = {14, 15};
Line(15) = {15, 11};
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

// size: h near the contact point, growing to hmax
Field[1] = Distance;
Field[1].PointsList = {3, 14};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = hmax;
Field[2].DistMin = 0.25;
Field[2].DistMax = 2;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("disc") = {1};
Physical Surface("block") = {2};
Physical Curve("disc_top") = {3};
Physical Curve("disc_arc") = {1, 2};
Physical Curve("block_top") = {13, 14};
Physical Curve("block_bottom") = {11};
Physical Curve("block_left") = {15};
Physical Curve("block_right") = {12};
