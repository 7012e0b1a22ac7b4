// A quarter of a Nakajima specimen (x, y >= 0) for demos/nakajima.toml: a disc of radius R
// with a circular notch of radius rho on each side, whose centre lies at y = W/2 + rho, so
// that the waist along x = 0 has the width W. The major strain runs along x, the waist's
// edges (named "edge") are free, the disc's rim ("rim") lies under the holder and beyond the
// lock bead. Change W for another width (2 R > W > 2 (R - 2 rho): the notch reaches the rim);
// `shellform study nakajima` writes one such file per width.
R = 90;
rho = 50;
W = 60;
c = W / 2 + rho;
ys = (R^2 - rho^2 + c^2) / (2 * c);  // where the notch's circle meets the rim
xs = Sqrt(R^2 - ys^2);
Point(1) = {0, 0, 0};
Point(2) = {R, 0, 0};
Point(3) = {xs, ys, 0};
Point(4) = {0, c, 0};
Point(5) = {0, W / 2, 0};
Line(1) = {1, 2};
Circle(2) = {2, 1, 3};
Circle(3) = {3, 4, 5};
Line(4) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("rim") = {2};
Physical Curve("edge") = {3};
Physical Curve("left") = {4};
Physical Surface("specimen") = {1};
