"""A strip squeezed between flat faces and a strip drawn through a gap: the ironing of the sheet
(shellform.material.ironing) against the closed forms of plane-strain flow.

Both strips are held flat (w and its slopes zero) and in plane strain (v and its slopes zero),
a half strip with symmetry on the left; the faces are given as a clearance over each cell, the
way the tools give it in a drawn cup. The material is the strip study's mild steel (Swift,
von Mises), whose plane-strain flow stress is (2 / sqrt 3) sigma_f((2 / sqrt 3) eps) at the
strain eps = ln(t0 / t).

- squeezed: the clearance falls uniformly from t0 to t1 over the whole strip (plane-strain
  compression between frictionless platens, Hill 1950, The Mathematical Theory of Plasticity,
  ch. VII). The sheet comes out at t1 and the platens press with p = (2 / sqrt 3) sigma_f.
- drawn: the clearance is t1 over a die of length `die` in the current configuration, infinite
  elsewhere; the strip's right end is pulled through it. In steady flow through frictionless
  faces every element of the strip is thinned from t0 to t1 in plane strain, and the drawing
  stress at the exit is the ideal work per unit volume (Hosford and Caddell, Metal Forming:
  Mechanics and Metallurgy, 4th ed., ch. 6, drawing with no friction and no redundant work):

      sigma_d = int_0^ln(t0/t1) (2 / sqrt 3) sigma_f((2 / sqrt 3) e) de,   F / w = t1 sigma_d.

  A shell has no through-thickness shear, so its flow has no redundant work, the closed form's
  own assumption; the elastic strains (sigma / E, about 0.2 %) are left out of it.

    shellform study ironing --out docs/results/ironing

writes ironing.csv (thickness, pressure and drawing force against the closed forms) and
ironing_draw.csv (the drawn strip's force and exit thickness per increment); about 40 s.
"""

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI
from scipy.integrate import quad

from shellform.material import flow_stress
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.parts import Change, Part
from shellform.nonlinear.problem import SheetProblem
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.strip import effects, mild_steel

T0 = 1.0
EFFECTS = effects(True) + ("ironing",)
FLAT = {("all", k): 0.0 for k in ("v", "v_x", "v_y", "w", "w_x", "w_y")}  # flat, plane strain


def plane_strain_stress(mat, eps: float) -> float:
    """(2 / sqrt 3) sigma_f((2 / sqrt 3) eps): von Mises's plane-strain flow stress at the
    thickness strain -eps (rigid-plastic)."""
    c = 2.0 / np.sqrt(3.0)
    return c * float(flow_stress(c * eps, mat.pack())[0])


def drawing_stress(mat, t1: float, t0: float = T0) -> float:
    """sigma_d = int_0^ln(t0/t1) plane_strain_stress de (module docstring)."""
    return quad(lambda e: plane_strain_stress(mat, e), 0.0, np.log(t0 / t1))[0]


class Platens(Part):
    """Flat frictionless faces whose clearance falls from t0 to t1 as lambda goes from 0 to 1."""

    def __init__(self, model, t1: float):
        self.model, self.t1 = model, t1

    def start(self, lam: float, predicting: bool) -> None:
        self.model.squeeze(np.full(self.model.num_cells, T0 - lam * (T0 - self.t1)))


class Die(Part):
    """Flat frictionless faces over start <= x <= start + entry + land in the current
    configuration: their clearance narrows linearly from t0 to t1 over the entry, then stays t1
    over the land. A cell is pressed while its centre lies under them (the set is updated after
    every pass, as a contact set is), with the clearance at its centre's current position and its
    gradient along x (the inclined faces push the strip back: the element's force). The die
    closes on the strip as lambda goes from 0 to `close`: its clearance is
    t0 - (t0 - c(x)) min(1, lambda / close)."""

    def __init__(self, model, t1: float, start: float, entry: float, land: float, close: float):
        self.model, self.t1, self.start_x, self.entry, self.land, self.close = model, t1, start, entry, land, close
        self.q, self.lam = None, 0.0
        self.over = np.zeros(model.num_cells, dtype=bool)

    def bind(self, driver) -> None:
        self.q = driver.q

    def centres(self) -> np.ndarray:
        """The owned cells' centres' current x."""
        m = self.model
        u = self.q.x.array[m.dofs * len(m.components)]  # u at the cells' vertices
        return m.cell_centres()[:, 0] + u.mean(axis=1)

    def _set(self, decide: bool) -> int:
        """The cells under the faces (with `decide`; else the set stays) and their clearances
        at the current positions, with the gradient dc/dx at their vertices."""
        x = self.centres() - self.start_x
        over = (x >= 0.0) & (x <= self.entry + self.land) if decide else self.over
        closing = min(1.0, self.lam / self.close)
        shape = T0 + (self.t1 - T0) * np.clip(x / self.entry, 0.0, 1.0)
        slope = np.where((x >= 0.0) & (x <= self.entry), (self.t1 - T0) / self.entry * closing, 0.0)
        gradient = np.zeros((self.model.num_cells, 3, 3))
        gradient[:, :, 0] = np.where(over, slope, 0.0)[:, None]
        changes = int(self.model.mesh.comm.allreduce(int(np.sum(over != self.over)), op=MPI.SUM))
        self.over = over
        self.model.squeeze(np.where(over, T0 - (T0 - shape) * closing, np.inf), gradient)
        return changes

    def start(self, lam: float, predicting: bool) -> None:
        self.lam = lam
        self._set(decide=True)

    def constrain(self, c, lam: float) -> None:
        """No constraint: the clearances follow this iterate's positions."""
        self._set(decide=False)

    def update(self, lam: float, changes: int) -> Change:
        n = self._set(decide=True)
        return Change(changes=n, line=f"{n} cells in or out of the die" if n else "")


