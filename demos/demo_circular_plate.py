# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: circular plate, supports on a curved edge
#
# **What it shows.** A uniformly loaded circular plate, simply supported or clamped along its
# curved rim, solved with shellform's C1 triangle on nested gmsh meshes of a quarter disc. The
# centre deflection converges at O(h^2) to Timoshenko's closed form, because the rim's slope
# conditions are imposed in each rim vertex's own normal-tangent frame.
#
# **How to run it.**
#
#     python demos/demo_circular_plate.py --levels 3 --support simply_supported
#
# Flags: `--support {simply_supported,clamped}`, `--levels N` (uniform refinements of the
# coarsest mesh, default 3), `--base-n N` (elements along the radius of the coarsest mesh,
# default 4). `--help` lists them.
#
# **Sample runs.**
#
#     $ python demos/demo_circular_plate.py --levels 3
#     circular plate, simply_supported rim, base n = 4, 3 refinements
#     closed form w D/(q a^4) = 0.06370192307692307
#     level  cells      w_center   rel_error  rate  time_s
#         0     37  0.0638489812    2.31e-03     -    1.65
#         1    148  0.0637388896    5.80e-04  1.99    0.03
#         2    592  0.0637111776    1.45e-04  2.00    0.04
#         3   2368  0.0637042391    3.64e-05  2.00    0.09
#     observed rate 2.00 (finest pair), finest |error| 3.64e-05: OK

# ## The problem
#
# A plate of radius $a$ and bending stiffness $D = E t^3/(12(1-\nu^2))$ carries a uniform
# pressure $q$. Its centre deflection (Timoshenko & Woinowsky-Krieger, section 15) is
#
# $$ w_0 = \frac{q a^4}{64 D}\ \text{(clamped)},\qquad
#    w_0 = \frac{5+\nu}{1+\nu}\,\frac{q a^4}{64 D}\ \text{(simply supported)}. $$
#
# With $a = 1$, $D = 1$, $q = 1$ the computed centre deflection is the coefficient itself.
#
# ## A curved edge in a C1 element
#
# The carrier holds $(w, w_{,x}, w_{,y})$ at each vertex. On a straight edge along $x$ or $y$ a
# support fixes components: simply supported means $w = 0$ and $w_{,s} = 0$ (the deflection
# vanishes along the edge, so does its derivative along it), with the normal slope $w_{,n}$
# free. On the circle $n$ and $s$ turn from vertex to vertex. Fixing both slopes at each rim
# vertex would clamp the plate; fixing the slopes of the inscribed polygon's edges would
# converge to the polygon's plate, whose corners are clamped (Babuska's paradox: the
# simply supported polygon does not tend to the simply supported circle). shellform instead
# turns each rim vertex's slope pair into the rim's frame,
#
# $$ (w_{,x}, w_{,y}) = a_1\, s + a_2\, n \quad\Rightarrow\quad
#    q = R\, q',\qquad R^T K R\, q' = R^T f, $$
#
# and fixes $a_1 = w_{,s}$ with the exact tangent $s$ of the circle
# (shellform/edge_frames.py). Then the discrete plate is simply supported along the circle,
# to the accuracy of the mesh.
#
# ## Nested meshes
#
# Level $k$ refines the coarsest gmsh mesh $k$ times; gmsh puts the new rim vertices on the
# circle, so the boundary improves with the mesh and $h$ halves exactly.

import argparse
import math
import sys

import shellform  # noqa: F401  (loads the DOLFINx runtime before dolfinx itself)
from shellform.results import log
from shellform.studies.common import deflection_table, observed_rates
from shellform.studies.outlines import REFERENCE, disc_scene

parser = argparse.ArgumentParser(description="Circular plate: convergence of the centre deflection.")
parser.add_argument("--support", choices=["simply_supported", "clamped"], default="simply_supported",
                    help="support on the rim (default: simply_supported)")
parser.add_argument("--levels", type=int, default=3, help="uniform refinements of the coarsest mesh (default 3)")
parser.add_argument("--base-n", type=int, default=4, help="elements along the radius of the coarsest mesh (default 4)")
args = parser.parse_args([] if "ipykernel" in sys.modules else None)
if args.levels < 1:
    parser.error("--levels must be >= 1: a rate needs two meshes")
if args.base_n < 1:
    parser.error("--base-n must be >= 1")

reference = REFERENCE[args.support]  # q a^4/(64 D); simply supported: times (5 + nu)/(1 + nu)
print(f"circular plate, {args.support} rim, base n = {args.base_n}, {args.levels} refinements")
print(f"closed form w D/(q a^4) = {reference}")

# The scene of one mesh: the quarter disc $a = 1$ with symmetry on $x = 0$ and $y = 0$,
# $E t^3 = 12(1-\nu^2)$ so that $D = 1$, meshed by gmsh with `--base-n` elements along the
# radius and refined `k` times (`shellform.studies.outlines.disc_scene`, also behind
# `shellform study outlines`).

# `deflection_table` logs one row per mesh; shellform prints nothing unless asked, and
# `log.console()` asks.
log.console()
rows = deflection_table((disc_scene(args.support, args.base_n, k) for k in range(args.levels + 1)), reference)

# ## Checks
#
# Second order on the finest pair (at least 1.9) and the finest mesh within 0.5 % of the closed
# form. A rim that clamped the simply supported plate would miss it by a factor
# $(5+\nu)/(1+\nu) = 4.1$; the polygon's plate (Babuska) would not converge to it at all.

rate = observed_rates(rows)[-1]
error = abs(rows[-1]["rel_error"])
print(f"observed rate {rate:.2f} (finest pair), finest |error| {error:.2e}: ", end="")
assert rate >= 1.9 and math.isfinite(rate), f"observed rate {rate:.3f} < 1.9"
assert error < 5e-3, f"finest relative error {error:.2e} >= 5e-3"
print("OK")
