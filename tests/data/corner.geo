// A block in the inner corner of an L-shaped bracket (units m): the bracket (physical surface
// 'bracket', its base 'base', its inner faces 'floor' and 'wall') and the block ('block', sides
// 'block_bottom', 'block_right', 'block_top', 'block_left'), quadrilaterals of about 0.1.
// tests/system/test_assemblies.py poses two contact pairs between the block and the bracket.
// gmsh -2 -format msh41 corner.geo -o corner.msh
h = 0.1;
// L-shaped bracket: outer (0,0)-(2,0)-(2,0.5)-(0.5,0.5)-(0.5,2)-(0,2)
Point(1) = {0,0,0,h}; Point(2) = {2,0,0,h}; Point(3) = {2,0.5,0,h};
Point(4) = {0.5,0.5,0,h}; Point(5) = {0.5,2,0,h}; Point(6) = {0,2,0,h};
Line(1) = {1,2}; Line(2) = {2,3}; Line(3) = {3,4}; Line(4) = {4,5}; Line(5) = {5,6}; Line(6) = {6,1};
Curve Loop(1) = {1,2,3,4,5,6}; Plane Surface(1) = {1};
Physical Surface("bracket") = {1};
Physical Curve("base") = {1};
Physical Curve("floor") = {3};
Physical Curve("wall") = {4};
// block in the corner: (0.5,0.5)-(1.3,1.3)
Point(11) = {0.5,0.5,0,h}; Point(12) = {1.3,0.5,0,h}; Point(13) = {1.3,1.3,0,h}; Point(14) = {0.5,1.3,0,h};
Line(11) = {11,12}; Line(12) = {12,13}; Line(13) = {13,14}; Line(14) = {14,11};
Curve Loop(2) = {11,12,13,14}; Plane Surface(2) = {2};
Physical Surface("block") = {2};
Physical Curve("block_bottom") = {11};
Physical Curve("block_left") = {14};
Physical Curve("block_top") = {13};
Physical Curve("block_right") = {12};
Recombine Surface{1,2};
Mesh.RecombinationAlgorithm = 1;
