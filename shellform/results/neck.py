"""Where the sheet starts to neck: the watch over the sections' membrane stability.

A neck is a material instability: the material point can no longer carry more nominal force
for more stretch, and a local model then localises the strain into one row of cells. Its onset
is where a cell's membrane stability (shellform.material.stability, SheetModel.membrane_stability:
the smallest eigenvalue of the tangent of the nominal membrane force, per unit initial
thickness) first reaches 0; in uniaxial tension that is Considere's force maximum.

A neck thins the sheet: only the cells thinner than the blank (thickness strain below 0) are
watched. Where the sheet thickens, compressed in the mean (a cup's flange and its drawn-in rim,
a rim ironed between the tools), the membrane tangent may turn indefinite too, but that is the
membrane's own wrinkling, which the shell's bending resists, or the faces' pressure, not a neck.
Given the cells' major strains, a cell is watched only on the stretching side of the forming-limit
diagram, from uniaxial tension to equibiaxial stretching: where its thinning is at least
STRETCHED / (1 + r) of its major strain (r the sheet's largest Lankford coefficient), as uniaxial
tension thins the sheet by 1 / (1 + r) of its major strain (a proportional path of minor to
major strain beta: -e33 = (1 + beta) eps1, beta = -r / (1 + r)). Left of uniaxial tension, where
the flange is drawn in hoop compression towards pure shear (beta -> -1: the flange drawn over
the die's corner into the wall), a material point may pass its force maximum (Swift's diffuse
instability on the drawing side) and the sheet still draws on stably, barely thinning: there a
local neck needs eps1 = n / (1 + beta) (Hill's zero-extension criterion, Hill 1952), without
bound as beta -> -1, and the forming-limit view ([output] fld) is the measure of a drawn part's
failure (docs/plastic.md).

Where the run stops at the neck ([process] stop_at_neck), the watch shortens the steps ahead
of the onset (`ahead`), so that the run ends close to it: from the least stability at the
last two increments it extrapolates linearly where it reaches 0, and where the next step would
go past that, the step is bounded to half the distance to it, but not below a quarter of the
step it first bounded, so that the onset falls into a short increment (its interpolation the
more accurate, the neck's first increments the easier for Newton) and the approach takes a few
increments, not a halving without end. Only a least stability below PLASTIC of the first
increment's (an elastic sheet's) is extrapolated: above it its fall is the transition from
elastic to plastic (a cup's least stability falls from some 36,000 MPa at its first increment
to 8,000 in its first plastic one), which a straight line through two increments would see
reach 0 within a step; near a neck it is a few hundred MPa or less (Considere's d sigma / d eps
- sigma, against E).

The watch is told the sheet's state after every converged increment by the listener `Necking`,
one for both routes (a tool scene's run, contact/run.py with results/drawing.py; a sheet scene's,
nonlinear/run.py with results/sheet.py; the driver knows nothing of it), which reads the
problem's public measurements (cell_fields, membrane_stability, cell_centres). It records the
onset once: the load measure (the stroke of a tool scene, the load factor of a sheet scene,
both the driver's load factor times a unit) interpolated linearly between the last increment
whose least stability is positive and the first whose is not (the least over all cells of
every rank at each: where the weakest cell changes between them, a lower bound of the onset),
the initial x, y of the cell weakest at that first increment, and its thickness strain
interpolated to the onset the same way. `reached` stays True from then on; a run with
[process] stop_at_neck ends its stroke or load path there, one without goes on and only
reports it (summary.json "neck", null without a neck).
"""

import json
from pathlib import Path

import numpy as np

from shellform.results.listeners import EndOfStroke, Listener, Run

PLASTIC = 0.01  # of the first increment's least stability: below it, its fall is extrapolated to a neck
STRETCHED = 0.9  # of uniaxial tension's thinning share 1 / (1 + r): the least a watched cell's path thins


class NeckReached(EndOfStroke):
    """A run's stroke or load path ends: the sheet starts to neck ([process] stop_at_neck)."""


