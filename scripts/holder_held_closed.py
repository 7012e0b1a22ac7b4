"""What the open holder costs in Newton iterations: the NUMISHEET'93 aluminium cup on n x n
(default 35: 2,450 cells) drawn to 40 mm with the holder held closed, beside the same cup as
cup-benchmark draws it (docs/contact.md, "On fine meshes the holder opens early").

    .venv/bin/python scripts/holder_held_closed.py [--n 35] [--out /tmp/holder_held_closed]

Held closed, the holder never opens. Its squeeze left S = F - sum max(-R0, 0) is read as
max(S, 0) in the opening test, so that the closed holder ends up holding more than F where the
flange pushes it up. That is a diagnostic, not a model: the answers at 40 mm differ. It shows
whether the late stroke's iterations come from the open holder or from the stroke itself.
Prints, for both runs, the iterations and contact passes per increment over four parts of the
stroke, the punch force and DX at 40 mm, and whether the holder opened.
"""

import argparse
import json
from pathlib import Path

import shellform  # noqa: F401  (DOLFINx runtime first)

from shellform.contact.run import run
from shellform.contact.semi_inverse import SemiInverseDriver
from shellform.studies.cup_benchmark import scene_for

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--n", type=int, default=35, help="quarter mesh n x n x 2 triangles")
parser.add_argument("--out", type=Path, default=Path("/tmp/holder_held_closed"))
args = parser.parse_args()

update_holder = SemiInverseDriver._update_holder


def held_closed(self, x, under, net):
    """_update_holder with the opening test blind to a negative squeeze (the faces' split is
    unchanged: it takes max(S, 0) anyway)."""
    h, squeeze_left = self.holder, type(self.holder).squeeze_left
    h.squeeze_left = lambda pinched, n: max(squeeze_left(h, pinched, n), 0.0)
    try:
        return update_holder(self, x, under, net)
    finally:
        del h.squeeze_left


for name, patch in (("as drawn", update_holder), ("held closed", held_closed)):
    SemiInverseDriver._update_holder = patch
    out = args.out / name.replace(" ", "_")
    summary = run(scene_for(args.n), out)
    history = json.loads((out / "history.json").read_text())
    parts = []
    for a, b in ((0.0, 9.3), (9.3, 18.3), (18.3, 29.3), (29.3, 40.1)):
        inc = [h for h in history if a < 40.0 * h["lam"] <= b]
        parts.append(f"{a:g}-{min(b, 40):g} mm: {sum(h['iterations'] for h in inc) / len(inc):.2f} iterations, "
                     f"{sum(h['contact']['passes'] for h in inc) / len(inc):.2f} passes")
    opened = any(not h["contact"]["holder_closed"] for h in history)
    print(f"{name}: {summary['newton_iterations']} iterations, {summary['wall_time_s']['total']:.0f} s, "
          f"force {summary['punch_force_kN'][-1]['force']:.3f} kN, DX {summary['draw_in_mm'][-1]['DX']:.3f} mm "
          f"at 40 mm, holder opened: {opened}; per increment " + "; ".join(parts), flush=True)
SemiInverseDriver._update_holder = update_holder
