"""Where the closed holder holds the flange down: the pinched nodes' net normal forces R0 (docs/contact.md,
"On fine meshes the holder opens early").

    .venv/bin/python scripts/pinch_edge_forces.py --n 71 --stroke 3

Draws the NUMISHEET'93 aluminium cup (shellform.studies.cup_benchmark's scene, n x n quarter,
the scene's increments) `--stroke` mm, then prints the holder's force F on the quarter, the sum
of the holding-down forces max(-R0, 0) over the pinched nodes as a share of F (the holder opens
when it passes 1), the largest of them, and per row of pinched nodes along the side y < 20 mm
(their x, innermost first) the number of nodes and their mean holding-down force.
"""

import argparse

import numpy as np

import shellform  # noqa: F401  (the DOLFINx runtime first)
from shellform.contact.problem import DrawingProblem
from shellform.studies.cup_benchmark import scene_for

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=35, help="elements along a side of the quarter (35: 2,450 cells)")
parser.add_argument("--stroke", type=float, default=3.0, help="mm drawn")
parser.add_argument("--rows", type=int, default=4, help="rows of pinched nodes printed")
args = parser.parse_args()

p = DrawingProblem.from_scene(scene_for(args.n, 5.0), verbose=False)
d = p.driver
d.run(args.stroke / 5.0)
net, pinched, X = d.net_normal_forces(), d.pinched, d.X[: d.n_owned]
F = d.holder.force
down = np.where(pinched, np.maximum(-net, 0.0), 0.0)
print(f"n {args.n} ({d.model.num_cells} cells), {args.stroke:g} mm: F = {F:.0f} N on the quarter, "
      f"{pinched.sum()} nodes pinched, sum of max(-R0, 0) = {down.sum():.0f} N = {down.sum() / F:.3f} F")
i = int(np.argmax(down))
print(f"largest: {down[i]:.1f} N at ({X[i, 0]:.2f}, {X[i, 1]:.2f}) mm")
side = pinched & (X[:, 1] < 20.0)
for x in np.unique(np.round(X[side, 0], 2))[: args.rows]:
    row = side & (np.abs(X[:, 0] - x) < 1e-2)
    print(f"  row x = {x:6.2f} mm: {row.sum():3d} nodes, holding-down force {down[row].mean():6.1f} N per node")
