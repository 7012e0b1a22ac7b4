// MacNeal and Harder's curved beam (Finite Elem. Anal. Des. 1, 1985): a quarter ring, inner
// radius 4.12, outer 4.32, clamped at the x axis, loaded at the y axis. Their mesh: 6 elements
// along the arc, 1 across (here 12 triangles); `along` and `across` set the divisions
// (shellform.studies.locking writes finer copies).
along = 6;
across = 1;
Point(1) = {0, 0, 0};
Point(2) = {4.12, 0, 0};
Point(3) = {4.32, 0, 0};
Point(4) = {0, 4.32, 0};
Point(5) = {0, 4.12, 0};
Line(1) = {2, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{2, 4} = along + 1;
Transfinite Curve{1, 3} = across + 1;
Transfinite Surface{1};
Physical Curve("root") = {1};
Physical Curve("outer") = {2};
Physical Curve("tip") = {3};
Physical Curve("inner") = {4};
Physical Surface("beam") = {1};
