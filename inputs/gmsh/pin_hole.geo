// pin_hole.geo: a steel pin in the bore of an aluminium plate (robin_contact, units mm).
// The pin is a ring (outer radius 10, inner radius 5) centred at the origin; the plate is
// the square (-30,30)x(-30,30) with a bore of radius 10.02 (clearance 0.02 mm), clamped on
// its bottom side. Both rims are whole circles: the contact groups are closed loops.
// The ring is split by its vertical axis (two segments inside the body), so that ux = 0
// on them holds its sideways motion and rotation and leaves the vertical motion to the
// contact. Physical surfaces "pin", "plate"; curves "pin_rim" (the pin's outer circle),
// "pin_bore_low" (lower half of its inner circle, where the shaft's load comes in),
// "pin_bore_high", "pin_axis" (the two axis segments), "bore" (the plate's hole),
// "plate_bottom", "plate_top", "plate_left", "plate_right".
//   gmsh -2 -format msh41 -setnumber h 0.5 pin_hole.geo -o pin_hole.msh
If (!Exists(h))
  h = 0.5;       // mesh size along the contact rims
EndIf
r = 10; ri = 5; rb = 10.02; L = 30;
hmax = 4;

Point(1) = {0, 0, 0, h};
// pin: outer rim points (right, top, left, bottom), inner rim points
Point(2) = {r, 0, 0, h};   Point(3) = {0, r, 0, h};   Point(4) = {-r, 0, 0, h};  Point(5) = {0, -r, 0, h};
Point(6) = {ri, 0, 0, h};  Point(7) = {0, ri, 0, h};  Point(8) = {-ri, 0, 0, h}; Point(9) = {0, -ri, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 8}; Circle(7) = {8, 1, 9}; Circle(8) = {9, 1, 6};
Line(9) = {7, 3};          // axis, top segment
Line(10) = {9, 5};         // axis, bottom segment
Curve Loop(1) = {-10, 8, 5, 9, -1, -4};    // right half: bottom axis up... ring right
Plane Surface(1) = {1};
Curve Loop(2) = {-9, 6, 7, 10, -3, -2};    // left half
Plane Surface(2) = {2};

// plate with its bore
Point(11) = {rb, 0, 0, h}; Point(12) = {0, rb, 0, h}; Point(13) = {-rb, 0, 0, h}; Point(14) = {0, -rb, 0, h};
Circle(11) = {11, 1, 12}; Circle(12) = {12, 1, 13}; Circle(13) = {13, 1, 14}; Circle(14) = {14, 1, 11};
Point(21) = {-L, -L, 0, hmax}; Point(22) = {L, -L, 0, hmax}; Point(23) = {L, L, 0, hmax}; Point(24) = {-L, L, 0, hmax};
Line(21) = {21, 22}; Line(22) = {22, 23}; Line(23) = {23, 24}; Line(24) = {24, 21};
Curve Loop(3) = {21, 22, 23, 24};
Curve Loop(4) = {11, 12, 13, 14};
Plane Surface(3) = {3, 4};

Mesh.MeshSizeExtendFromBoundary = 1;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("pin") = {1, 2};
Physical Surface("plate") = {3};
Physical Curve("pin_rim") = {1, 2, 3, 4};
Physical Curve("pin_bore_low") = {7, 8};
Physical Curve("pin_bore_high") = {5, 6};
Physical Curve("pin_axis") = {9, 10};
Physical Curve("bore") = {11, 12, 13, 14};
Physical Curve("plate_bottom") = {21};
Physical Curve("plate_right") = {22};
Physical Curve("plate_top") = {23};
Physical Curve("plate_left") = {24};
