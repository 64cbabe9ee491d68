// bench_paper_tri.geo: the paper's two-body scene (inputs/gmsh/paper.geo) as UNSTRUCTURED
// linear triangles, for bench/bench_gmsh.py (make bench-gmsh). Body 1 "upper" = (0,3)x(1,2),
// body 2 "lower" = (0,3)x(0,1); uniform size h in the upper body and ratio*h in the lower one
// (default ratio 1.07: the contact lines do not match, the mortar coupling is a real one).
// About 4/h^2 nodes in the upper body (measured, gmsh 4.8): h = 0.02 10k nodes (20k DOFs),
// 0.01 40k (80k DOFs), 0.005 159k (318k DOFs), 0.0025 636k (1.27M DOFs); the lower body 13% fewer. The bodies share no point. Physical names as in paper.geo:
// surfaces "upper", "lower"; curves <body>_left/right/top/bottom.
//   gmsh -2 -format msh41 -setnumber h 0.01 bench_paper_tri.geo -o bench_paper_tri_h0.01.msh
// Large meshes are not shipped: bench/bench_gmsh.py generates them in its work folder.
Geometry.AutoCoherence = 0;
If (!Exists(h))
  h = 0.02;
EndIf
If (!Exists(ratio))
  ratio = 1.07;
EndIf
hl = ratio * h;

// upper body
Point(1) = {0, 1, 0, h};  Point(2) = {3, 1, 0, h};  Point(3) = {3, 2, 0, h};  Point(4) = {0, 2, 0, h};
Line(1) = {1, 2};  Line(2) = {2, 3};  Line(3) = {3, 4};  Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
// lower body (its own points on y = 1)
Point(11) = {0, 0, 0, hl};  Point(12) = {3, 0, 0, hl};  Point(13) = {3, 1, 0, hl};  Point(14) = {0, 1, 0, hl};
Line(11) = {11, 12};  Line(12) = {12, 13};  Line(13) = {13, 14};  Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 1;
Mesh.Algorithm = 5;          // Delaunay: the fastest 2D algorithm for large uniform meshes

Physical Surface("upper") = {1};
Physical Surface("lower") = {2};
Physical Curve("upper_bottom") = {1};
Physical Curve("upper_right") = {2};
Physical Curve("upper_top") = {3};
Physical Curve("upper_left") = {4};
Physical Curve("lower_bottom") = {11};
Physical Curve("lower_right") = {12};
Physical Curve("lower_top") = {13};
Physical Curve("lower_left") = {14};
