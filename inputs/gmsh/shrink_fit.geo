// shrink_fit.geo: a solid shaft shrink-fitted in a ring (robin_contact, SI units, plane strain).
// A quarter of each, symmetric about x = 0 and y = 0: the shaft of radius b + delta, the ring
// of inner radius b and outer radius c, overlapping by the radial interference delta along
// the arcs. Lame's solution gives the contact pressure (doc/geometry.md, "Interference fits").
// Mesh with:  gmsh -2 -format msh41 -setnumber h 0.00125 shrink_fit.geo -o shrink_fit.msh
If (!Exists(b)) b = 0.05; EndIf          // nominal radius of the fit [m]
If (!Exists(c)) c = 0.1; EndIf           // outer radius of the ring [m]
If (!Exists(delta)) delta = 5e-5; EndIf  // radial interference, 1e-3 b [m]
If (!Exists(h)) h = 0.00125; EndIf       // element size [m]
rs = b + delta;
Point(1) = {0, 0, 0, h};
Point(2) = {rs, 0, 0, h};
Point(3) = {0, rs, 0, h};
Point(4) = {b, 0, 0, h};
Point(5) = {c, 0, 0, h};
Point(6) = {0, c, 0, h};
Point(7) = {0, b, 0, h};
Line(1) = {1, 2};
Circle(2) = {2, 1, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Line(4) = {4, 5};
Circle(5) = {5, 1, 6};
Line(6) = {6, 7};
Circle(7) = {7, 1, 4};
Curve Loop(2) = {4, 5, 6, 7};
Plane Surface(2) = {2};
Physical Surface("shaft") = {1};
Physical Surface("ring") = {2};
Physical Curve("shaft_y0") = {1};     // symmetry: uy = 0
Physical Curve("shaft_arc") = {2};    // the shaft's contact surface
Physical Curve("shaft_x0") = {3};     // symmetry: ux = 0
Physical Curve("ring_y0") = {4};
Physical Curve("ring_out") = {5};
Physical Curve("ring_x0") = {6};
Physical Curve("ring_arc") = {7};     // the ring's bore
// the arcs divided alike (their nodes face each other) and the ring structured
na = Ceil(Pi*b/(2*h)) + 1;
nr = Ceil((c - b)/h) + 1;
Transfinite Curve{2, 5, 7} = na;
Transfinite Curve{4, 6} = nr;
Transfinite Surface{2};
Mesh.Algorithm = 6;                   // frontal-Delaunay, then recombined (8 crashes gmsh 4.8)
Mesh.RecombinationAlgorithm = 1;
Recombine Surface{1, 2};
