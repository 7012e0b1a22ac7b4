"""Parts: what the Newton driver composes besides the sheet (tools, the holder, friction, beads).

The driver (driver.py) solves R(q, lambda) = 0 for the sheet's carrier q. A part adds to that
problem without the driver knowing what it is. Per Newton iterate the driver

1. asks every part for its *constraints* (``constrain``): rows of q that are known at this
   iterate, with their known corrections, seen in a nodal frame (a node on a tool is seen in
   the tool's normal frame, so that its normal displacement is a known row: the semi-inverse
   split), and which of those rows stay known long enough for the solve to take them out;
2. turns the element arrays into those frames, assembles R and K, and lets every part add its
   nodal forces (``add_residual``) and then its stiffness (``add_tangent``), in list order, both
   in the nodal frames;
3. solves K dq = -R with the known corrections lifted, and lets a part with an unknown of its
   own (the open holder's lift) solve for it with the same factors (``border``); a part may
   bound the step (``largest_move``);
4. searches along the step on the energy slope, the parts' unknowns moved with it (``move``).

A Newton on a fixed set of constraints is a *pass*. After a converged pass every part updates
its set (``update``: nodes joining or leaving a tool, the holder opening, friction's normal
forces relaxed) and the passes repeat until no part changes. A part owns its state: it starts
an increment from its committed state (``start``), commits it with a converged increment
(``commit``), writes it into a checkpoint and reads it back (``checkpoint``, ``restore``) and
says what it is doing (``report``). Every method has a default that contributes nothing.

Sensitivities (sensitivity.py) differentiate the converged increment with the parts' sets
held: a part says whether it can (``derivatives``: None, or why not) and gives the derivatives
of its known rows (``known_derivatives``: a node on a tool lies its half thickness from it,
which moves with the thickness strain). They linearize the converged state as Newton's iterates
see it and put the parts back as the last iterate left them (``iterate_state``,
``set_iterate_state``; Driver.linearized), so that a run with them is the run without.
"""

from dataclasses import dataclass

import numpy as np


@dataclass
class Constraints:
    """The constraints of one iterate on the owned nodes, as parts fill them in.

    frames: (n, 3, 3) orthonormal nodal frames (rows: the slots 0, 1, 2 of u, v, w);
    known: (n, BS) known corrections in those frames; flags: (n, BS) True where a row is known;
    stable: (n, BS) True where a known row stays known within the increment (the free-row solve
    takes those out of the factorisation)."""

    frames: np.ndarray
    known: np.ndarray
    flags: np.ndarray
    stable: np.ndarray

    @classmethod
    def none(cls, n: int, bs: int) -> "Constraints":
        return cls(np.tile(np.eye(3), (n, 1, 1)), np.zeros((n, bs)), np.zeros((n, bs), dtype=bool),
                   np.zeros((n, bs), dtype=bool))


@dataclass
class Change:
    """A part's update after a converged pass: `changes` to its set (all ranks), of which `back`
    are switches back (a node's second switch in the increment); `settled`: whatever the part
    relaxes between passes (friction's normal forces) has converged; `line`: for a trace."""

    changes: int = 0
    back: int = 0
    settled: bool = True
    line: str = ""


def copy_state(obj) -> dict:
    """obj's own arrays (copied), numbers, flags, tuples and Nones: the state an iterate writes
    (Part.iterate_state)."""
    return {k: v.copy() if isinstance(v, np.ndarray) else v for k, v in vars(obj).items()
            if v is None or isinstance(v, (np.ndarray, bool, int, float, tuple))}


def put_state(obj, state: dict) -> None:
    """Put back copy_state(obj)'s state: a writeable array in place where it keeps its shape
    (whoever shares it sees the old values again), else the saved value."""
    for k, v in state.items():
        now = getattr(obj, k)
        if isinstance(v, np.ndarray) and isinstance(now, np.ndarray) and now.shape == v.shape and now.flags.writeable:
            now[...] = v
        else:
            setattr(obj, k, v)


