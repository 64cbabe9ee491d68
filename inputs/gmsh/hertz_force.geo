// hertz_force.geo: Hertz contact of a half-disc on a block, geometry for force control
// (robin_contact). As hertz.geo (disc of centre (0,2) and radius R = 1, lower half, curved
// side down, touching the block (-4,4)x(-3,1) at (0,1); linear TRIANGLES of size h within
// 0.25 of (0,1), growing to R/4 at distance 2; the bodies share no point), but the disc is
// split by its symmetry axis x = 0 into two quarter-discs, so that the axis from (0,1) to
// (0,2) is a mesh line: ux = 0 on it holds the disc's horizontal motion and rotation and
// leaves its vertical translation free, to be held by a force or by uy at one point.
// Physical surfaces "disc" (both quarters), "block"; physical curves "disc_top" (flat side,
// both halves), "disc_arc" (curved side), "disc_axis" (the axis, inside the disc),
// "block_top", "block_bottom", "block_left", "block_right"; physical point "disc_centre"
// (the centre (0,2): top of the axis, middle of the flat side; a node of the disc's mesh).
// `make meshes` writes hertz_force_h0.04.msh ... hertz_force_h0.005.msh (`make bench-hertz`
// meshes it finer, with -setnumber dmin 0.1):
//   gmsh -2 -format msh41 -setnumber h 0.02 hertz_force.geo -o hertz_force_h0.02.msh
Geometry.AutoCoherence = 0;
If (!Exists(h))
  h = 0.02;   // mesh size at the contact point
EndIf
If (!Exists(dmin))
  dmin = 0.25;   // the size h holds within this distance of the contact point
EndIf
R = 1;
hmax = R/4;

// disc: two quarter-discs sharing the axis (line 4)
Point(1) = {0, 1 + R, 0, hmax};      // centre
Point(2) = {-R, 1 + R, 0, hmax};
Point(3) = {0, 1, 0, h};             // lowest point
Point(4) = {R, 1 + R, 0, hmax};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 1};                    // flat side, right half
Line(4) = {1, 3};                    // the axis, from the centre down to the lowest point
Line(5) = {1, 2};                    // flat side, left half
Curve Loop(1) = {1, -4, 5};          // left quarter: arc, axis up, flat side
Plane Surface(1) = {1};
Curve Loop(3) = {2, 3, 4};           // right quarter: arc, flat side, axis down
Plane Surface(3) = {3};

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
Field[2].DistMin = dmin;
Field[2].DistMax = 2;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("disc") = {1, 3};
Physical Surface("block") = {2};
Physical Curve("disc_top") = {3, 5};
Physical Curve("disc_arc") = {1, 2};
Physical Curve("disc_axis") = {4};
Physical Curve("block_top") = {13, 14};
Physical Curve("block_bottom") = {11};
Physical Curve("block_left") = {15};
Physical Curve("block_right") = {12};
Physical Point("disc_centre") = {1};
