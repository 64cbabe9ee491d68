// paper.geo: the paper's two-body scene as a Gmsh model (robin_contact).
// Body 1 "upper" = (0,3)x(1,2) on body 2 "lower" = (0,3)x(0,1), each a 24x16 quadrangle
// mesh, nodes on the uniform grid (a transfinite mesh in effect). Each body is a
// structured grid made by extruding a point, then the line, with Layers (its nodes are on
// the uniform grid to rounding, unlike a transfinite mesh's, which are off by ~1e-12).
// The bodies share no point or curve. Physical surfaces "upper", "lower"; physical curves
// <body>_left/right/top/bottom; the points on y = 1 are duplicated, so each body has its own
// nodes. Regenerate paper.msh with `make meshes` (gmsh -2 -format msh41 paper.geo -o paper.msh).
// The upper body is built at y = 11..12, the duplicate points of each extrusion merged
// (Coherence), then it is moved down: no automatic merging (AutoCoherence = 0) keeps the
// duplicate points on y = 1 apart.
Geometry.AutoCoherence = 0;
nu = 24;  nl = 24;   // cells along x in the upper and lower body (16 along y)

// upper body: bottom line, then the surface swept up from it
Point(1) = {0, 11, 0};
ub[] = Extrude {3, 0, 0} { Point{1}; Layers{nu}; };
us[] = Extrude {0, 1, 0} { Curve{ub[1]}; Layers{2*nu/3}; Recombine; };
// lower body
Point(101) = {0, 0, 0};
lb[] = Extrude {3, 0, 0} { Point{101}; Layers{nl}; };
ls[] = Extrude {0, 1, 0} { Curve{lb[1]}; Layers{2*nl/3}; Recombine; };
Coherence;
Translate {0, -10, 0} { Surface{us[1]}; }

// Extrude returns {top curve, surface, the curves swept from the line's end points}: [2] is
// the right side, [3] the left one
// (reversed: Gmsh writes its physical tag negative)
Physical Surface("upper") = {us[1]};
Physical Surface("lower") = {ls[1]};
Physical Curve("upper_bottom") = {ub[1]};
Physical Curve("upper_top") = {us[0]};
Physical Curve("upper_left") = {us[3]};
Physical Curve("upper_right") = {us[2]};
Physical Curve("lower_bottom") = {lb[1]};
Physical Curve("lower_top") = {ls[0]};
Physical Curve("lower_left") = {ls[3]};
Physical Curve("lower_right") = {ls[2]};
