// A quarter of the unit disc, x, y >= 0, for demos/disc_file_plate.toml.
// Its named physical curves are the boundary groups a scene's [supports] refers to.
h = 0.1;
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Point(3) = {0, 1, 0, h};
Line(1) = {1, 2};
Circle(2) = {2, 1, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("x_axis") = {1};
Physical Curve("arc") = {2};
Physical Curve("y_axis") = {3};
Physical Surface("plate") = {1};
