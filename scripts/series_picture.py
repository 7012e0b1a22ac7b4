"""A picture of a tool scene's VTU series (docs/results.md): the last step of DIR/cup.pvd
coloured by a field, with the punch, the die and the blank holder at their positions.

    python scripts/series_picture.py DIR [--field thickness_strain] [--png cup_series.png]

What it does is what docs/results.md's pyvista snippet does, with a camera and a colour bar.
"""

import argparse
from pathlib import Path

import numpy as np
import pyvista

from shellform.results.fields import offscreen_backend


def last_step(pvd: Path):
    reader = pyvista.get_reader(str(pvd))
    reader.set_active_time_point(len(reader.time_values) - 1)
    return reader.active_time_value, reader.read()[0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path, help="a tool scene's output folder (shellform run ... --out DIR)")
    parser.add_argument("--field", default="thickness_strain", help="a point or cell field of cup.pvd")
    parser.add_argument("--png", type=Path, default=Path("cup_series.png"), help="the picture to write")
    args = parser.parse_args(argv)
    offscreen_backend()
    stroke, cup = last_step(args.folder / "cup.pvd")
    values = cup[args.field]
    top = float(np.abs(values).max()) or 1.0
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 750))
    pl.add_mesh(cup, scalars=args.field, cmap="coolwarm", clim=(-top, top), show_edges=True, edge_color="#555555",
                line_width=0.3, scalar_bar_args={"title": f"{args.field} (white 0)"})
    for name, colour in (("punch", "#9a9a9a"), ("die", "#6f6f6f"), ("blank_holder", "#c8b070")):
        if (args.folder / f"{name}.pvd").exists():  # the tools lifted apart along z, to show the sheet
            lift = {"punch": 1.0, "die": -0.3, "blank_holder": 0.6}[name] * float(np.ptp(cup.points[:, 2]))
            pl.add_mesh(last_step(args.folder / f"{name}.pvd")[1].translate((0, 0, lift)), color=colour,
                        opacity=0.25, show_edges=False)
    pl.add_text(f"stroke {stroke:g} mm: the modelled quarter; the tools moved apart along z", font_size=10)
    L = float(np.ptp(cup.points[:, 0]))
    pl.camera_position = [(-0.9 * L, -1.2 * L, 1.3 * L), (0.45 * L, 0.35 * L, -0.25 * L), (0.0, 0.0, 1.0)]
    pl.screenshot(str(args.png))
    pl.close()


if __name__ == "__main__":
    main()