def squeezed(mat, t1: float, steps: int = 10, n: int = 2, comm=MPI.COMM_WORLD):
    """The strip squeezed to t1; returns (problem, thickness strain, mean face pressure)."""
    p = SheetProblem.on_rectangle(
        comm, 4.0, 2.0, n, mat, T0, EFFECTS, region="quarter", supports={"left": "symmetry", "bottom": "symmetry"},
        prescribed=FLAT, controls=Controls(initial_step=1.0 / steps, max_step=1.0 / steps, rtol=1e-8),
        parts=[lambda m: Platens(m, t1)])
    p.driver.run(1.0)
    return p, _mean(p.model.thickness_strain(), comm), _mean(p.model.face_pressure, comm)


def drawn(mat, t1: float, pull: float, cells: int = 40, length: float = 20.0, die=(6.0, 2.0, 2.0, 0.25),
          steps: int = 40, comm=MPI.COMM_WORLD):
    """The strip of half length `length` drawn through the Die (start, entry, land, close) by
    pulling its right end `pull`; returns (problem, rows): per increment the pull, the force per
    unit width on the right end, and the mean thickness strain of the cells drawn through the die
    (left of it at the start, past its exit now)."""
    held = dict(FLAT)
    held[("right", "u")] = pull
    p = SheetProblem.on_rectangle(
        comm, 2 * length, 2.0 * length / cells, cells, mat, T0, EFFECTS, region="quarter",
        supports={"bottom": "symmetry"}, prescribed=held,
        controls=Controls(initial_step=1.0 / steps, max_step=1.0 / steps, rtol=1e-8, easy_iterations=6,
                          max_iterations=40),
        parts=[lambda m: Die(m, t1, *die)])
    die_part = p.driver.parts[0]
    rows = []

    before = p.model.cell_centres()[:, 0] < die[0]  # the strip's cells left of the die at the start

    def record(d):
        x = die_part.centres()
        past = before & (x > die[0] + die[1] + die[2])
        e33 = p.model.thickness_strain()
        count = comm.allreduce(int(past.sum()), op=MPI.SUM)
        past_e33 = comm.allreduce(float(e33[past].sum()), op=MPI.SUM) / max(count, 1)
        width = 2.0 * length / cells / 2.0  # the half strip's width
        rows.append({"pull": d.lam * pull, "force_per_width": p.reaction("right", "u") / width,
                     "exit_thickness_strain": past_e33, "cells_past_exit": count})

    p.driver.run(1.0, on_increment=record)
    return p, rows


def _mean(a, comm) -> float:
    a = np.asarray(a)
    return comm.allreduce(float(a.sum()), op=MPI.SUM) / comm.allreduce(a.size, op=MPI.SUM)


COLUMNS = ["case", "quantity", "model", "closed_form", "rel_error", "seconds"]


def run(outdir: Path) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    mat, rows = mild_steel(), []
    t = time.perf_counter()
    _, e33, pressure = squeezed(mat, 0.8)
    seconds = time.perf_counter() - t
    closed = plane_strain_stress(mat, np.log(T0 / 0.8))
    case = "squeezed to 0.8 t0"
    rows += [{"case": case, "quantity": "thickness / t0", "model": float(np.exp(e33)), "closed_form": 0.8},
             {"case": case, "quantity": "face pressure (MPa)", "model": pressure, "closed_form": closed}]
    t = time.perf_counter()
    _, path = drawn(mat, 0.9, 5.0, cells=80)
    seconds2 = time.perf_counter() - t
    last = path[-1]
    u = np.array([r["pull"] for r in path])
    F = np.array([r["force_per_width"] for r in path])
    steady = u >= 2.5  # the die closed and filled
    mean = np.trapezoid(F[steady], u[steady]) / (u[steady][-1] - u[steady][0])
    case = "drawn 5 mm through 0.9 t0"
    exit_t = float(np.exp(path[-1]["exit_thickness_strain"]))
    rows += [{"case": case, "quantity": "exit thickness / t0", "model": exit_t, "closed_form": 0.9},
             {"case": case, "quantity": "mean drawing force from 2.5 mm (N/mm)", "model": mean,
              "closed_form": 0.9 * drawing_stress(mat, 0.9)}]
    for r in rows:
        r["rel_error"] = r["model"] / r["closed_form"] - 1.0
        r["seconds"] = seconds if r["case"].startswith("squeezed") else seconds2
        say(f"ironing: {r['case']}: {r['quantity']} {r['model']:.5g} against {r['closed_form']:.5g} "
            f"({100 * r['rel_error']:+.2f} %)")
    write_csv(outdir / "ironing.csv", rows, COLUMNS)
    write_csv(outdir / "ironing_draw.csv", path, list(path[0]))
    return rows
