"""The incremental Newton driver: load-factor stepping, passes of Newton, cut-back, checkpoints.

The problem is  R(q, lambda) = 0  for the sheet's carrier q with its known rows (system.py):
the supports, q_D = lambda qbar_D, and the rows that the driver's parts (parts.py: tools,
the holder, friction, beads) make known. Each increment lambda_n -> lambda_n + dlambda:

    predictor   q = q_n + (dlambda / dlambda_prev) (q_n - q_n-1) (after a converged increment)
    passes      of Newton with a line search until no part changes (newton.py)

A failing increment (too many iterations or passes, a non-finite value, a failed return
mapping, no descent) is tried once more where a part offers another way (retry); then,
without parts that bound the step, with the energy line search swapped; then it is restored
and retried with dlambda / 4. An easy one (few iterations) lets the next grow by 1.5. Below
min_step the run stops with ConvergenceFailure, after writing the last converged state to disk.
Nothing non-finite is ever committed.

What watches the run may shorten the next step ahead of an event it sees coming (the neck:
shellform.results.neck.NeckWatch.ahead): after an increment, on_increment may call
bound_next_step(dlambda); the step is never shortened below min_step, and it grows again from
there as usual.
"""

import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from shellform.errors import InputError
from shellform.nonlinear import checkpoint
from shellform.nonlinear.interrupt import Interrupted, StopRequests
from shellform.nonlinear.newton import Controls, Newton  # noqa: F401 (the driver's controls)
from shellform.results.disk import Room
from shellform.results.listeners import Record
from shellform.results.log import Progress
from shellform.results.tables import write_json


class ConvergenceFailure(RuntimeError):
    """The driver could not continue; the last converged state is on disk (``checkpoint``)."""

    def __init__(self, message, checkpoint=None):
        super().__init__(message + (f" (last converged state: {checkpoint})" if checkpoint else ""))
        self.checkpoint = checkpoint


@dataclass
class Increment:
    number: int
    lam: float
    dlam: float
    iterations: int  # Newton iterations (linear solves), those of the tries cut back included
    residuals: list[float]
    plastic_layers: int
    cutbacks: int
    seconds: dict = field(default_factory=dict)
    contact: dict = field(default_factory=dict)  # passes, set changes and what the parts report
    change: float = 0.0  # |q_n+1 - q_n|, 2-norm over all ranks (the path's stiffness: |dlam| / change)


