// blocks_3d.geo: two blocks in contact, non-matching, for the 3D patch test (robin_contact).
// Body "upper" = (0,1)x(1,2)x(0,1), linear tetrahedra of size about h; body "lower" =
// (0,1)x(0,1)x(0,1), a transfinite n x n x n mesh of hexahedra, so the nodes of the two
// contact faces at y = 1 do not match. The bodies share no point, curve or surface (two
// OpenCASCADE boxes, not fragmented).
// Physical volumes "upper", "lower"; physical surfaces <body>_<side>, side one of x0, x1
// (x = 0, 1), bottom, top (the body's smallest and largest y), z0, z1 (z = 0, 1).
// Regenerate blocks_3d.msh with `make meshes` (gmsh -3).
SetFactory("OpenCASCADE");
h = 0.22;  n = 4;

Box(1) = {0, 0, 0, 1, 1, 1};     // lower: its faces 1..6 at x = 0, x = 1, y = 0, y = 1, z = 0, z = 1
Box(2) = {0, 1, 0, 1, 1, 1};     // upper: its faces 7..12, the same order
Transfinite Curve{1:12} = n + 1;
Transfinite Surface{1:6};
Recombine Surface{1:6};
Transfinite Volume{1};
MeshSize{PointsOf{Volume{2};}} = h;

Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
Physical Surface("lower_x0") = {1};
Physical Surface("lower_x1") = {2};
Physical Surface("lower_bottom") = {3};
Physical Surface("lower_top") = {4};
Physical Surface("lower_z0") = {5};
Physical Surface("lower_z1") = {6};
Physical Surface("upper_x0") = {7};
Physical Surface("upper_x1") = {8};
Physical Surface("upper_bottom") = {9};
Physical Surface("upper_top") = {10};
Physical Surface("upper_z0") = {11};
Physical Surface("upper_z1") = {12};
