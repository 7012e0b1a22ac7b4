# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: the shallow-shell block (Figs. 1-2 of the paper)
#
# **What it shows.** A square block of a spherical shallow shell, supported on shell
# diaphragms and loaded by a uniform pressure, is solved with shellform's quasi-conforming
# C1 shallow-shell triangle on nested meshes. The centre deflection converges at O(h^2) to the
# Navier series solution of Donnell's shallow-shell equations, and a sweep over the radius of
# curvature shows the block stiffen as it gets more curved and tend to the flat plate as
# $R \to \infty$.
#
# **How to run it.**
#
#     python demos/demo_shallow_shell.py --radius 5 --levels 3 --kind structured
#
# Flags: `--radius R` (radius of the sphere, default 5; `inf` gives a flat plate),
# `--levels N` (uniform refinements of the coarsest mesh, default 3), `--kind
# {structured,unstructured}`, `--base-n N` (elements along a side of the coarsest quarter
# mesh, default 3), `--sweep-n N` (the fixed mesh of the radius sweep, default 24).
#
# **Sample runs.**
#
#     $ python demos/demo_shallow_shell.py --levels 3
#     shallow shell block: R = 5, a = 1, t = 0.01 (a^2/(R t) = 20), structured meshes, base n = 3
#     Navier (Donnell) coefficient w D/(q a^4) = 0.0002755872
#     level  cells   coefficient   rel_error  rate  time_s
#         0     18  0.0002527037   -8.30e-02     -    2.34
#         1     72  0.0002697519   -2.12e-02  1.97    0.01
#         2    288  0.0002742012   -5.03e-03  2.07    0.02
#         3   1152  0.0002753133   -9.94e-04  2.34    0.05
#     order from successive differences (levels 1-3): 2.00
#     Richardson limit of the model 0.0002756841, +3.51e-04 relative to Donnell's
#
#     radius sweep on the structured n = 24 mesh (1152 cells):
#            R  a^2/(R t)   coefficient        Navier   vs_Navier  vs_plate
#            2         50  0.0000369816  0.0000369885   -1.85e-04    0.0091
#           10         10  0.0010057904  0.0010067177   -9.21e-04    0.2476
#          100          1  0.0039486385  0.0039490457   -1.03e-04    0.9720
#        10000       0.01  0.0040620478  0.0040623410   -7.22e-05    0.9999
#          inf          0  0.0040620594  0.0040623527   -7.22e-05    0.9999
#
#     rate against Navier 2.34 (levels 2-3); order from differences 2.00;
#     R = 1e4 within 7.44e-05 of the plate: OK
#
#     $ python demos/demo_shallow_shell.py --levels 4 --kind unstructured
#     ...
#         2    416  0.0002751390   -1.63e-03  2.22    0.03
#         3   1664  0.0002755474   -1.44e-04  3.49    0.07
#         4   6656  0.0002756496    2.26e-04 -0.65    0.32
#     order from successive differences (levels 2-4): 2.00
#     Richardson limit of the model 0.0002756836, +3.50e-04 relative to Donnell's
#     ...
#     rate against Navier 2.22 (levels 1-2); order from differences 2.00;
#     R = 1e4 within 7.44e-05 of the plate: OK
#
# The first solve includes the one-off compilation of the element kernels (FFCx and numba).
# The checks at the end are made for shallow blocks, $a^2/(R t) \lesssim 20$ ($R \gtrsim 5$):
# a deeper block such as `--radius 2` ($a^2/(R t) = 50$) has edge layers of width about
# $\sqrt{R t} \approx 0.14$ at the diaphragms; on these meshes its successive differences still
# change sign, and the order check fails.

# ## The shallow shell
#
# The reference surface is the shallow sphere $z_0 = -(x^2 + y^2)/(2R)$ over the square
# $(-a/2, a/2)^2$, with the curvature tensor $\kappa_0 = -\nabla\nabla z_0 =
# \mathrm{diag}(1/R, 1/R)$. Its displacement has in-plane components $u = (u, v)$ and a
# transverse component $w$. In shallow-shell theory the strains are those of a plate plus the
# coupling through $\kappa_0$:
#
# $$ f^p = \mathrm{sym}\,\nabla u + w\,\kappa_0, \qquad
#    f^b = -\nabla\nabla w + \mathrm{sym}(\kappa_0 \nabla u). $$
#
# The membrane strain $f^p$ now sees $w$: a shell cannot deflect without stretching, so
# it carries the pressure partly by membrane forces, which is what makes it far stiffer than a
# plate of the same thickness. The energy is
# $\frac12\int N : f^p + M : f^b \, dA - \int q\,w\,dA$ with
# $N = \frac{E t}{1-\nu^2}\big((1-\nu) f^p + \nu\,\mathrm{tr} f^p I\big)$ and
# $M = D\big((1-\nu) f^b + \nu\,\mathrm{tr} f^b I\big)$, $D = E t^3/(12(1-\nu^2))$. The element
# uses linear assumed strains for both groups, tied to $f^p$ and $f^b$ weakly, with the
# string-net edge traces of the plate element for the $-\nabla\nabla w$ part (docs/derivation.md).
#
# Data (ours; the paper gives none): $a = 1$, $t = 0.01$, $E = 1$, $\nu = 0.3$, $q = 1$, and
# $R = 5$ by default, so $a^2/(R t) = 20$: membrane action dominates.

