// patch_mixed.geo: patch.geo with the top body recombined by the simple algorithm, which leaves
// some triangles among the quadrangles: a mixed P1/Q1 body (robin_contact).
// Body "top" = (0,1)x(1,1.5), linear triangles of size about 1/7 (7 edges on its bottom);
// body "bottom" = (0,1)x(0,1), a transfinite 5x5 recombined quadrangle mesh (size 1/5), so
// the nodes of the two contact lines do not match. The bodies share no point or curve.
// Physical surfaces "top", "bottom"; physical curves <body>_top/bottom/left/right.
// Regenerate patch.msh with `make meshes`.
Geometry.AutoCoherence = 0;
ht = 1/7;  nb = 5;

Point(1) = {0, 1, 0, ht};  Point(2) = {1, 1, 0, ht};  Point(3) = {1, 1.5, 0, ht};  Point(4) = {0, 1.5, 0, ht};
Line(1) = {1, 2};  Line(2) = {2, 3};  Line(3) = {3, 4};  Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1} = 8;     // 7 edges on the contact line

Point(5) = {0, 0, 0};  Point(6) = {1, 0, 0};  Point(7) = {1, 1, 0};  Point(8) = {0, 1, 0};
Line(5) = {5, 6};  Line(6) = {6, 7};  Line(7) = {7, 8};  Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};
Transfinite Curve{5, 6, 7, 8} = nb + 1;
Transfinite Surface{2} = {5, 6, 7, 8};
Recombine Surface{1, 2};
Mesh.RecombinationAlgorithm = 0;

Physical Surface("top") = {1};
Physical Surface("bottom") = {2};
Physical Curve("top_bottom") = {1};
Physical Curve("top_right") = {2};
Physical Curve("top_top") = {3};
Physical Curve("top_left") = {4};
Physical Curve("bottom_bottom") = {5};
Physical Curve("bottom_right") = {6};
Physical Curve("bottom_top") = {7};
Physical Curve("bottom_left") = {8};
