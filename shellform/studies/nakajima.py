"""The Nakajima test: forming limits read numerically, one specimen width after another.

    shellform study nakajima --out docs/results/nakajima

The scene demos/nakajima.toml (a hemispherical punch of 100 mm, a die opening of 105 mm, the
specimen clamped beyond the die by a lock bead) with its specimen, demos/meshes/nakajima/
specimen.geo, at each waist width W of WIDTHS: a disc of 180 mm with circular notches leaving
a waist W wide, and the whole disc (W = 180). Each run draws until an element's margin to the
forming-limit curve reaches 0 ([process] stop_at_forming_limit): the limit dome height. Narrow
waists are pulled along x alone (uniaxial tension, minor strain about -r/(1 + r) of the major),
the whole disc is stretched in both directions (equibiaxial): their strain paths sweep the
forming-limit diagram from left to right.

Writes nakajima.csv (a row per width: the limit's stroke, where the critical element lies and
its strains there, the strain ratio of its path, the punch's force, counts and time),
strain_paths.csv (each width's critical element's path), nakajima.png (the paths over the
forming-limit curve, and the limit dome height against the width), nakajima.md (the table as
markdown) and per width its summary.json (W_<width>_summary.json). The runs themselves go to
out/runs/.
"""

import csv
import json
import re
from pathlib import Path

import numpy as np

from shellform import demos, scene
from shellform.contact.run import run as run_cup
from shellform.results.log import say
from shellform.results.tables import markdown_table, write_csv

SCENE = demos.path("nakajima.toml")
SPECIMEN = demos.path("meshes/nakajima/specimen.geo")
WIDTHS = (20, 40, 60, 80, 100, 110, 120, 130, 140, 160, 180)  # mm; 180: the whole disc
LEVEL = 24
QUICK_LEVELS = (8,)  # --quick: a narrow waist and the whole disc on a coarse mesh
QUICK_WIDTHS = (20, 180)
DIE_RADIUS = 52.5  # demos/nakajima.toml: a limit inside the die's opening is on the dome
COLUMNS = ["width_mm", "n", "cells", "limit_stroke_mm", "reached", "where", "x0_mm", "y0_mm", "major", "minor",
           "strain_ratio", "peak_thinning", "punch_force_kN", "increments", "newton_iterations", "cutbacks",
           "worst_balance", "wall_s", "stopped"]


def specimen(width: float, folder: Path) -> Path:
    """The specimen's .geo for a waist `width` wide (the demo's file with its W changed), written
    into folder."""
    text = SPECIMEN.read_text()
    text, count = re.subn(r"(?m)^W = [0-9.]+;", f"W = {width:g};", text)
    if count != 1:
        raise RuntimeError(f"{SPECIMEN}: no single line 'W = ...;' to set the width in")
    path = Path(folder) / f"specimen_W{width:g}.geo"
    path.write_text(text)
    return path.resolve()


def scene_of(width: float, n: int, folder: Path) -> scene.Scene:
    """The demo's scene for a waist `width` wide on mesh level n; the whole disc (the circle
    outline) where the width reaches the disc's diameter. No field series: the study compares
    the limits."""
    base = scene.load(SCENE)
    radius = float(re.search(r"(?m)^R = ([0-9.]+);", SPECIMEN.read_text()).group(1))
    specimen_name = f"waist {width:g} mm" if width < 2 * radius else "whole disc"
    changes = {"mesh.n": n, "output.vtx": False, "output.vtu": False,
               "title": f"Nakajima test, {specimen_name}: " + base.title.split(": ", 1)[-1]}
    if width >= 2 * radius:
        changes.update({"geometry.shape": "circle", "geometry.file": "", "geometry.radius": radius,
                        "geometry.region": "quarter", "supports": {"left": "symmetry", "bottom": "symmetry"}})
    else:
        changes["geometry.file"] = str(specimen(width, folder))
    return base.changed(changes)


def row(width: float, n: int, d: Path) -> tuple[dict, list[dict]]:
    """A width's row and its strain path, from its run folder d."""
    s = json.loads((d / "summary.json").read_text())
    with open(d / "strain_path.csv") as f:
        path = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    with open(d / "force_stroke.csv") as f:
        curve = list(csv.DictReader(f))
    limit, end = s.get("forming_limit_reached"), s["strain_path"]["end"]
    x0, y0 = s["strain_path"]["initial_xy_mm"]
    r = {"width_mm": width, "n": n, "cells": s["cells"],
         "limit_stroke_mm": limit["stroke_mm"] if limit else s["stroke_mm"], "reached": limit is not None,
         "where": "dome" if np.hypot(x0, y0) < DIE_RADIUS else "flange", "x0_mm": x0, "y0_mm": y0,
         "major": end["major"], "minor": end["minor"],
         "strain_ratio": end["minor"] / end["major"], "peak_thinning": s["min_thickness_strain"],
         "punch_force_kN": max(float(c["punch_force_kN"]) for c in curve),
         "increments": s["increments"], "newton_iterations": s["newton_iterations"], "cutbacks": s["cutbacks"],
         "worst_balance": s["over_the_stroke"]["force_balance"], "wall_s": s["wall_time_s"]["total"],
         "stopped": s["stopped"] or ""}
    return r, [{"width_mm": width, **p} for p in path]


