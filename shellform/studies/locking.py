"""Membrane locking: thin roll-ups and a curved roof, with and without the assumed membrane strain.

Two cases in which bending and membrane couple (docs/locking.md):

- **roll-up** (docs/rollup.md): the strip rolled into a full circle at t/L = 1e-2, 1e-3 and
  1e-4, 16 to 64 elements along it, with the sheet's compatible membrane strain ("compatible",
  the element before issue 13) and with the edge-tied assumed one ("assumed",
  shellform.assembly.assumed_membrane). Error: the largest tip distance from the exact arc over
  the load path, in units of L.
- **roof**: the Scordelis-Lo cylindrical roof as a shallow panel (R = 25, 50 long, t = 0.25,
  80 degrees of arc, z0 = -y^2/(2R) over the plane, nu = 0, diaphragm ends, free straight
  edges, uniform load 90 per unit plan area, a quarter model), deflection at the middle of the
  free edge relative to each model's own overkill value:
  the linear shallow-shell element, the paper's (P1 in-plane, its assumed membrane strain
  constant since issue 13) and with the effect cubic_membrane (u, v as w, quadratic membrane
  strain), both against the latter's overkill; and the sheet in linearised Kirchhoff-Love
  strains, compatible and assumed, against its own.

- **curved beam** (MacNeal and Harder's, demos/meshes/curved_beam.geo): a quarter ring clamped
  at one end, a unit shear at the other, in plane (a membrane that bends in plane on a curved
  outline) and out of plane; the paper's element and cubic_membrane on 6 x 1 to 48 x 8 meshes,
  against the published 0.08734 and 0.5022 (thin-beam theory; the plate model's torsion of a
  section 2 thicknesses wide is not the beam's, see docs/locking.md).

Wall time on the plot: each run's total less its set-up (mesh, kernels: compile_s in the table).
"""

import math
import tempfile
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform import demos, linear
from shellform.material import Hill79Material
from shellform.nonlinear.driver import Controls, ConvergenceFailure
from shellform.nonlinear.loads import SheetLoads
from shellform.nonlinear.problem import SheetProblem
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.scene import Scene, from_dict
from shellform.studies import rollup
from shellform.studies.common import observed_rates, plot_error_time

THICKNESSES = (1e-2, 1e-3, 1e-4)
ROLLUP_LEVELS = (16, 32, 64)
MEMBRANE = ("compatible", "assumed")

R, LENGTH, T_ROOF, E_ROOF, LOAD = 25.0, 50.0, 0.25, 4.32e8, 90.0
HALF_WIDTH = R * math.sin(math.radians(40.0))  # the planform of the 80 degree arc
ROOF_LEVELS = (8, 16, 32, 64)
ROOF_OVERKILL = {"linear": 128, "sheet": 128}
BEAM_LEVELS = ((6, 1), (12, 2), (24, 4), (48, 8))  # divisions along the arc, across
BEAM_REFERENCE = {"in-plane": 0.08734, "out-of-plane": 0.5022}
BEAM_GEO = demos.path("meshes/curved_beam.geo")
LEVELS = (ROLLUP_LEVELS, ROOF_LEVELS, BEAM_LEVELS)
QUICK_LEVELS = ((16,), (8, 16), ((6, 1),))
COLUMNS = ["case", "element", "membrane", "thickness", "n", "cells", "value", "reference", "error", "rate",
           "increments", "iterations", "compile_s", "total_s", "note"]


def rollup_row(n: int, thickness: float, membrane: str) -> dict:
    row = {"case": "roll-up", "element": "sheet", "membrane": membrane, "thickness": thickness, "n": n,
           "cells": 4 * n}
    t0 = time.perf_counter()
    try:
        r = rollup.solve(n, thickness=thickness, assumed_membrane=membrane == "assumed")
    except ConvergenceFailure as err:
        return {**row, "error": math.nan, "total_s": time.perf_counter() - t0, "compile_s": 0.0,
                "note": f"stopped: {err}"}
    return {**row, "value": r["full_circle_error"], "error": r["max_tip_error"], "increments": r["increments"],
            "iterations": r["iterations"], "compile_s": r["compile_s"], "total_s": r["total_s"], "note": ""}


