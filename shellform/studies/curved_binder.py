"""Curved binders: a channel and a square cup, each closed onto a cylindrical binder by the
holder (the binder wrap), then drawn; friction per tool.

    shellform study curved-binder --out docs/results/curved_binder

The channel: demos/channel_binder.toml (a hat channel along y over a die whose binder face is a cylinder of
R = 150 mm about the x axis, the holder at a gap of 0.8 mm, t 0.78 mm; the ram brings the holder
down by binder_rise = 6 mm, then the punch draws the channel 12 mm deep; shellform/tools/
channel.py) in these runs:

    lubricated punch      the demo: punch 0.02, die and holder 0.12; n 16 and n 24
    one coefficient       0.12 on every tool
    dry punch             punch 0.3, die and holder 0.12
    flat binder           the demo's friction over a flat binder (binder_radius 0, binder_rise
                          0, the stroke 12.5 mm: the same channel depth)

Measured on each, where the holder has closed (the ram at binder_rise): the wrap, the largest
distance of the flange's mid-surface (|x| beyond the binder's edge + 2 mm) from the radius
R + t/2 of the wrapped blank (`wrap_flange_mm`: within the holder's clearance 0.02 mm and the
contact's tolerance it lies on the die's face), and of the centre line over the opening
(`wrap_centre_mm`, pressed by no binder); at the end, the punch force (kN, whole blank; `force_kN`
at the end, `force_peak_kN` the largest of the draw), the draw-in DX of the blank's edge on
y = 0, the peak thinning (thickness strain) and where it began. Pictures of the demo's run:
channel_wrap.png (closed onto the binder) and channel.png (drawn). Writes channel.csv and
channel.md.

The cup: demos/square_cup_curved_binder.toml (the square cup's punch, a die whose top is a
cylinder of R = 500 mm about the x axis and the concentric holder, from STEP files written by
scripts/curved_binder_step.py; binder_rise 6 mm, the cup 25 mm deep; n 16): the same wrap
(the flange: beyond the die's opening and shoulder, 42 mm, by 2 mm) and at the end the punch
force, DX, DY (the draw-in along the binder's straight and curved directions), DD, the peak
thinning. Pictures cup_wrap.png, cup.png; cup.csv and cup.md.
"""

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform import demos, scene
from shellform.contact.problem import DrawingProblem
from shellform.results import cup
from shellform.results.log import say
from shellform.results.tables import markdown_table, write_csv

SCENE = demos.path("channel_binder.toml")
CUP_SCENE = demos.path("square_cup_curved_binder.toml")
CUP_RADIUS = 500.0  # the die's binder face in demos/meshes/curved_binder/ (scripts/curved_binder_step.py)
CUP_LEVEL = 16
FLAT = {"tools.binder_radius": 0.0, "tools.binder_rise": 0.0, "tools.stroke": 12.5}
CASES = (  # name, changes, n
    ("lubricated punch", {}, 16),
    ("lubricated punch", {}, 24),
    ("one coefficient", {"tools.punch_friction": 0.12}, 16),
    ("dry punch", {"tools.punch_friction": 0.3}, 16),
    ("flat binder", FLAT, 16),
)
QUICK_LEVELS = (6,)  # --quick: the demo alone, coarse
CUP_COLUMNS = ["n", "cells", "mu_punch", "mu_die", "mu_holder", "stroke_mm", "wrap_flange_mm", "force_kN",
               "force_peak_kN", "DX_mm", "DY_mm", "DD_mm", "peak_thinning", "thinning_x0_mm", "thinning_y0_mm",
               "increments", "iterations", "cutbacks", "wall_s"]
COLUMNS = ["case", "n", "cells", "mu_punch", "mu_die", "mu_holder", "binder_radius_mm", "stroke_mm",
           "wrap_flange_mm", "wrap_centre_mm", "force_kN", "force_peak_kN", "DX_mm", "peak_thinning",
           "thinning_x0_mm", "thinning_y0_mm", "increments", "iterations", "cutbacks", "wall_s"]


def wrap(p, radius: float, flange) -> tuple[float, float]:
    """(flange, centre): the largest distance of the mid-surface from the wrapped radius
    radius + t/2 about the x axis through z = -(radius + t/2) (module docstring), over the
    nodes whose initial (x, y) pass `flange`, and over the centre line x = 0; all ranks."""
    d, t = p.driver, p.scene.material.thickness
    rm = radius + t / 2
    X, x = d.model.mesh.geometry.x[: d.n_owned], d.positions()
    off = np.abs(np.hypot(x[:, 1], x[:, 2] + rm) - rm)
    centre = np.abs(X[:, 0]) < 1e-9
    return tuple(p.comm.allreduce(float(off[m].max(initial=0.0)), op=MPI.MAX) for m in (flange(X), centre))


