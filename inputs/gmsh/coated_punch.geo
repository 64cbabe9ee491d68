// coated_punch.geo: a block of aluminium with a hard coating, for a flat punch (robin_contact,
// SI units, plane strain). Half of it, symmetric about x = 0: the substrate [0, L] x [-H, 0]
// and the coating [0, L] x [0, tc], bonded (they share the nodes of y = 0). The body is the
// physical surface "block" (both), the coating the region "coating" (doc/physics.md).
// Mesh with:  gmsh -2 -format msh41 -setnumber h 0.00025 coated_punch.geo -o coated_punch.msh
If (!Exists(L)) L = 0.01; EndIf          // half-width of the block [m]
If (!Exists(H)) H = 0.008; EndIf         // depth of the substrate [m]
If (!Exists(tc)) tc = 0.0005; EndIf      // coating thickness [m]
If (!Exists(h)) h = 0.00025; EndIf       // element size near the punch [m]
Point(1) = {0, -H, 0, 8*h};
Point(2) = {L, -H, 0, 8*h};
Point(3) = {L, 0, 0, 4*h};
Point(4) = {0, 0, 0, h};
Point(5) = {L, tc, 0, 4*h};
Point(6) = {0, tc, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {3, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(2) = {2};
Physical Surface("block") = {1, 2};
Physical Surface("coating") = {2};
Physical Curve("block_bottom") = {1};
Physical Curve("block_axis") = {4, 7};
Physical Curve("block_top") = {6};
// the coating at least two cells thick, its top graded towards the punch
Transfinite Curve{5, 7} = Max(3, Ceil(2*tc/h) + 1);
Transfinite Curve{3, 6} = Ceil(L/h/2) + 1 Using Progression 0.93;
Transfinite Surface{2};
Mesh.Algorithm = 6;                     // frontal-Delaunay, then recombined (8 crashes gmsh 4.8)
Mesh.RecombinationAlgorithm = 1;
Recombine Surface{1, 2};
