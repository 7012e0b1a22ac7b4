# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: membrane locking, and the membrane strain tied to the string net
#
# **What it shows.** A thin strip rolled into a full circle by an end moment. With the sheet's
# compatible membrane strain the coarse cubic cannot bend without stretching, and at t/L = 1e-3
# the tip ends far from the exact arc: the element locks. The effect `assumed_membrane` ties the
# membrane strain to the stretch of the element edges (the paper's string net) and the strip
# rolls up, its error falling as h^2 whatever the thickness (docs/locking.md).
#
# **How to run it.**
#
#     python demos/demo_membrane_locking.py --n 16 32 --thickness 1e-3
#
# Flags: `--n N [N ...]` (elements along the strip, default 16 32), `--thickness T` (t/L,
# default 1e-3), `--factor F` (the assumed strain must beat the compatible one by this factor
# on every mesh, default 10).
#
# **Sample run.**
#
#     $ python demos/demo_membrane_locking.py
#     strip L = 1, t/L = 0.001, rolled into a full circle; max tip distance from the arc / L
#       n  cells  compatible   assumed    ratio
#      16     64     7.96e-01  7.54e-03      106
#      32    128     3.13e-01  1.87e-03      168
#     OK

import argparse
import sys

import shellform  # noqa: F401  (DOLFINx runtime first)

from shellform.studies import rollup

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--n", type=int, nargs="+", default=[16, 32])
parser.add_argument("--thickness", type=float, default=1e-3)
parser.add_argument("--factor", type=float, default=10.0)
args = parser.parse_args([] if "ipykernel" in sys.modules else None)  # in a notebook: the defaults

# ## Why a cubic locks
#
# Every displacement component of the sheet is the reduced cubic. Along the rolled strip the
# Green-Lagrange membrane strain of the cubic, $E_{11} = \tfrac12(|x_{,1}|^2 - 1)$, is a quartic
# in $x$ that no nodal values make vanish: a cubic curve cannot keep its length while it bends.
# Its energy scales with $E t$, the bending energy with $E t^3$; at $t/L = 10^{-3}$ the spurious
# stretch wins.
#
# ## The assumed membrane strain
#
# An independent membrane strain $\varepsilon^p$, constant in each cell, is tied to the
# compatible one on each edge $e$ of unit tangent $t_e$:
#
# $$ t_e \cdot \varepsilon^p \cdot t_e = \frac{1}{|e|} \int_e t_e \cdot E \cdot t_e \, ds . $$
#
# The edge stretch depends only on the displacement's trace on the edge, which the two
# neighbours share, so one stretch condition per edge remains. A fraction $\beta$ of the
# compatible strain, $\beta^2 = t^2/(t^2 + 0.3 h^2)$, keeps the modes the tying leaves free:
#
# $$ e^p = (1 - \beta)\,\varepsilon^p + \beta E . $$

print(f"strip L = {rollup.L:g}, t/L = {args.thickness:g}, rolled into a full circle; "
      f"max tip distance from the arc / L")
print(f"{'n':>3s} {'cells':>6s} {'compatible':>11s} {'assumed':>9s} {'ratio':>8s}")
ratios = []
for n in args.n:
    locked = rollup.solve(n, thickness=args.thickness)["max_tip_error"]
    free = rollup.solve(n, thickness=args.thickness, assumed_membrane=True)["max_tip_error"]
    ratios.append(locked / free)
    print(f"{n:3d} {4 * n:6d} {locked:11.2e} {free:9.2e} {ratios[-1]:8.0f}")

# ## Check
#
# On every mesh the assumed strain is at least `--factor` times closer to the arc.

assert min(ratios) >= args.factor, f"the assumed membrane strain gained only {min(ratios):.1f}x"
print("OK")
