// The quarter (x, y >= 0) of the 150 mm square blank of the graded cup scenes
// (demos/square_cup_graded.toml, demos/numisheet93_aluminium_graded.toml), graded: 2.5 mm cells
// in a band along the diagonal from (15, 15) mm outwards, which holds the punch's corner (the peak
// thinning) and the flange's corner (where the holder's inner edge meets the die's corner and the
// sheet's bending reaction is lumped on few nodes, docs/contact.md), 5.5 mm elsewhere. The
// diagonal is a line of the mesh, so the thickness line x = y has nodes.
// The physical curves are the rectangle's side names, so the scene's [supports] read as usual.
L = 75; h_coarse = 5.5; h_fine = 2.5;
Point(1) = {0, 0, 0, h_coarse}; Point(2) = {L, 0, 0, h_coarse};
Point(3) = {L, L, 0, h_coarse}; Point(4) = {0, L, 0, h_coarse};
Point(5) = {15, 15, 0, h_coarse};  // where the fine band starts, on the diagonal
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Line(5) = {1, 5}; Line(6) = {5, 3};
Line{5, 6} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2};
Physical Curve("top") = {3}; Physical Curve("left") = {4};
Physical Surface("blank") = {1};
Field[1] = Distance; Field[1].CurvesList = {6}; Field[1].Sampling = 200;
Field[2] = Threshold; Field[2].InField = 1;
Field[2].SizeMin = h_fine; Field[2].SizeMax = h_coarse; Field[2].DistMin = 4; Field[2].DistMax = 12;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0;
