# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: a plastic hinge and its springback (Hill 1979 through the thickness)
#
# **What it shows.** A cantilever strip of elastic-perfectly plastic sheet is bent by a
# prescribed tip deflection until a plastic hinge forms at the clamp. The tip force rises to
# the limit load of limit analysis, $P_L = M_p b/L$, and levels off. Unloaded, the strip
# springs back along its elastic slope and keeps a permanent set.
#
# **How to run it.**
#
#     python demos/demo_springback.py --n 16 --layers 9 --r 1.5 --m 2
#
# Flags: `--n N` (elements along the strip, default 16), `--layers K` (Gauss points through
# the thickness, default 9), `--r R` (Lankford value, default 1), `--m M` (Hill 1979 exponent,
# default 2; `--r 1 --m 2` is von Mises).
#
# **Sample run.**
#
#     $ python demos/demo_springback.py
#     cantilever L = 1, t = 0.02, E = 1000, sigma_y = 1, plane strain across the strip
#     plane-strain yield stress 1.1547 sigma_y; P_L = 7.217e-06 per strip (b = 1/16)
#       tip deflection    P / P_L
#               0.0067     0.1269
#               0.0542     0.9250
#               0.1542     1.0130
#               ...
#               0.6667     1.0131
#     unloaded to the residual deflection the elastic slope predicts, 0.6135: tip force there 6.6e-11 P_max
#     OK

import argparse
import sys

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np

from shellform.studies import plastic

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--n", type=int, default=16)
parser.add_argument("--layers", type=int, default=9)
parser.add_argument("--r", type=float, default=1.0)
parser.add_argument("--m", type=float, default=2.0)
args = parser.parse_args([] if "ipykernel" in sys.modules else None)  # in a notebook: the defaults

# ## The section
#
# At each in-plane quadrature point the strain of a layer at height $z$ is $E + zK$; the
# plane-stress return mapping of Hill 1979,
#
# $$ |s_1 + s_2|^m + (1 + 2r)|s_1 - s_2|^m = 2(1 + r)\bar\sigma^m, $$
#
# gives its stress and consistent tangent, and Gauss quadrature through the thickness gives
# the resultants $N, M$ and the section tangent. With symmetry on the long sides the strip
# bends in plane strain, so its fully plastic moment is $M_p = s_{ps} t^2/4$ with the
# plane-strain yield stress $s_{ps}$ of the yield function.

b = plastic.L / args.n
PL = plastic.limit_load(b, args.r, args.m)
print(f"cantilever L = {plastic.L:g}, t = {plastic.T:g}, E = {plastic.E:g}, sigma_y = {plastic.SY:g}, "
      f"plane strain across the strip")
print(f"plane-strain yield stress {plastic.plane_strain_yield(args.r, args.m):.4f} sigma_y; "
      f"P_L = {PL:.3e} per strip (b = 1/{args.n})")

# ## Load to 20 times the first-yield deflection, then unload along the elastic slope

row = plastic.solve(args.n, args.layers, args.r, args.m)
d, P = row["path"]
print(f"{'tip deflection':>16s} {'P / P_L':>10s}")
for k in np.unique(np.linspace(0, len(d) - 1, 8).astype(int)):
    print(f"{d[k]:16.4f} {P[k] / PL:10.4f}")
k_el = P[0] / d[0]
print(f"unloaded to the residual deflection the elastic slope predicts, {d[-1] - P[-1] / k_el:.4f}: "
      f"tip force there {row['residual_deflection_error']:.1e} P_max")

# ## Checks
#
# * the force rises monotonically and levels off within 2 % of the limit load;
# * (von Mises) unloading is elastic: at the residual deflection the elastic slope predicts,
#   the tip force is zero.

assert np.all(np.diff(P) > 0), "the load-deflection curve must rise"
assert abs(P[-1] / PL - 1) < 0.02, f"P_max / P_L = {P[-1] / PL:.4f}"
if (args.r, args.m) == (1.0, 2.0):
    assert row["residual_deflection_error"] < 1e-8
print("OK")
