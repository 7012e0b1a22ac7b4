# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: square Kirchhoff plate, second-order convergence of the centre deflection
#
# **What it shows.** A uniformly loaded square plate, simply supported or clamped, is solved
# with shellform's quasi-conforming C1 triangle on a sequence of nested meshes. The centre
# deflection converges to the classical series value at the rate O(h^2), on structured and on
# unstructured (gmsh) meshes alike.
#
# **How to run it.**
#
#     python demos/demo_plate_convergence.py --levels 4 --support clamped
#
# Flags: `--support {simply_supported,clamped}`, `--kind {structured,unstructured}`,
# `--levels N` (uniform refinements of the coarsest mesh, default 4), `--base-n N` (elements
# along a side of the coarsest quarter mesh, default 4). `--help` lists them.
#
# **Sample runs.**
#
#     $ python demos/demo_plate_convergence.py --levels 3
#     square plate, simply_supported, structured meshes, base n = 4, 3 refinements
#     reference w D/(q a^4) = 0.004062352660675052
#     level  cells      w_center   rel_error  rate  time_s
#         0     32  0.0040508434   -2.83e-03     -    2.36
#         1    128  0.0040596271   -6.70e-04  2.08    0.01
#         2    512  0.0040616884   -1.63e-04  2.04    0.01
#         3   2048  0.0040621882   -3.98e-05  2.03    0.04
#     observed rate 2.03 (finest pair), finest |error| 3.98e-05: OK
#
#     $ python demos/demo_plate_convergence.py --levels 4 --support clamped --kind unstructured
#     square plate, clamped, unstructured meshes, base n = 4, 4 refinements
#     reference w D/(q a^4) = 0.00126532
#     level  cells      w_center   rel_error  rate  time_s
#         0     44  0.0012564153   -7.04e-03     -    2.41
#         1    176  0.0012632766   -1.61e-03  2.12    0.01
#         2    704  0.0012648347   -3.84e-04  2.07    0.03
#         3   2816  0.0012652015   -9.36e-05  2.03    0.06
#         4  11264  0.0012652901   -2.36e-05  1.99    0.22
#     observed rate 1.99 (finest pair), finest |error| 2.36e-05: OK
#
# The first solve includes the one-off compilation of the element kernels (FFCx and numba);
# the meshes after it take milliseconds.

# ## The problem
#
# A thin plate of bending stiffness $D = E t^3 / (12 (1 - \nu^2))$ carries a uniform pressure
# $q$. Kirchhoff's theory (normals stay normal, no transverse shear strain) gives the
# biharmonic equation for the deflection $w$,
#
# $$ D\,\Delta^2 w = q \quad\text{in } \Omega = (-a/2, a/2)^2, $$
#
# with $w = 0$ and zero normal moment on a simply supported edge, or $w = 0$ and $w_{,n} = 0$
# on a clamped one. Equivalently $w$ minimises the potential energy
#
# $$ \Pi(w) = \frac12 \int_\Omega M : \kappa \, dA - \int_\Omega q\, w \, dA,\qquad
#    \kappa = -\nabla\nabla w,\quad M = D\big((1-\nu)\kappa + \nu\,\mathrm{tr}\,\kappa\, I\big). $$
#
# With $a = 1$, $E = 1$, $\nu = 0.3$, $q = 1$ and $t = (12(1-\nu^2))^{1/3}$ we have $D = 1$, so
# the computed centre deflection *is* the dimensionless coefficient $w D / (q a^4)$:
# 0.0040623527 (simply supported: the Navier series, summed to round-off) and 0.00126532
# (clamped, an extrapolated finite-difference solution).
# By symmetry only the quarter $x, y \ge 0$ is meshed, with zero normal slope on $x = 0$ and
# $y = 0$.

import argparse
import sys

import shellform  # noqa: F401  (loads the DOLFINx runtime before dolfinx itself)
from shellform.results import log
from shellform.studies import plate
from shellform.studies.common import deflection_table, observed_rates

# ## Command-line flags
#
# Every knob of the study is a flag, so the same file serves as a quick check
# (`--levels 2`) and as a longer convergence run (`--levels 5`). In a notebook, where the
# kernel's own arguments are on `sys.argv`, the defaults are used.

