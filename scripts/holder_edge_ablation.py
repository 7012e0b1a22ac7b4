"""The holding-down forces at the pinch's inner edge against the mesh, with the edge clamped or
hinged (an ablation for issue 32; numbers in docs/contact.md, "The pinch's edge: clamped or
hinged").

    python scripts/holder_edge_ablation.py N STROKE VARIANT

The NUMISHEET'93 aluminium cup (demos/numisheet93_aluminium.toml) on N x N to STROKE mm.
VARIANT "clamp": the pinch as it is (w and the slopes known on every pinched node); "hinge":
the pinched nodes on the pinched region's border (a neighbour not pinched) keep w known and
their slopes free, so that the border is a line support about which the sheet may turn. Prints
at each whole millimetre the holding-down sum, sum of max(-R0, 0) over the pinched nodes, as a
fraction of the holder's force F, the largest nodal share of F, the slope rows' reactions (the
clamp's moments), the punch force. About 6 s (N 16) to 4 minutes (N 50) to 3 mm on 2 cores.
"""

import sys
import time

import numpy as np

from shellform import scene
from shellform.assembly.sheet_element import BS
from shellform.contact.holder import PinchingHolder
from shellform.contact.nodes import W_SLOPES
from shellform.contact.problem import DrawingProblem

n, stroke, variant = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
s = scene.load("demos/numisheet93_aluminium.toml").changed({"mesh.n": n})
p = DrawingProblem.from_scene(s, verbose=False)
d = p.driver
neighbours = [set() for _ in range(d.n_local)]
for cell in d.model.dofs:
    for a in cell:
        neighbours[a].update(cell)

clamped = PinchingHolder.constrain


def hinged(self, c, lam):
    clamped(self, c, lam)
    pin = self.pinched
    border = np.array([pin[i] and not all(j < len(pin) and pin[j] for j in neighbours[i]) for i in range(len(pin))],
                      dtype=bool)
    c.known[border, W_SLOPES] = 0.0
    c.flags[border, W_SLOPES] = False
    c.stable[border, W_SLOPES] = False


if variant == "hinge":
    PinchingHolder.constrain = hinged


def record(dr):
    if abs(p.stroke - round(p.stroke)) > 1e-6:
        return
    R = dr.residual_full[: dr.n_owned * BS].reshape(-1, BS)
    pinched = dr.holder.pinched
    print(f"n {n} {variant} {p.stroke:.1f} mm: held down {p.holder_held_down()[0]:.4f} F, largest share "
          f"{p.holder_share():.4f} F, slope reactions {np.abs(R[pinched][:, W_SLOPES]).sum():.0f} N mm, "
          f"punch {p.punch_force() / 1e3:.3f} kN, holder closed {dr.holder.closed}", flush=True)


t0 = time.time()
d.run(stroke / s.tools.stroke, on_increment=record)
print(f"{time.time() - t0:.0f} s, {d.model.mesh.topology.index_map(2).size_global} cells")