class Driver(Newton):
    """Newton on the sheet model and its parts, DOLFINx assembly and a MUMPS LU solve."""

    def __init__(self, model, bcs, prescribed=None, pressure=0.0, nodal=None, controls=None,
                 checkpoint_dir=None, verbose=True, frames=None, parts=(), trace=False):
        """bcs: Dirichlet conditions of the carrier (values = the prescribed values at lambda = 1,
        held in the `prescribed` Function, or homogeneous); pressure: dead pressure at lambda = 1;
        nodal: shellform.nonlinear.loads.NodalLoads; frames: shellform.edge_frames.SheetEdgeFrames
        of clamped curved edges (the system is solved in their frames, the state kept in x, y);
        parts: the parts (parts.py) in the order they add their forces; trace: log every pass,
        step and iterate."""
        self.controls = controls or Controls()
        self.controls.check()
        super().__init__(model, bcs, prescribed, pressure, nodal, frames, parts)
        self.easy_iterations = max([self.controls.easy_iterations]  # an increment this easy lets the next grow
                                   + [p.easy_iterations(self.controls.max_iterations) for p in self.parts])
        self.known_tolerance = max([0.0] + [p.known_tolerance for p in self.parts])
        self.swap_line_search = all(np.isinf(p.largest_move()) for p in self.parts)
        self.checkpoint_dir = Path(checkpoint_dir) if checkpoint_dir else None
        self._room = None  # the checkpoint folder's Room (the property room)
        self.verbose, self.trace = verbose, trace
        self.progress = Progress()  # a run sets its own (label, total, unit)
        self.stops = StopRequests(model.mesh.comm)  # Ctrl-C and SIGTERM while it steps (interrupt.py)
        self.fingerprint = {}  # what defines the run, written into its checkpoints (set by a run)
        # what a run records along the way and a resume continues (a strain path, a watch, the
        # sensitivities): each a Record (results/listeners.py), its state kept with the driver's
        self.records: list[Record] = []
        self._numbering = None  # the checkpoints' global numbers of nodes and cells (numbering())
        self.q_n = self.q.x.array.copy()  # the carrier of the last converged increment
        self.lam = 0.0
        self.history: list[Increment] = []
        self._dlam_prev = None
        self._direction = None
        self._steps = None  # between two increments of run(): (the next dlam, the last one, q before it)
        self._resumed_steps = None  # (dlam, dlam_prev, q_prev) a checkpoint gave the next run() to step on with
        self.cause = ""  # why the last attempt at an increment failed, in words
        self.searching = True  # the energy line search on; an increment that fails swaps it once
        self.passes = self.set_changes = 0  # of the last increment
        self.scale = 0.0  # the residual's scale at the last iterate
        self.line_search_factors: list[float] = []  # alpha of every accepted Newton step (this increment)
        self.pass_residuals: list[list[float]] = []  # |R| of every iterate, one list per pass (this increment)
        for part in self.parts:
            part.bind(self)

    def limit_point(self, failed: float, softening: float = 0.05) -> str | None:
        """Why stepping stopped, where the load cannot grow further: a limit point of the path
        (a collapse load, a snap-through). Along the path the stiffness k_n = |dlambda_n| / |dq_n|
        of the converged increments has fallen below `softening` times the first one's; the limit
        load factor is estimated where k, extrapolated linearly in lambda from the last two
        increments, reaches zero, within [the last converged lambda, the failed one]. None where
        the stiffness held up (a failure of another kind)."""
        path = [h for h in self.history if h.change > 0]
        if len(path) < 2:
            return None
        k = [abs(h.dlam) / h.change for h in path]
        if k[-1] > softening * k[0]:
            return None
        lam_c, lam_b = path[-1].lam, path[-2].lam
        slope = (k[-1] - k[-2]) / (lam_c - lam_b)  # dk / dlambda
        estimate = lam_c - k[-1] / slope if slope * (failed - lam_c) < 0 else failed
        lo, hi = sorted((lam_c, failed))
        estimate = min(max(estimate, lo), hi)
        return (f"the structure reached its limit load at about load factor {estimate:.4g} (last converged "
                f"{lam_c:.6g}; no equilibrium found at {failed:.6g}): along the path its stiffness "
                f"|dlambda|/|dq| fell to {k[-1] / k[0]:.2g} times the first increment's")

    def _commit(self, lam) -> None:
        """Accept the increment's state (the sheet's and every part's); every record sees the
        converged state first (Record.converged), before it is committed."""
        for record in self.records:
            record.converged(self, lam)
        self.model.commit()
        for part in self.parts:
            part.commit(lam)

    def _restore_converged(self) -> None:
        """Before a stop: make every derived quantity (residual, reactions, the parts' forces)
        that of the last converged state, which q already holds, so that what is reported is
        that state."""
        for part in self.parts:
            part.start(self.lam, False)
        self._set_dirichlet(self.lam)
        self.constrain(self.lam)
        self.residual(self.lam, tangent=False)

    def _increment_info(self) -> dict:
        if not self.parts:
            return {}
        alphas = self.line_search_factors
        info = {"passes": self.passes, "set_changes": self.set_changes,
                "min_line_search": min(alphas) if alphas else 1.0}
        for part in self.parts:
            info.update(part.report())
        return info

    def _predict(self, dlam, x_n, x_prev):
        if self._dlam_prev:
            self.q.x.array[:] = x_n + (dlam / self._dlam_prev) * (x_n - x_prev)
        else:
            self.q.x.array[:] = x_n

    def _other_line_search(self, lam, reversal, dlam, x_n, x_prev, its):
        """Retry a failed increment with the energy line search swapped (off if it was on), and
        keep the swap while it converges. A thin sheet needs it off: Newton's first step bends it
        with the membrane unbalanced, past the energy minimum along that step, and converges from
        there in a few iterations, where a line search would creep (docs/locking.md)."""
        cause = self.cause
        self.searching = not self.searching
        self._predict(dlam, x_n, x_prev)
        ok, its2, res, ev = self.newton(lam, reversal)
        if not ok:
            self.searching = not self.searching
            self.cause = f"{cause}; with the line search {'on' if self.searching else 'off'}: {self.cause}"
        return ok, its + its2, res, ev

    @property
    def room(self) -> Room | None:
        """The room kept on the checkpoints' disk (results/disk.py): each checkpoint, and the
        run's series written there, refused before it starts where it might not fit; one per
        checkpoint_dir (which a caller may set after construction), None without one."""
        if self.checkpoint_dir is None:
            return None
        if self._room is None or self._room.folder != Path(self.checkpoint_dir):
            self._room = Room(Path(self.checkpoint_dir), self.model.mesh.comm)
        return self._room

    @property
    def next_step(self) -> float | None:
        """The load-factor step the next increment will try (None outside a run's stepping)."""
        return None if self._steps is None else self._steps[0]

    def bound_next_step(self, dlam: float) -> None:
        """Shorten the next increment's step to at most dlam, not below min_step (called from
        on_increment, by what sees an event coming); a no-op outside a run's stepping."""
        if self._steps is not None and dlam < self._steps[0]:
            self._steps = (max(dlam, self.controls.min_step),) + self._steps[1:]

    def continue_from(self, lam: float) -> None:
        """q holds a converged state at load factor lam, reached from 0 (another driver's, or a
        state set by hand): the next run() steps on from there, a load reversal where it goes
        back towards 0 (its first tangent the elastic one)."""
        self.lam = float(lam)
        self._direction = float(np.sign(lam)) or None
        self._dlam_prev = None

    def forget_steps(self) -> None:
        """The next run() starts its steps afresh (initial_step, no predictor), not as a checkpoint
        written between two increments had them (a resume with other steps)."""
        self._resumed_steps = None

    def run(self, target: float = 1.0, on_increment=None):
        """Step lambda from its current value to `target` (up or down). A SIGINT or SIGTERM
        meanwhile stops it after the increment under way: the last converged state is written
        (save_checkpoint) and Interrupted raised."""
        with self.stops:
            return self._run(target, on_increment)

    def _stop_if_requested(self) -> None:
        """After an attempt at an increment: where a stop was requested, write the last
        converged state (q holds it) and raise Interrupted."""
        signum = self.stops.requested()
        if signum:
            self._restore_converged()
            raise Interrupted(signum, self.save_checkpoint())

    def _run(self, target, on_increment):
        c = self.controls
        direction = 1.0 if target >= self.lam else -1.0
        reversal = self._direction is not None and direction != self._direction
        self._direction = direction
        resumed, self._resumed_steps = self._resumed_steps, None
        if resumed is not None:  # a checkpoint written between two increments: step on as it would have
            dlam, self._dlam_prev, x_prev = resumed
        else:
            dlam = min(c.initial_step, abs(target - self.lam))
            x_prev = self.q.x.array.copy()
            self._dlam_prev = None  # nothing to extrapolate from at a new target
        while abs(target - self.lam) > 1e-14:
            dlam = min(dlam, abs(target - self.lam))
            x_n = self.q.x.array.copy()
            cutbacks = spent = 0  # the tries cut back, and their iterations
            t0 = time.perf_counter()
            while True:
                lam = self.lam + direction * dlam
                self._predict(dlam, x_n, x_prev)
                ok, its, res, ev = self.newton(lam, reversal)
                if not ok and self.swap_line_search:
                    ok, its, res, ev = self._other_line_search(lam, reversal, dlam, x_n, x_prev, its)
                if ok:
                    break
                self.q.x.array[:] = x_n
                spent += its
                self._stop_if_requested()
                cutbacks += 1
                dlam *= c.cut
                if self.verbose:
                    self.progress.note(f"  cut back: lambda {lam:.6g} failed after {its} iterations "
                                       f"(|R| {res[-1]:.3e}: {self.cause}); retry with dlambda {dlam:.3g}")
                if dlam < c.min_step:
                    self._restore_converged()
                    path = self.save_checkpoint()
                    raise ConvergenceFailure(self.limit_point(lam) or (
                        f"increment at lambda {self.lam:.6g} -> {lam:.6g} did not converge ({self.cause}) and "
                        f"the step fell below min_step {c.min_step:g}"), path)
                self._dlam_prev = None  # no extrapolation after a failure
            self._commit(lam)
            self.q_n = self.q.x.array.copy()
            reversal = False
            x_prev = x_n
            self.lam = lam
            self._dlam_prev = dlam
            inc = Increment(len(self.history) + 1, lam, dlam, spent + its, res, ev.plastic_layers, cutbacks,
                            {"wall_s": time.perf_counter() - t0}, self._increment_info(), self._norm(self.q.x.array - x_n))
            self.history.append(inc)
            if self.verbose:
                self.progress.increment(
                    lam, inc.number, sum(h.iterations for h in self.history),
                    f"increment {inc.number:3d}  lambda {lam:.6g}  dlambda {dlam:.3g}  iterations {inc.iterations}  "
                    f"|R| {res[0]:.2e} -> {res[-1]:.2e}  plastic layers {ev.plastic_layers}")
            if its <= self.easy_iterations and cutbacks == 0:
                dlam = min(dlam * c.growth, c.max_step)
            self._steps = (dlam, self._dlam_prev, x_n)  # the next step; this one and the state before it (the predictor's)
            if on_increment is not None:
                on_increment(self)
            dlam = self._steps[0]  # as a watch may have bounded it
            self._stop_if_requested()
        self._steps = None  # the next target starts its steps afresh
        return self.history

    # -- disk ----------------------------------------------------------------------------------
    def checkpoint_state(self) -> dict:
        """Everything the next increment starts from, as of the last converged increment, in the
        groups of shellform.nonlinear.checkpoint: per owned node the carrier, per owned cell the
        material state, and the load factor."""
        state = {"nodes": {"q": self._owned_nodes(self.q_n)}, "cells": dict(self.model.checkpoint()),
                 "global": {"lam": np.array(self.lam), "searching": np.array(self.searching)}}
        if self._steps is not None:  # between two increments of a target: how the next one starts
            dlam, dlam_prev, q_prev = self._steps
            state["nodes"]["q_prev"] = self._owned_nodes(q_prev)
            state["global"].update({"next_dlam": np.array(dlam), "dlam_prev": np.array(dlam_prev)})
        for part in [*self.parts, *self.records]:  # the parts' committed states, what the run recorded
            for group, values in part.checkpoint().items():
                state[group].update(values)
        return state

    def _owned_nodes(self, values: np.ndarray) -> np.ndarray:
        """A carrier array as rows of its owned nodes (a view)."""
        imap = self.q.function_space.dofmap.index_map
        return values.reshape(imap.size_local + imap.num_ghosts, -1)[: imap.size_local]

    def restore_state(self, state: dict, lam_scale: float = 1.0) -> None:
        """Continue from a checkpoint_state (this rank's rows; lam_scale: its load factor in this
        run's units)."""
        q = self._owned_nodes(self.q.x.array)
        if "q" not in state["nodes"] or state["nodes"]["q"].shape != q.shape:
            raise InputError("resume", "the checkpoint's carrier does not fit this model (another mesh)")
        q[...] = state["nodes"]["q"]
        self.q.x.scatter_forward()
        self.q_n = self.q.x.array.copy()
        self.model.restore(state["cells"], self.q)
        glob = state["global"]
        self.lam = float(glob["lam"]) * lam_scale
        self._direction = 1.0 if self.lam > 0 else None
        self._dlam_prev = None
        self.searching = bool(glob.get("searching", True))
        if "q_prev" in state["nodes"]:  # written between two increments: the next run() steps on from there
            q[...] = state["nodes"]["q_prev"]
            self.q.x.scatter_forward()
            q_prev = self.q.x.array.copy()
            self.q.x.array[:] = self.q_n
            self._resumed_steps = (float(glob["next_dlam"]) * lam_scale, float(glob["dlam_prev"]) * lam_scale, q_prev)
        for part in self.parts:
            part.restore(state, lam_scale)
        for record in self.records:
            record.restore(state)

    def numbering(self) -> checkpoint.Numbering:
        """The global numbers of this rank's nodes and cells in a checkpoint (made once)."""
        if self._numbering is None:
            self._numbering = checkpoint.Numbering(self.model.V, self.model.num_cells)
        return self._numbering

    def save_checkpoint(self):
        """Write the last converged state (checkpoint_state, gathered into one rank-independent
        file by rank 0, with the run's fingerprint and the history of every increment so far) as
        checkpoint_dir/checkpoint.npz, keeping the one before (shellform.nonlinear.checkpoint);
        and the history as history.json. Collective; safe at any time of a run (it writes the
        state of the last converged increment, not a Newton iterate). Returns the path (None
        without a checkpoint_dir). Where the disk has not the room kept for it (self.room) or
        fills meanwhile: DiskFull, the last complete checkpoint kept."""
        if self.checkpoint_dir is None:
            return None
        history = [asdict(h) for h in self.history]
        with self.room.write("the checkpoint"):
            path = checkpoint.save(self.checkpoint_dir, self.numbering(), self.checkpoint_state(),
                                   {"fingerprint": self.fingerprint, "history": history})
            write_json(self.checkpoint_dir / "history.json", history)
        return path

    def resume(self, saved: checkpoint.Checkpoint, lam_scale: float | None = None) -> None:
        """Continue from a checkpoint read by shellform.nonlinear.checkpoint.read (written on any
        number of ranks): its state (restore_state) and its history, so that the increments,
        iterations and cut-backs counted afterwards are the whole run's."""
        state = saved.local(self.numbering())
        if lam_scale is None:
            self.restore_state(state)
        else:
            self.restore_state(state, lam_scale)
        self.history = [Increment(**h) for h in saved.meta.get("history", [])]