class NeckWatch:
    """The onset of the neck along a run. at, place: the names of the load measure and of the
    place in `onset` ("stroke_mm", "initial_xy_mm" for tool scenes; "load_factor", "initial_xy"
    for sheet scenes); r: the sheet's largest Lankford coefficient (Scene.largest_r)."""

    def __init__(self, comm, at: str = "stroke_mm", place: str = "initial_xy_mm", r: float = 1.0):
        self.comm, self.at, self.place = comm, at, place
        self.thinning = STRETCHED / (1.0 + r)  # the least share of its major strain a watched cell has thinned
        self.last = None  # (load measure, least stability) of the last increment
        self.thickness = None  # the local cells' thickness strains at the last increment
        self.onset = None  # {at, "increment_" + at, place, "thickness_strain", "stability"}, or None
        self.before = None  # (load measure, least stability) of the increment before the last
        self.first = None  # the least stability at the first increment with a thinned cell (an elastic sheet's)
        self.shortest = None  # the least step `ahead` bounds to: a quarter of the first it bounded

    def carry(self, onset: dict | None, at: float) -> None:
        """Keep the onset an earlier run found at or before `at` (a resumed run's state), so that
        a resume reports where the neck started, not where the resumed run first sees it."""
        if onset and self.onset is None and onset.get(self.at) is not None and onset[self.at] <= at:
            self.onset = dict(onset)

    def reached(self, at: float, stability, thickness_strain, centres, major_strain=None) -> bool:
        """After an increment at the load measure `at`: the local cells' stability, thickness
        strain and initial centres (cells, 2), and where given their major strains. Whether the
        neck has started (now or before); the cells that have not thinned, and given the major
        strains those drawn more than stretched, are not watched (module docstring)."""
        thickness_strain = np.asarray(thickness_strain, dtype=float)
        watched = thickness_strain < 0.0
        if major_strain is not None:
            watched &= -thickness_strain >= self.thinning * np.asarray(major_strain, dtype=float)
        stability = np.where(watched, np.asarray(stability, dtype=float), np.inf)
        local = float(np.nanmin(stability)) if np.any(np.isfinite(stability)) else np.inf
        least, owner = min(self.comm.allgather((local, self.comm.rank)))
        if least <= 0.0 and self.onset is None:
            fraction = 1.0
            if self.last is not None and self.last[1] > 0.0 and np.isfinite(self.last[1]):
                a0, m0 = self.last
                fraction = m0 / (m0 - least)
                start = a0 + (at - a0) * fraction
            else:
                start = at
            where = None
            if self.comm.rank == owner:
                i = int(np.nanargmin(stability))
                t1 = float(thickness_strain[i])
                t0 = float(self.thickness[i]) if self.thickness is not None else t1
                where = ([float(c) for c in centres[i]], t0 + fraction * (t1 - t0))
            xy, t = self.comm.bcast(where, root=owner)
            self.onset = {self.at: float(start), f"increment_{self.at}": float(at), self.place: xy,
                          "thickness_strain": float(t), "stability": float(least)}
        self.before, self.last = self.last, (float(at), float(least))
        if self.first is None and np.isfinite(least):  # the first increment with a thinned cell
            self.first = float(least)
        self.thickness = np.array(thickness_strain, dtype=float, copy=True)
        return self.onset is not None

    def ahead(self, step: float) -> float:
        """The longest next step (in the load measure) that does not overrun the onset the last
        two increments predict (module docstring): step itself where no onset is predicted
        within it (one increment seen, the stability above PLASTIC of the first increment's or not
        falling, or the neck already started)."""
        if self.onset is not None or self.before is None:
            return step
        (a0, m0), (a1, m1) = self.before, self.last
        if not (np.isfinite(m0) and np.isfinite(m1)) or m1 <= 0.0 or m1 >= m0 or a1 == a0:
            return step
        if not m1 < PLASTIC * self.first:  # the elastic-plastic transition, not a neck's approach
            return step
        distance = m1 * abs(a1 - a0) / (m0 - m1)  # to the linear extrapolation's zero
        if distance >= step:
            return step
        if self.shortest is None:
            self.shortest = step / 4
        return min(step, max(distance / 2, self.shortest))


