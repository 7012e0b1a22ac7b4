"""The square cup's tangent at a stroke: its softest modes on the free dofs, and the element
tangents with a negative eigenvalue (docs/locking.md, section 3).

    .venv/bin/python scripts/cup_tangent_modes.py --stroke 13.0 [--assumed-membrane]

Draws demos/square_cup.toml to the stroke (with the effect assumed_membrane added if asked),
assembles the tangent there and prints, for its three lowest eigenpairs on the free dofs (rows
that are not a Dirichlet or contact identity), the eigenvalue, the share of the mode's energy
in each carrier component and the nodes that carry most of it; then how many element tangents
have an eigenvalue below -1e-8 of their largest, and where the most negative are.
"""

import argparse
import dataclasses
from pathlib import Path

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np

from shellform.contact.problem import DrawingProblem
from shellform.scene import load

ROOT = Path(__file__).resolve().parents[1]

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--stroke", type=float, default=13.0, help="punch stroke in mm")
parser.add_argument("--assumed-membrane", action="store_true", help="add the effect assumed_membrane")
args = parser.parse_args()

s = load(ROOT / "demos" / "square_cup.toml")
if args.assumed_membrane:
    s = dataclasses.replace(s, effects=tuple(s.effects) + ("assumed_membrane",))
p = DrawingProblem.from_scene(s, verbose=False)
d, m = p.driver, p.model
d.run(args.stroke / s.tools.stroke)
d.residual(d.lam, tangent=True)

A = d.A.copy().convert("dense").getDenseArray()
A = 0.5 * (A + A.T)
free = np.where(np.abs(A - np.diag(np.diag(A))).sum(axis=1) > 0)[0]
ev, vectors = np.linalg.eigh(A[np.ix_(free, free)])
xy = m.V.tabulate_dof_coordinates()[:, :2]
print(f"stroke {args.stroke} mm, effects {', '.join(s.effects)}: {free.size} free dofs of {A.shape[0]}")
print(f"largest eigenvalue {ev[-1]:.4e}")
for k in range(3):
    mode = np.zeros(A.shape[0])
    mode[free] = vectors[:, k]
    energy = mode.reshape(-1, len(m.components)) ** 2
    share = energy.sum(axis=0) / energy.sum()
    top = np.argsort(energy.sum(axis=1))[::-1][:5]
    parts = ", ".join(f"{c} {f:.3f}" for c, f in zip(m.components, share) if f >= 0.001)
    print(f"mode {k}: eigenvalue {ev[k]:.4e} ({ev[k] / ev[-1]:.2e} of the largest); energy: {parts}; "
          f"nodes {np.round(xy[top], 1).tolist()}")

m.evaluate(d.q)
lowest = np.array([np.linalg.eigvalsh(0.5 * (K + K.T))[[0, -1]] for K in m.forms.matrices])
ratio = lowest[:, 0] / lowest[:, 1]
centroids = m.cell_coords.reshape(-1, 3, 3).mean(axis=1)[:, :2]
worst = np.argsort(ratio)[:5]
print(f"element tangents with an eigenvalue below -1e-8 of their largest: {int((ratio < -1e-8).sum())} "
      f"of {ratio.size}; most negative {np.round(ratio[worst], 6).tolist()} at {np.round(centroids[worst], 1).tolist()}")