def drawn(s, radius: float, flange, pictures: Path | None = None, name: str = "") -> dict:
    """The scene s drawn: closed onto its binder (radius, over the nodes `flange` passes) where
    it has a binder_rise, then to its stroke; with `pictures` (a folder), name_wrap.png and
    name.png there. Returns its measures."""
    t0 = time.perf_counter()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    forces = []
    record = lambda _: forces.append(p.punch_force())  # noqa: E731
    flange_off = centre = float("nan")
    if s.tools.binder_rise > 0:
        d.run(s.tools.binder_rise / s.tools.stroke, on_increment=record)
        flange_off, centre = wrap(p, radius, flange)
        if pictures is not None:
            cup.picture(pictures / f"{name}_wrap.png", p,
                        f"{s.title}: closed onto the binder ({p.stroke:.1f} mm)")
    d.run(1.0, on_increment=record)
    if pictures is not None:
        cup.picture(pictures / f"{name}.png", p, f"{s.title}: drawn ({p.stroke:.1f} mm)")
    thin, draw_in, mu = cup.peak_thinning(p), cup.draw_in(p), s.tools.friction_per_tool()
    return {"n": s.mesh.n, "cells": p.model.mesh.topology.index_map(2).size_global,
            "mu_punch": mu["punch"], "mu_die": mu["die"], "mu_holder": mu["holder"], "stroke_mm": p.stroke,
            "wrap_flange_mm": flange_off, "wrap_centre_mm": centre, "force_kN": forces[-1] / 1e3,
            "force_peak_kN": max(forces) / 1e3, "DX_mm": draw_in["DX"], "DY_mm": draw_in["DY"], "DD_mm": draw_in["DD"],
            "peak_thinning": thin["min_thickness_strain"], "thinning_x0_mm": thin["where_initial_xy_mm"][0],
            "thinning_y0_mm": thin["where_initial_xy_mm"][1], "increments": len(d.history),
            "iterations": sum(h.iterations for h in d.history), "cutbacks": sum(h.cutbacks for h in d.history),
            "wall_s": time.perf_counter() - t0}


def channel(name: str, changes: dict, n: int, pictures: Path | None = None) -> dict:
    """One run of the channel's scene with `changes` on mesh level n (module docstring)."""
    s = scene.load(SCENE).changed({"mesh.n": n, **changes})
    t = s.tools
    edge = t.die_half_width + t.die_profile_radius + 2.0
    row = drawn(s, t.binder_radius, lambda X: X[:, 0] > edge, pictures, "channel")
    return {"case": name, "binder_radius_mm": t.binder_radius, **row}


def square_cup(n: int = CUP_LEVEL, pictures: Path | None = None) -> dict:
    """The square cup over the cylindrical binder from CAD files (module docstring)."""
    s = scene.load(CUP_SCENE).changed({"mesh.n": n})
    edge = 42.0 + 2.0  # the die's opening and shoulder (37 + 5 mm), and 2 mm
    return drawn(s, CUP_RADIUS, lambda X: np.maximum(np.abs(X[:, 0]), np.abs(X[:, 1])) > edge, pictures, "cup")


def markdown(rows: list[dict]) -> str:
    head = ["run", "mu punch / die / holder", "wrap: flange, centre line (mm)", "punch force end, peak (kN)",
            "DX (mm)", "peak thinning (initial x, y)", "increments, iterations, cut-backs", "wall (s)"]
    body = [[f"{r['case']} n {r['n']} ({r['cells']} cells)",
             f"{r['mu_punch']:g} / {r['mu_die']:g} / {r['mu_holder']:g}",
             "flat" if np.isnan(r["wrap_flange_mm"]) else f"{r['wrap_flange_mm']:.4f}, {r['wrap_centre_mm']:.3f}",
             f"{r['force_kN']:.2f}, {r['force_peak_kN']:.2f}", f"{r['DX_mm']:.3f}",
             f"{r['peak_thinning']:.4f} ({r['thinning_x0_mm']:.1f}, {r['thinning_y0_mm']:.1f})",
             f"{r['increments']}, {r['iterations']}, {r['cutbacks']}", f"{r['wall_s']:.0f}"] for r in rows]
    return markdown_table(head, body)


def cup_markdown(r: dict) -> str:
    head = ["run", "mu punch / die / holder", "wrap: flange (mm)", "punch force end, peak (kN)", "DX, DY, DD (mm)",
            "peak thinning (initial x, y)", "increments, iterations, cut-backs", "wall (s)"]
    body = [[f"square cup over R {CUP_RADIUS:g} mm, n {r['n']} ({r['cells']} cells)",
             f"{r['mu_punch']:g} / {r['mu_die']:g} / {r['mu_holder']:g}", f"{r['wrap_flange_mm']:.4f}",
             f"{r['force_kN']:.2f}, {r['force_peak_kN']:.2f}", f"{r['DX_mm']:.3f}, {r['DY_mm']:.3f}, {r['DD_mm']:.3f}",
             f"{r['peak_thinning']:.4f} ({r['thinning_x0_mm']:.1f}, {r['thinning_y0_mm']:.1f})",
             f"{r['increments']}, {r['iterations']}, {r['cutbacks']}", f"{r['wall_s']:.0f}"]]
    return markdown_table(head, body)


def run(outdir: Path, levels: tuple | None = None) -> list[dict]:
    """The channel's CASES and the square cup, or with `levels` the channel's demo alone on
    those mesh levels."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    cases = CASES if levels is None else tuple(("lubricated punch", {}, n) for n in levels)
    rows = []
    for i, (name, changes, n) in enumerate(cases):
        rows.append(channel(name, changes, n, outdir if i == 0 else None))
        r = rows[-1]
        say(f"channel over a curved binder, {name}, n {n}: force {r['force_kN']:.3f} kN, DX {r['DX_mm']:.3f} mm, "
            f"peak thinning {r['peak_thinning']:.4f}, wrap {r['wrap_flange_mm']:.4f} mm, {r['wall_s']:.0f} s")
    write_csv(outdir / "channel.csv", rows, COLUMNS)
    (outdir / "channel.md").write_text(markdown(rows))
    if levels is None:
        r = square_cup(pictures=outdir)
        say(f"square cup over a curved binder: force {r['force_kN']:.3f} kN, DX {r['DX_mm']:.3f} mm, "
            f"peak thinning {r['peak_thinning']:.4f}, wrap {r['wrap_flange_mm']:.4f} mm, {r['wall_s']:.0f} s")
        write_csv(outdir / "cup.csv", [r], CUP_COLUMNS)
        (outdir / "cup.md").write_text(cup_markdown(r))
    return rows
