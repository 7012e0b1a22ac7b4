# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: rolling a strip into a full circle (large rotations)
#
# **What it shows.** A cantilever strip is bent by an end moment until it closes into a full
# circle. The exact answer is a circular arc of radius $EI/M$; a shallow (small-rotation)
# description fails long before the tip turns through $2\pi$. shellform's total-Lagrangian
# Kirchhoff-Love sheet follows it with no rotation variables at all.
#
# **How to run it.**
#
#     python demos/demo_rollup.py --n 48 --stations 8
#
# Flags: `--n N` (elements along the strip, default 48), `--stations K` (load levels at which
# the tip is compared with the exact arc, default 8), `--step S` (load-factor increment,
# default 0.05), `--tol T` (the largest tip error accepted, in units of L, default 1e-3).
#
# **Sample run.**
#
#     $ python demos/demo_rollup.py --n 48
#     strip L = 1, t = 0.01, nu = 0; 192 cells; end moment up to 2 pi EI / L
#     load factor  tip rotation   tip x/L   tip z/L exact x/L exact z/L   error/L
#           0.125          45.0   0.90031   0.37292   0.90032   0.37292   6.1e-06
#           0.250          90.0   0.63663   0.63659   0.63662   0.63662   3.2e-05
#           ...
#           0.875         315.0  -0.12903   0.05367  -0.12862   0.05327   5.7e-04
#           1.000         360.0  -0.00070   0.00000   0.00000   0.00000   7.0e-04
#     OK

import argparse
import sys

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np

from shellform.studies import rollup

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--n", type=int, default=48)
parser.add_argument("--stations", type=int, default=8)
parser.add_argument("--step", type=float, default=0.05)
parser.add_argument("--tol", type=float, default=1e-3)
args = parser.parse_args([] if "ipykernel" in sys.modules else None)  # in a notebook: the defaults

# ## The model
#
# The unknown is the displacement $U$ of the strip's mid-surface from the flat blank, with the
# quasi-conforming $C^1$ interpolation on all three components. The deformed tangents
# $a_\alpha = e_\alpha + U_{,\alpha}$ and normal $n = a_1 \times a_2/|a_1 \times a_2|$ give the
# exact strains
#
# $$ E = \tfrac12 (a_\alpha \cdot a_\beta - \delta_{\alpha\beta}), \qquad
#    K_{\alpha\beta} = -n \cdot x_{,\alpha\beta}, $$
#
# with $x_{,\alpha\beta}$ the string-net weak Hessian of each component. The end moment does
# the work $M\theta$ on the end fibre's rotation $\theta = \operatorname{atan2}(w_{,x}, 1 + u_{,x})$,
# which is exact for any angle; symmetry on the long sides makes the strip a slice of a wide plate.

p = rollup.problem(args.n, args.step)
print(f"strip L = {rollup.L:g}, t = {rollup.T:g}, nu = 0; {p.model.mesh.topology.index_map(2).size_global} cells; "
      f"end moment up to 2 pi EI / L")
print(f"{'load factor':>11s} {'tip rotation':>13s} {'tip x/L':>9s} {'tip z/L':>9s} {'exact x/L':>9s} "
      f"{'exact z/L':>9s} {'error/L':>9s}")

# ## Load it and compare the tip with the arc

errors = []
L = rollup.L
for lam in np.linspace(1.0 / args.stations, 1.0, args.stations):
    p.driver.run(lam)
    u, w = p.value("u", L / 2, 0.0), p.value("w", L / 2, 0.0)
    ue, we = rollup.exact_tip(lam)
    errors.append(np.hypot(u - ue, w - we) / L)
    print(f"{lam:11.3f} {np.degrees(2 * np.pi * lam):13.1f} {(L + u) / L:9.5f} {w / L:9.5f} "
          f"{(L + ue) / L:9.5f} {we / L:9.5f} {errors[-1]:9.1e}")

# ## Check
#
# The tip stays within `--tol` of the exact arc all the way round.

assert max(errors) < args.tol, f"tip error {max(errors):.2e} L exceeds {args.tol:g} L"
print("OK")