import argparse
import math
import sys

import shellform  # noqa: F401  (loads the DOLFINx runtime before dolfinx itself)
from shellform.studies import shell
from shellform.studies.common import observed_rates

# ## Command-line flags
#
# In a notebook, where the kernel's own arguments are on `sys.argv`, the defaults are used.

parser = argparse.ArgumentParser(description="Shallow spherical shell block: convergence to the Navier series.")
parser.add_argument("--radius", type=float, default=5.0,
                    help="radius R of the spherical reference surface (default 5; inf: flat plate)")
parser.add_argument("--levels", type=int, default=3,
                    help="number of uniform refinements of the coarsest mesh (default 3: 4 meshes)")
parser.add_argument("--kind", choices=["structured", "unstructured"], default="structured",
                    help="structured (n x n x 2 triangles) or unstructured gmsh meshes for the convergence study")
parser.add_argument("--base-n", type=int, default=shell.BASE_N,
                    help=f"elements along a side of the coarsest quarter mesh (default {shell.BASE_N})")
parser.add_argument("--sweep-n", type=int, default=24,
                    help="elements along a side of the structured quarter mesh of the radius sweep (default 24)")
args = parser.parse_args([] if "ipykernel" in sys.modules else None)
if args.levels < 2:
    parser.error("--levels must be >= 2: the checks need three meshes")
if args.base_n < 1 or args.sweep_n < 1:
    parser.error("--base-n and --sweep-n must be >= 1")
if not args.radius > 0:
    parser.error("--radius must be > 0")

R, A, T = args.radius, shell.A, shell.T
print(f"shallow shell block: R = {R:g}, a = {A:g}, t = {T:g} (a^2/(R t) = {A**2 / (R * T):.3g}), "
      f"{args.kind} meshes, base n = {args.base_n}")

# ## Supports: the shell diaphragm
#
# By symmetry only the quarter $x, y \ge 0$ is meshed (zero normal slope and zero normal
# in-plane displacement on $x = 0$ and $y = 0$). The outer edges rest on *diaphragms*: walls
# that are rigid in their own plane and flexible out of it. They hold
#
# $$ w = 0,\qquad w_{,s} = 0,\qquad u_s = 0 $$
#
# along the edge ($s$ the tangent), and leave the normal slope $w_{,n}$ and the normal
# displacement $u_n$ free, so the normal moment $M_n$ and the normal membrane force $N_n$
# vanish there in the limit. These are shellform's `simply_supported` sides.
#
# ## The analytic reference: a Navier series
#
# On diaphragm supports every term $\sin(m\pi x/a)\sin(n\pi y/a)$ (odd $m, n$, with $x, y$
# measured from a corner) satisfies all the boundary conditions of Donnell's shallow-shell
# equations. For a sphere those equations collapse to
# $D\Delta^4 w + (E t/R^2)\Delta^2 w = \Delta^2 q$: each Fourier mode behaves like a plate on an
# elastic foundation of modulus $E t / R^2$, and
#
# $$ \frac{w D}{q a^4}\Big|_{\text{centre}} = \frac{D}{a^4}\sum_{m, n\ \text{odd}}
#    \frac{16}{\pi^2 m n}\,\frac{\sin(m\pi/2)\sin(n\pi/2)}{D\lambda_{mn}^4 + E t/R^2},\qquad
#    \lambda_{mn}^2 = (m^2 + n^2)\frac{\pi^2}{a^2}. $$
#
# (`shellform.studies.shell.navier_coefficient`). At $R = \infty$ it is the plate value 0.00406235.

navier = shell.navier_coefficient(R)
print(f"Navier (Donnell) coefficient w D/(q a^4) = {navier:.10f}")

# ## Convergence on nested meshes
#
# Level $k$ is the coarsest mesh refined uniformly $k$ times, so $h$ halves from one level to
# the next and the meshes are nested. As for the plate, the centre deflection converges at
# O(h^2); the rate is measured with $h \propto (\text{cells})^{-1/2}$.