parser = argparse.ArgumentParser(description="Square Kirchhoff plate: convergence of the centre deflection.")
parser.add_argument("--support", choices=["simply_supported", "clamped"], default="simply_supported",
                    help="support on the outer edges (default: simply_supported)")
parser.add_argument("--kind", choices=["structured", "unstructured"], default="structured",
                    help="structured (n x n x 2 right-diagonal triangles) or unstructured gmsh mesh")
parser.add_argument("--levels", type=int, default=4,
                    help="number of uniform refinements of the coarsest mesh (default 4: 5 meshes)")
parser.add_argument("--base-n", type=int, default=plate.BASE_N,
                    help=f"elements along a side of the coarsest quarter mesh (default {plate.BASE_N})")
args = parser.parse_args([] if "ipykernel" in sys.modules else None)
if args.levels < 1:
    parser.error("--levels must be >= 1: a rate needs two meshes")
if args.base_n < 1:
    parser.error("--base-n must be >= 1")

reference = plate.REFERENCE[args.support]
print(f"square plate, {args.support}, {args.kind} meshes, base n = {args.base_n}, {args.levels} refinements")
print(f"reference w D/(q a^4) = {reference}")

# ## The element
#
# A C1 field is what the energy asks for: $\kappa = -\nabla\nabla w$ must be square
# integrable, so $w$ and its normal slope $w_{,n}$ must be continuous across element edges.
# Polynomials on a triangle with only the vertex values $(w, w_{,x}, w_{,y})$ cannot achieve
# that. The quasi-conforming element gives up exact conformity *inside* the element and
# keeps it on the edge skeleton:
#
# * the curvature is an independent, linear field $\varepsilon^b$ in each triangle, tied to
#   $-\nabla\nabla w$ weakly (an $L^2$ projection onto linear tensors);
# * by Green's theorem that projection needs only the edge traces of $w$ and $\nabla w$, and
#   those are replaced by "string-net" functions built from the two end vertices of the edge
#   alone: a cubic Hermite trace for $w$ and a linear normal slope.
#
# Neighbouring triangles therefore see the same edge data, the element passes the patch
# test, and the condensed stiffness acts on 3 unknowns per vertex (see docs/derivation.md).
#
# ## Why O(h^2)
#
# The element reproduces every quadratic deflection, i.e. every constant curvature, exactly
# (the patch test), so the curvature and the energy are approximated to first order:
# $\|\kappa - \kappa_h\| = O(h)$. The centre deflection is a single number, the work of the
# solution against a unit point force at the centre. A duality argument bounds its error by
# the energy error of the plate problem times that of this dual problem (the plate under the
# point force), $O(h)\cdot O(h) = O(h^2)$, up to a logarithmic factor from the point force
# (whose deflection behaves like $r^2 \log r$). The table measures the rate as
#
# $$ \text{rate} = \frac{\log(e_{k-1}/e_k)}{\log(h_{k-1}/h_k)},\qquad
#    h \propto (\text{cells})^{-1/2}. $$
#
# ## Nested meshes
#
# Level $k$ is the coarsest mesh refined uniformly $k$ times: every triangle is split into
# four by its edge midpoints. The meshes are nested (each contains the previous one), $h$
# halves exactly from one level to the next, and the element shapes do not change, which
# is what makes the observed rate a clean measurement even on an unstructured mesh.

# The centre of the full plate is the corner x = y = 0 of the quarter. `deflection_table` logs
# one row per mesh; shellform prints nothing unless asked, and `log.console()` asks.
log.console()
rows = deflection_table((plate.scene(args.support, args.kind, args.base_n, refine=k) for k in range(args.levels + 1)),
                        reference)

# ## Checks
#
# The observed rate of the finest pair of meshes must be second order (with a little slack,
# 1.9), and the finest mesh must be accurate to 0.1 %. A failed check stops the script with
# an `AssertionError`, so the demo doubles as a regression test.

rate = observed_rates(rows)[-1]
error = abs(rows[-1]["rel_error"])
print(f"observed rate {rate:.2f} (finest pair), finest |error| {error:.2e}: ", end="")
assert rate >= 1.9, f"observed rate {rate:.3f} < 1.9"
assert error < 1e-3, f"finest relative error {error:.2e} >= 1e-3"
print("OK")