def roof_scene(n: int, cubic: bool = False) -> Scene:
    """The linear shallow-shell roof on an n x round(0.64 n) quarter mesh (demos/scordelis_lo_roof.toml)."""
    effects = ["bending", "membrane", "shallow_curvature"] + (["cubic_membrane"] if cubic else [])
    return from_dict({
        "title": f"Scordelis-Lo roof (shallow), n={n}", "effects": effects,
        "geometry": {"lx": LENGTH, "ly": 2 * HALF_WIDTH, "region": "quarter"}, "surface": {"R2": R},
        "mesh": {"kind": "structured", "n": n},
        "material": {"E": E_ROOF, "nu": 0.0, "thickness": T_ROOF},
        "supports": {"left": "symmetry", "bottom": "symmetry", "right": "simply_supported", "top": "free"},
        "loads": {"pressure": -LOAD}})


def roof_linear(n: int, cubic: bool = False) -> dict:
    t0 = time.perf_counter()
    res = linear.solve(roof_scene(n, cubic))
    return {"case": "roof", "element": "linear shallow shell", "membrane": "cubic u" if cubic else "P1 u",
            "thickness": T_ROOF, "n": n,
            "cells": res.num_cells, "value": -res.value("w", 0.0, HALF_WIDTH), "compile_s": res.timings["compile_s"],
            "total_s": time.perf_counter() - t0}


def roof_sheet(n: int, membrane: str) -> dict:
    """The roof in the sheet's linearised Kirchhoff-Love strains over the exact z0 (one increment)."""
    t0 = time.perf_counter()
    p = SheetProblem.on_rectangle(
        MPI.COMM_WORLD, LENGTH, 2 * HALF_WIDTH, n, Hill79Material(E=E_ROOF, nu=0.0), T_ROOF,
        ("bending", "membrane") + (("assumed_membrane",) if membrane == "assumed" else ()),
        supports={"left": "symmetry", "bottom": "symmetry", "right": "simply_supported", "top": "free"},
        loads=SheetLoads(pressure=-LOAD), controls=Controls(initial_step=1.0, max_step=1.0), region="quarter",
        kappa0=np.array([[0.0, 0.0], [0.0, 1.0 / R]]))
    setup_s = time.perf_counter() - t0
    p.driver.run(1.0)
    return {"case": "roof", "element": "sheet (linearised)", "membrane": membrane, "thickness": T_ROOF, "n": n,
            "cells": p.model.num_cells, "value": -p.value("w", 0.0, HALF_WIDTH),
            "iterations": sum(h.iterations for h in p.driver.history), "compile_s": setup_s,
            "total_s": time.perf_counter() - t0}


def beam_scene(geo: Path, across: int, load: str, cubic: bool) -> Scene:
    """The curved beam from a .geo file, a unit force on the tip's vertices (consistent: half
    on the end vertices), along y (in plane, across the beam's axis there) or z."""
    ys = np.linspace(4.12, 4.32, across + 1)
    force = "fy" if load == "in-plane" else "fz"
    points = [{"x": 0.0, "y": float(y), force: (0.5 if k in (0, across) else 1.0) / across} for k, y in enumerate(ys)]
    return from_dict({
        "title": f"MacNeal-Harder curved beam, {load}", "geometry": {"shape": "file", "file": str(geo)},
        "effects": ["bending", "membrane"] + (["cubic_membrane"] if cubic else []),
        "mesh": {"kind": "unstructured", "n": 1}, "material": {"E": 1.0e7, "nu": 0.25, "thickness": 0.1},
        "supports": {"root": "clamped", "tip": "free", "inner": "free", "outer": "free"},
        "loads": {"point": points}})


