// cattaneo_disc.geo: a half-disc on a block for Cattaneo-Mindlin (robin_contact,
// tools/cattaneo_study.py --scene disc).
// Body "disc": the lower half of the disc of centre (0,R) and radius R (curved side down, flat
// side on y = R), touching the block at (0,0). Body "block" = (-L,L)x(-D,0). The bodies share no
// point (each has its own node at (0,0)). Quadrangles: under the contact, in each body, a
// structured patch of squares of size h = ac/n over |x| < 1.5 ac and 1.5 ac deep (bounded by the
// contact arc in the disc), the same divisions on both contact curves; elsewhere recombined
// triangles of size h at distance 1.5 ac from the contact point, growing by g per unit distance
// to R/4. The contact half-width is about ac, so n is the resolution of the contact and the mesh
// stays small however small ac/R is.
// Physical surfaces "disc", "block"; physical curves "disc_top" (flat side), "disc_contact"
// (the arc over |x| < 1.5 ac), "disc_arc" (the rest of the curved side), "block_contact" (the
// block's top over |x| < 1.5 ac), "block_top" (the rest of the top), "block_bottom",
// "block_left", "block_right"; physical point "disc_centre" (the middle of the flat side).
// `make meshes` writes cattaneo_disc_a8.msh, cattaneo_disc_a16.msh, cattaneo_disc_a32.msh
// (ac = 0.005):
//   gmsh -2 -format msh41 -setnumber n 16 cattaneo_disc.geo -o cattaneo_disc_a16.msh
Geometry.AutoCoherence = 0;
If (!Exists(R))
  R = 1;
EndIf
If (!Exists(ac))
  ac = 0.005;     // the contact half-width aimed at
EndIf
If (!Exists(n))
  n = 8;          // ac / h, h the mesh size over the contact
EndIf
h = ac / n;
If (!Exists(L))
  L = 4 * R;      // the block's half-width
EndIf
If (!Exists(D))
  D = 4 * R;      // the block's depth
EndIf
If (!Exists(g))
  g = 0.25;       // size growth per unit distance away from the contact
EndIf
hmax = R / 4;
xc = 1.5 * ac;    // end of the contact groups
yb = 1.5 * ac;    // depth of the structured patches
yc = R - Sqrt(R^2 - xc^2);

// a structured patch of uniform squares h under the contact in each body: |x| < xc, depth yb
nc = Ceil(xc / h);              // divisions of each half of a contact curve
ny = Ceil(yb / h);              // divisions across a patch
yt = yc + yb;

// disc: its patch is bounded by the contact arc below and y = yt above
Point(1) = {0, R, 0};              // centre
Point(2) = {-R, R, 0};
Point(3) = {-xc, yc, 0};
Point(4) = {0, 0, 0};              // lowest point
Point(5) = {xc, yc, 0};
Point(6) = {R, R, 0};
Point(7) = {0, R, 0};              // the middle of the flat side
Point(8) = {-xc, yt, 0};
Point(9) = {xc, yt, 0};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 6};
Line(5) = {6, 7};
Line(6) = {7, 2};
Line(7) = {3, 8};
Line(8) = {8, 9};
Line(9) = {9, 5};
Curve Loop(1) = {1, 7, 8, 9, 4, 5, 6};
Plane Surface(1) = {1};
Curve Loop(3) = {2, 3, -9, -8, -7};
Plane Surface(3) = {3};
Transfinite Curve{2, 3} = nc + 1;
Transfinite Curve{8} = 2 * nc + 1;
Transfinite Curve{7, 9} = ny + 1;
Transfinite Surface{3} = {3, 5, 9, 8};

// block, with a point of its own at the contact point; its patch down to y = -yb
Point(11) = {-L, -D, 0};  Point(12) = {L, -D, 0};  Point(13) = {L, 0, 0};
Point(14) = {xc, 0, 0};   Point(15) = {0, 0, 0};   Point(16) = {-xc, 0, 0};  Point(17) = {-L, 0, 0};
Point(18) = {xc, -yb, 0}; Point(19) = {-xc, -yb, 0};
Line(11) = {11, 12};  Line(12) = {12, 13};  Line(13) = {13, 14};  Line(14) = {14, 15};
Line(15) = {15, 16};  Line(16) = {16, 17};  Line(17) = {17, 11};
Line(18) = {14, 18};  Line(19) = {18, 19};  Line(20) = {19, 16};
Curve Loop(2) = {11, 12, 13, 18, 19, 20, 16, 17};
Plane Surface(2) = {2};
Curve Loop(4) = {14, 15, -20, -19, -18};
Plane Surface(4) = {4};
Transfinite Curve{14, 15} = nc + 1;
Transfinite Curve{19} = 2 * nc + 1;
Transfinite Curve{18, 20} = ny + 1;
Transfinite Surface{4} = {14, 16, 19, 18};

// size away from the patches: h at the contact point's distance xc, growing by g per unit
// distance to hmax
Field[1] = Distance;
Field[1].PointsList = {4, 15};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = hmax;
Field[2].DistMin = xc;
Field[2].DistMax = xc + (hmax - h) / g;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;               // frontal-Delaunay, then recombined (8 crashes gmsh 4.8.4)
Mesh.RecombinationAlgorithm = 1;
Recombine Surface{1, 2, 3, 4};

Physical Surface("disc") = {1, 3};
Physical Surface("block") = {2, 4};
Physical Curve("disc_top") = {5, 6};
Physical Curve("disc_contact") = {2, 3};
Physical Curve("disc_arc") = {1, 4};
Physical Curve("block_contact") = {14, 15};
Physical Curve("block_top") = {13, 16};
Physical Curve("block_bottom") = {11};
Physical Curve("block_left") = {17};
Physical Curve("block_right") = {12};
Physical Point("disc_centre") = {7};