rows = []
print(f"{'level':>5s} {'cells':>6s} {'coefficient':>13s} {'rel_error':>11s} {'rate':>5s} {'time_s':>7s}")
for k in range(args.levels + 1):
    r = shell.coefficient(R, args.base_n, args.kind, refine=k)  # w D/(q a^4) at the centre
    r["rel_error"] = (r["coefficient"] - navier) / navier
    rows.append(r)
    rate = observed_rates(rows)[-1]
    rate_text = "    -" if k == 0 else f"{rate:5.2f}"
    print(f"{k:5d} {r['cells']:6d} {r['coefficient']:13.10f} {r['rel_error']:11.2e} {rate_text} "
          f"{r['total_s']:7.2f}")

# ## How close is Donnell's theory to the discrete model?
#
# The model's bending strain keeps the term $\mathrm{sym}(\kappa_0\nabla u)$, which Donnell's
# equations drop, so the two limits differ slightly: the Navier value is a reference for the
# *discretisation* error only while that error is much larger than the model gap. Two
# reference-free quantities settle this:
#
# * the order from successive differences of three nested levels,
#   $p = \log_2\big((c_{k-1} - c_{k-2}) / (c_k - c_{k-1})\big)$, which needs no exact value;
# * the Richardson limit $c_\infty \approx c_k + (c_k - c_{k-1})/3$ (for order 2 and $h$
#   halved), whose distance from the Navier value estimates the model gap (a few $10^{-4}$
#   relative at $R = 5$).
#
# The rate against Navier is then judged on the finest pair of meshes whose errors are both
# larger than twice that gap; on finer meshes the error against Navier levels off at the gap,
# and its "rate" says nothing about the element.

c = [r["coefficient"] for r in rows]
diff_order = math.log2((c[-2] - c[-3]) / (c[-1] - c[-2])) if (c[-2] - c[-3]) * (c[-1] - c[-2]) > 0 else math.nan
limit = c[-1] + (c[-1] - c[-2]) / 3
gap = (limit - navier) / navier
print(f"order from successive differences (levels {args.levels - 2}-{args.levels}): {diff_order:.2f}")
print(f"Richardson limit of the model {limit:.10f}, {gap:+.2e} relative to Donnell's")
rates = observed_rates(rows)
pairs = [k for k in range(1, len(rows))
         if min(abs(rows[k - 1]["rel_error"]), abs(rows[k]["rel_error"])) > 2 * abs(gap)]
judged = pairs[-1] if pairs else None

# ## From shell to plate: a sweep over the radius
#
# On one fixed mesh the radius runs from a deep shell to a flat plate. The foundation term
# $E t / R^2$ fades as $R$ grows; at $R = \infty$ the membrane decouples from the bending
# and the block is exactly the Kirchhoff plate of `demo_plate_convergence.py`.

plate_value = shell.PLATE
sweep = []
print(f"\nradius sweep on the structured n = {args.sweep_n} mesh ({2 * args.sweep_n**2} cells):")
print(f"{'R':>8s} {'a^2/(R t)':>10s} {'coefficient':>13s} {'Navier':>13s} {'vs_Navier':>11s} {'vs_plate':>9s}")
for radius in (2.0, 10.0, 100.0, 1e4, math.inf):
    r = shell.coefficient(radius, args.sweep_n)
    nav = shell.navier_coefficient(radius)
    sweep.append((radius, r["coefficient"]))
    print(f"{radius:8g} {A**2 / (radius * T):10.3g} {r['coefficient']:13.10f} {nav:13.10f} "
          f"{(r['coefficient'] - nav) / nav:11.2e} {r['coefficient'] / plate_value:9.4f}")

# ## Checks
#
# * second order against the Navier series, on the finest pair dominated by discretisation
#   error, and from the successive differences of the three finest meshes;
# * the block stiffens monotonically with curvature;
# * at $R = 10^4$ ($a^2/(R t) = 0.01$) the coefficient is the plate's to within 0.1 %.

c_1e4 = dict(sweep)[1e4]
plate_error = abs(c_1e4 - plate_value) / plate_value
assert judged is not None, f"no pair of meshes has errors above twice the model gap {abs(gap):.1e}: coarser meshes"
print(f"\nrate against Navier {rates[judged]:.2f} (levels {judged - 1}-{judged}); order from differences "
      f"{diff_order:.2f};")
print(f"R = 1e4 within {plate_error:.2e} of the plate: ", end="")
assert rates[judged] >= 1.9, f"rate against Navier {rates[judged]:.3f} < 1.9"
assert diff_order >= 1.9, f"order from successive differences {diff_order:.3f} < 1.9"
assert all(c0 < c1 for (_, c0), (_, c1) in zip(sweep, sweep[1:])), "the block must soften as R grows"
assert plate_error < 1e-3, f"R = 1e4 differs from the plate by {plate_error:.2e} (relative)"
print("OK")