def run(out: Path, levels=None, widths=None) -> list[dict]:
    """Every width on mesh level levels[0] (LEVEL by default; --quick: QUICK_WIDTHS on
    QUICK_LEVELS) into out/runs, then the tables and the plot."""
    out = Path(out)
    quick = levels == QUICK_LEVELS
    n = (levels or (LEVEL,))[0]
    widths = widths or (QUICK_WIDTHS if quick else WIDTHS)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    for w in widths:
        say(f"nakajima: waist {w:g} mm, n {n}")
        run_cup(scene_of(w, n, out / "runs"), out / "runs" / f"W_{w:g}")
    return tables(out, widths, n)


def tables(out: Path, widths, n: int) -> list[dict]:
    """The tables and the plot of the runs in out/runs (one per width, on mesh level n)."""
    out = Path(out)
    rows, paths = [], []
    for w in widths:
        d = out / "runs" / f"W_{w:g}"
        r, p = row(w, n, d)
        rows.append(r)
        paths += p
        (out / f"W_{w:g}_summary.json").write_text((d / "summary.json").read_text())
    write_csv(out / "nakajima.csv", rows, COLUMNS)
    write_csv(out / "strain_paths.csv", paths, ["width_mm", "stroke_mm", "major", "minor", "margin"])
    (out / "nakajima.md").write_text(markdown(rows))
    plot(out / "nakajima.png", rows, paths)
    return rows


def markdown(rows: list[dict]) -> str:
    return markdown_table(
        ["waist W mm", "cells", "limit dome height mm", "where", "critical element (initial x, y)",
         "major, minor at the limit", "minor / major", "peak thinning", "peak force kN",
         "increments, iterations, cut-backs", "worst balance", "wall s"],
        [[f"{'disc' if r['width_mm'] >= 180 else format(r['width_mm'], 'g')}", f"{r['cells']}",
          f"{r['limit_stroke_mm']:.2f}{'' if r['reached'] else ' (not reached)'}", f"{r['where']}",
          f"({r['x0_mm']:.1f}, {r['y0_mm']:.1f})", f"{r['major']:.3f}, {r['minor']:.3f}", f"{r['strain_ratio']:.2f}",
          f"{r['peak_thinning']:.3f}", f"{r['punch_force_kN']:.1f}",
          f"{r['increments']}, {r['newton_iterations']}, {r['cutbacks']}", f"{r['worst_balance']:.1e}",
          f"{r['wall_s']:.0f}"] for r in rows])


def plot(path: Path, rows: list[dict], paths: list[dict]) -> None:
    """Left: each width's strain path over the forming-limit curve, a dot where it ends. Right:
    the limit dome height against the width, marked by where the limit is reached (on the dome
    or on the flange), with the strain ratio there."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from shellform.results import fld

    (curve, label), _ = fld.curves(scene.load(SCENE).material)
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.6))
    e2 = np.linspace(-0.5, 0.5, 201)
    a.plot(e2, curve(e2), "r-", label=label)
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(rows)))
    for r, c in zip(rows, colours):
        p = [q for q in paths if q["width_mm"] == r["width_mm"]]
        name = "disc" if r["width_mm"] >= 180 else f"W {r['width_mm']:g}"
        a.plot([q["minor"] for q in p], [q["major"] for q in p], "-", color=c, label=name)
        a.plot([r["minor"]], [r["major"]], "o", color=c)
    a.set_xlabel("minor true strain")
    a.set_ylabel("major true strain")
    a.set_title("strain paths of the critical elements, to the forming limit", fontsize=9)
    a.grid(alpha=0.3)
    a.legend(fontsize=7, ncol=2)
    for where, style in (("dome", "ko"), ("flange", "rs")):
        mine = [r for r in rows if r["where"] == where]
        b.plot([r["width_mm"] for r in mine], [r["limit_stroke_mm"] for r in mine], style,
               label={"dome": "on the dome", "flange": "on the flange, beside the clamp"}[where])
    for r in rows:
        b.annotate(f"{r['minor'] / r['major']:.2f}", (r["width_mm"], r["limit_stroke_mm"]),
                   textcoords="offset points", xytext=(4, -10), fontsize=7)
    b.set_xlabel("waist width W (mm; 180: the whole disc)")
    b.set_ylabel("limit dome height (punch stroke, mm)")
    b.set_title("where the limit is reached, and the strain ratio minor / major there", fontsize=9)
    b.grid(alpha=0.3)
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