class Part:
    """The protocol (module docstring); every method defaults to contributing nothing."""

    magnitude = 0.0  # the size of the part's load at lambda = 1 (a scale of the residual)
    known_tolerance = 0.0  # |known corrections| at which a pass may converge

    def bind(self, driver) -> None:
        """The part is composed into `driver`: it may keep what it reads of the driver's public
        state (q, residual_full) and later use its solves (border)."""

    def start(self, lam: float, predicting: bool) -> None:
        """An attempt at the increment to lam begins from the committed state (`predicting`:
        the driver extrapolated q from the last two increments)."""

    def begin_pass(self) -> None:
        """A Newton on a fixed set begins."""

    def stepped(self, yes: bool) -> None:
        """Whether Newton has stepped from the pass's first iterate (the iterates after it)."""

    def constrain(self, c: Constraints, lam: float) -> None:
        """Fill in this part's frames, known rows and corrections at the current iterate."""

    def follow(self, frames: np.ndarray, lam: float) -> None:
        """The iterate's frames are settled (owned and ghost nodes): update what depends on them."""

    def add_residual(self, R: np.ndarray) -> None:
        """R -= the part's nodal forces (owned rows, nodal frames)."""

    def add_tangent(self, K, R: np.ndarray, fixed: np.ndarray) -> None:
        """K += the part's stiffness (R: the residual with every part's forces; fixed: the
        known rows, local dofs)."""

    def lift_known(self, delta: np.ndarray, b: np.ndarray) -> None:
        """b -= the part's stiffness on the known columns times their corrections `delta` (local
        dofs, the solve's frames; b: owned rows): what the assembled tangent, whose known columns
        hold nothing, cannot carry into the free rows (system.py, the lift)."""

    def imbalance(self) -> float:
        """The residual of the part's own equation (0 without an unknown)."""
        return 0.0

    def border(self, driver) -> float:
        """After the sheet's solve: solve for the part's own unknown with the same factors
        (driver.solve_lifted, driver.apply_tangent) and add its response to driver.dq; returns
        the unknown's step (nan where the solve failed)."""
        return 0.0

    def slope(self) -> float:
        """The share of the part's own unknown in the energy slope (its step times its equation)."""
        return 0.0

    def move(self, alpha: float) -> None:
        """Take alpha times the step of the part's own unknown (from its value before the step)."""

    def largest_move(self) -> float:
        """The largest nodal move of one Newton step the part allows (inf: no bound)."""
        return np.inf

    def ends_pass(self, move: float, lam: float) -> bool:
        """Whether the pass may end at this iterate (its last step moved nodes by at most
        `move`) because the part's set will change anyway."""
        return False

    def update(self, lam: float, changes: int) -> Change:
        """After a converged pass (`changes`: those of the parts before it): update the set."""
        return Change()

    def retry(self) -> str | None:
        """After a failed increment: a way to try it once more at the same step (said in
        words), or None."""
        return None

    def easy_iterations(self, max_iterations: int) -> int:
        """An increment converged in this many iterations lets the next one grow."""
        return 0

    def commit(self, lam: float) -> None:
        """The increment to lam converged."""

    def checkpoint(self) -> dict:
        """{"nodes": {...}, "global": {...}}: the committed state (owned nodes; global values)."""
        return {}

    def restore(self, state: dict, lam_scale: float) -> None:
        """Read back checkpoint() (state: this rank's groups); lam_scale: its load factor in
        this run's units."""

    def report(self) -> dict:
        """What the part is doing, for the increment's record."""
        return {}

    def iterate_state(self) -> dict:
        """The part's state as this iterate left it (what constrain, follow and the residual
        write), copied: by default its own arrays and numbers (copy_state); a part that keeps
        such state in objects of its own adds theirs. The derivatives' own state (dicts per
        parameter) is not in it."""
        return copy_state(self)

    def set_iterate_state(self, state: dict) -> None:
        """Put back iterate_state()'s state."""
        put_state(self, state)

    def derivatives(self) -> str | None:
        """None where this part's equations are differentiated by known_derivatives alone (its
        forces on the free rows independent of the parameters at fixed q, its set held), else
        why not, in words (the sensitivities are then refused)."""
        return f"the part {type(self).__name__} has no derivatives yet"

    def tangent_misses(self) -> bool:
        """Whether the part's tangent leaves out terms of its forces' derivative, so that a
        sensitivity's solve is corrected against the total derivative (nonlinear/sensitivity.py)."""
        return False

    def known_derivatives(self, delta: np.ndarray, de33: np.ndarray) -> None:
        """delta ((n_owned, BS), the solve's frames) += d/dp of this part's known values, given
        de33 = d/dp of the committed thickness strain per owned cell (the state the increment
        started from)."""

    def pseudo_load(self, key: str, rhs: np.ndarray, dx_n: np.ndarray, eps: float, parameter=None) -> None:
        """rhs ((n_owned, BS), the solve's frames: dR/dp at fixed q, the sheet's, its known rows
        still there) += the part's own forces' dR/dp at fixed q for the parameter `key`, whose
        central differences step by eps (dx_n: the committed positions' derivative; parameter:
        the Parameter (nonlinear/sensitivity.py), which says how its value enters: a friction
        coefficient's rates per tool, the holder's force, the material)."""

    def carry(self, key: str, dx: np.ndarray, dx_n: np.ndarray, dR: np.ndarray, lam: float, eps: float,
              parameter=None) -> None:
        """After the solve: the derivative of the part's history at this increment (dx: the
        positions', dR: the residual's total, (n_owned, BS) in the frames), taken at commit."""

    def border_derivative(self, key: str, driver, out, dR: np.ndarray, parameter=None) -> bool:
        """Where the part has an unknown of its own (the open holder's lift), add to the solved
        derivative in `out` (a Function, the solve's frames) that unknown's derivative times its
        unit response, from the part's equation differentiated along dR (the residual's total,
        owned rows, the frames), as border does for Newton's step; whether it added one (every
        rank alike)."""
        return False

    def total_derivative(self, key: str, dR: np.ndarray) -> None:
        """dR ((n_owned, BS), the frames) += the total derivative of the part's forces (after
        carry): the free rows' check of the sensitivities."""

    def derivative_state(self, key: str) -> dict:
        """The part's history derivative for `key`, owned nodes' arrays (a checkpoint's)."""
        return {}

    def restore_derivative_state(self, key: str, state: dict) -> None:
        """Read back derivative_state."""