def curved_beam(along: int, across: int, load: str, cubic: bool, folder: Path) -> dict:
    """Tip deflection along the load (mean over the tip's vertices) on an along x across mesh."""
    geo = folder / f"curved_beam_{along}x{across}.geo"
    text = BEAM_GEO.read_text().replace("along = 6;", f"along = {along};").replace("across = 1;", f"across = {across};")
    if MPI.COMM_WORLD.rank == 0:
        geo.write_text(text)
    MPI.COMM_WORLD.barrier()
    t0 = time.perf_counter()
    res = linear.solve(beam_scene(geo, across, load, cubic))
    comp = "v" if load == "in-plane" else "w"
    value = float(np.mean([res.value(comp, 0.0, float(y)) for y in np.linspace(4.12, 4.32, across + 1)]))
    ref = BEAM_REFERENCE[load]
    return {"case": f"curved beam, {load}", "element": "linear shallow shell",
            "membrane": "cubic u" if cubic else "P1 u",
            "thickness": 0.1, "n": along, "cells": res.num_cells, "value": value, "reference": ref,
            "error": (value - ref) / ref, "compile_s": res.timings["compile_s"], "total_s": time.perf_counter() - t0}


def _against(rows: list[dict], reference: float) -> list[dict]:
    for r in rows:
        r["reference"] = reference
        r["error"] = (r["value"] - reference) / reference
    for r, rate in zip(rows, observed_rates(rows, error="error")):
        r["rate"] = rate
    return rows


def _roof_series(part: list[dict], ref: float, label: str, rows: list, series: dict) -> None:
    """Errors of one family's roof rows against its overkill value, logged and collected."""
    for r in _against(part, ref):
        say(f"roof {label:28s} n={r['n']:3d} ({r['cells']} cells): w = {r['value']:.5f}, "
            f"{r['value'] / ref:.4f} of {ref:.5f}")
    rows += part
    series[f"roof, {label}"] = part


def run(outdir: Path, levels=LEVELS, thicknesses=THICKNESSES) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    roll_levels, roof_levels, beam_levels = levels
    rows, series = [], {}
    for t in thicknesses:
        for membrane in MEMBRANE:
            part = [rollup_row(n, t, membrane) for n in roll_levels]
            for r in part:
                say(f"roll-up t/L={t:g} {membrane:10s} n={r['n']:3d}: max tip error/L {r['error']:.2e} "
                    f"({r.get('increments', '-')} increments, {r['total_s']:.1f} s) {r['note']}")
            rows += part
            series[f"roll-up t/L={t:g}, {membrane}"] = [r for r in part if np.isfinite(r["error"])]
    ref = roof_linear(ROOF_OVERKILL["linear"], cubic=True)["value"]
    for cubic in (False, True):
        part = [roof_linear(n, cubic) for n in roof_levels]
        _roof_series(part, ref, f"linear element, {part[0]['membrane']}", rows, series)
    ref = roof_sheet(ROOF_OVERKILL["sheet"], "assumed")["value"]
    for membrane in MEMBRANE:
        _roof_series([roof_sheet(n, membrane) for n in roof_levels], ref, f"sheet {membrane}", rows, series)
    tmp = tempfile.mkdtemp(prefix="shellform-beam-") if MPI.COMM_WORLD.rank == 0 else None
    folder = Path(MPI.COMM_WORLD.bcast(tmp, root=0))  # the .geo copies of each mesh
    for load in BEAM_REFERENCE:
        for cubic in (False, True):
            part = [curved_beam(a, b, load, cubic, folder) for a, b in beam_levels]
            for r in part:
                say(f"curved beam {load:12s} {r['membrane']:8s} {r['n']:2d} along ({r['cells']} cells): "
                    f"{r['value']:.5f}, {r['value'] / r['reference']:.4f} of {r['reference']}")
            rows += part
            series[f"curved beam {load}, {part[0]['membrane']}"] = part
    write_csv(outdir / "locking.csv", rows, COLUMNS)
    plot_error_time(outdir / "locking_error_time.png", series,
                    "Membrane locking: error against wall time",
                    error="error", ylabel="|error| (roll-up: tip / L; roof: relative)")
    return rows
