# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Demo: the paper's square cup, drawn step by step
#
# **What it shows.** The paper's square cup (demos/square_cup.toml: a 0.78 mm steel blank,
# BHF 19.6 kN, mu 0.1, Hill 1979 with r = 1.5) drawn by a rigid punch into a die while a blank
# holder pinches its flange. On the way: the sheet's strains as UFL, the contact's parts that
# the Newton driver composes, and the draw-in and the thinning as the punch goes down.
#
# **How to run it.**
#
#     python demos/demo_square_cup.py --n 8 --stroke 30
#
# Flags: `--n N` (an N x N quarter mesh, default 8; the scene's own is 16), `--stroke S`
# (mm, default 30, the paper's), `--plot FILE` (a PNG of draw-in and thinning against
# the stroke). About 20 s with the defaults on 2 cores.
#
# **Sample run.**
#
#     $ python demos/demo_square_cup.py
#     parts: SheetNodes, ContactSet, PinchingHolder, CoulombFriction
#      stroke_mm   DX_mm   DD_mm  punch_kN  thickness_strain  increments  iterations
#            6.0   0.771   0.426     11.94           -0.0119          27          89
#           12.0   3.608   1.887     30.74           -0.0351          54         185
#           18.0   8.416   4.506     45.69           -0.0696          81         296
#           24.0  12.463   6.756     54.46           -0.1043         108         404
#           30.0  18.111   9.949     60.88           -0.1520         135         528
#     OK

import argparse
import inspect
import sys
from pathlib import Path

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np

from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.forms import kirchhoff_love
from shellform.results import cup

parser = argparse.ArgumentParser(description="the paper's square cup, drawn step by step")
parser.add_argument("--n", type=int, default=8)
parser.add_argument("--stroke", type=float, default=30.0)
parser.add_argument("--plot", default="")
args = parser.parse_args([] if "ipykernel" in sys.modules else None)  # in a notebook: the defaults

# ## The scene
#
# A scene file says what to simulate: geometry, material, tools, process, and the effects
# (bending, membrane, geometric nonlinearity, plasticity, finite strain, contact, friction).
# `Scene.changed` derives a variant that goes through the same checks as a file.

# The scene files lie beside this demo. A notebook has no __file__: its kernel starts in the
# notebook's folder (demos/) or, opened from the clone, in the clone.
HERE = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd()
DEMOS = next((d for d in (HERE, HERE / "demos") if (d / "square_cup.toml").is_file()), HERE)
paper = scene.load(DEMOS / "square_cup.toml")
s = paper.changed({"mesh.n": args.n, "tools.stroke": args.stroke, "process.springback": False,
                   "output.vtx": False, "output.png": False})  # the scene's steps are mm of travel: the same

# ## The sheet's strains, in UFL
#
# The sheet is a Kirchhoff-Love shell in total-Lagrangian form: its mid-surface moves by
# U = (u, v, w), F = F0 + grad U, and each layer at height z strains by E + z K, with the
# membrane strain and the change of curvature below (`shellform/forms/kirchhoff_love.py`; H
# are the weak Hessians of the three components, the C1 element's own unknowns).

print(inspect.getsource(kirchhoff_love.membrane_strain))
print(inspect.getsource(kirchhoff_love.curvature_change))

# ## The problem and its parts
#
# `DrawingProblem.from_scene` builds the blank's mesh, the sheet model (the element and the
# Hill 1979 layers) and a Newton driver composed of the contact's *parts*: the blank's nodes,
# the contact set (which node lies on which tool: its normal displacement is known, its
# contact force the residual of that row: the semi-inverse split), the pinching holder and
# Coulomb friction. The driver knows none of them; each gives its constraints, its forces and
# stiffness, and updates its set after each pass of Newton (docs/design.md).

p = DrawingProblem.from_scene(s, verbose=False)
print("parts:", ", ".join(type(part).__name__ for part in p.driver.parts))

# ## The driver's loop
#
# `driver.run(lam)` steps the load factor (the stroke fraction) to `lam`: each increment
# predicts the carrier, then runs passes of Newton on the parts' fixed constraints (with a
# line search bounded by the contact's trust region) until no part changes its set; a
# failing increment is cut back. Here we stop five times on the way and measure.

rows = []
for stroke in np.linspace(0.0, args.stroke, 6)[1:]:
    p.driver.run(stroke / s.tools.stroke)
    d, thin = cup.draw_in(p), cup.peak_thinning(p)
    rows.append((p.stroke, d["DX"], d["DD"], p.punch_force() / 1e3, thin["min_thickness_strain"],
                 len(p.driver.history), sum(h.iterations for h in p.driver.history)))

print(f"{'stroke_mm':>10} {'DX_mm':>7} {'DD_mm':>7} {'punch_kN':>9} {'thickness_strain':>17} "
      f"{'increments':>11} {'iterations':>11}")
for r in rows:
    print(f"{r[0]:10.1f} {r[1]:7.3f} {r[2]:7.3f} {r[3]:9.2f} {r[4]:17.4f} {r[5]:11d} {r[6]:11d}")

# ## Draw-in and thinning against the stroke
#
# The flange is drawn in more along the sides (DX) than at the corners (DD): the corners
# must compress in the hoop direction. The sheet thins most where it wraps the punch's nose,
# near the corner.

if args.plot or "ipykernel" in sys.modules:
    import matplotlib

    if args.plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = np.array(rows)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
    ax1.plot(a[:, 0], a[:, 1], "o-", label="DX (side)")
    ax1.plot(a[:, 0], a[:, 2], "s-", label="DD (corner)")
    ax1.set_xlabel("stroke (mm)")
    ax1.set_ylabel("draw-in (mm)")
    ax1.legend()
    ax2.plot(a[:, 0], a[:, 4], "o-")
    ax2.set_xlabel("stroke (mm)")
    ax2.set_ylabel("largest thinning (thickness strain)")
    fig.tight_layout()
    if args.plot:
        fig.savefig(args.plot, dpi=100)

# The checks: the draw-in grows with the stroke, more on the side than at the corner, and
# the sheet's z-forces balance (tools, holder and friction) to 1e-6 of the punch force.

DX, DD = np.array([r[1] for r in rows]), np.array([r[2] for r in rows])
assert np.all(np.diff(DX) > 0) and np.all(DX > DD), rows
assert p.force_balance() < 1e-6, p.force_balance()
print("OK")