def words(onset: dict, at: str = "stroke_mm", place: str = "initial_xy_mm") -> str:
    """A watch's onset in words, for a run's log and closing line: 'diffuse neck from stroke
    23.8 mm at initial (25, 12.5), thickness strain -0.1650' (a load factor without a unit):
    a material point's force maximum, which a drawn sheet may pass stably (docs/plastic.md)."""
    x, y = onset[place]
    where = f"stroke {onset[at]:.4g} mm" if at == "stroke_mm" else f"{at.replace('_', ' ')} {onset[at]:.4g}"
    return f"diffuse neck from {where} at initial ({x:.4g}, {y:.4g}), thickness strain {onset['thickness_strain']:.4f}"


def previous_neck(outdir: Path) -> dict | None:
    """The neck that the resumed run's summary.json reports (None without one or without it)."""
    try:
        return json.loads((outdir / "summary.json").read_text()).get("neck")
    except (OSError, ValueError, AttributeError):
        return None


class Necking(Listener):
    """Where the sheet starts to neck (NeckWatch), a listener of either route's run; with `stop`
    ([process] stop_at_neck) the steps shorten ahead of the onset and the run ends there
    (NeckReached), without it the onset is noted and the run goes on. A resumed run keeps the
    onset the run before it found (summary.json "neck").

    The load measure is the driver's load factor times `unit`: a tool scene's stroke in mm
    (`stroke`: unit the scene's stroke), a sheet scene's load factor (`load_factor`: unit 1);
    the watch's steps are bounded in it, the driver's in load factor (the bound divided by
    unit). The sheet is read through the problem's public measurements (cell_fields,
    membrane_stability, cell_centres), which DrawingProblem and SheetProblem both publish."""

    def __init__(self, watch: NeckWatch, stop: bool, unit: float, path: str):
        self.watch, self.stop, self.unit, self.path = watch, stop, unit, path
        self.centres = None

    @classmethod
    def stroke(cls, comm, stop: bool, stroke_mm: float, r: float = 1.0) -> "Necking":
        """A tool scene's: the onset at the stroke (mm), where the stroke ends."""
        return cls(NeckWatch(comm, "stroke_mm", "initial_xy_mm", r), stop, stroke_mm, "stroke")

    @classmethod
    def load_factor(cls, comm, stop: bool, r: float = 1.0) -> "Necking":
        """A sheet scene's: the onset at the load factor, where the load path ends."""
        return cls(NeckWatch(comm, "load_factor", "initial_xy", r), stop, 1.0, "load path")

    @property
    def onset(self) -> dict | None:
        return self.watch.onset

    def words(self) -> str:
        return words(self.watch.onset, self.watch.at, self.watch.place)

    def on_start(self, run: Run) -> None:
        self.centres = run.sheet.cell_centres()
        if run.resumed is not None:
            self.watch.carry(previous_neck(run.outdir), run.driver.lam * self.unit)

    def on_increment(self, run: Run) -> None:
        p, d = run.sheet, run.driver
        before = self.watch.onset
        f = p.cell_fields()
        necked = self.watch.reached(d.lam * self.unit, p.membrane_stability(), f["thickness_strain"], self.centres,
                                    f["major_strain"])
        if necked and before is None and not self.stop:
            d.progress.note(f"shellform: the sheet starts to neck: {self.words()}")
        if self.stop and d.next_step is not None:  # shorter steps ahead of the run's end
            d.bound_next_step(self.watch.ahead(d.next_step * self.unit) / self.unit)  # a measure per load factor
        if necked and self.stop:
            run.end_with(NeckReached(f"the {self.path} ends: {self.words()}"))
