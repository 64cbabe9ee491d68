// 18 unit blocks in 3 columns of 6, each its own surface (OpenCASCADE rectangles: no shared
// nodes), physical surfaces b1..b18, physical curves gathering the sides of all blocks, and a
// physical point on two corners: the file of test_gmsh's shared-read check.
SetFactory("OpenCASCADE");
For c In {0:2}
  For k In {1:6}
    i = 6*c + k;
    Rectangle(i) = {2*c, 6 - k, 0, 1, 1};
  EndFor
EndFor
For i In {1:18}
  Physical Surface(Sprintf("b%g", i)) = {i};
EndFor
Physical Curve("bottom") = {1:69:4};
Physical Curve("right") = {2:70:4};
Physical Curve("top") = {3:71:4};
Physical Curve("left") = {4:72:4};
Physical Point("corner") = {1, 21};
Transfinite Curve{1:56} = 3;
Transfinite Surface{1:14};
Recombine Surface{1:14};
Mesh.MeshSizeMax = 0.4;
