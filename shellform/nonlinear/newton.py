"""One increment: passes of Newton on the parts' fixed constraints until no part changes.

    passes      Newton on the parts' fixed constraints; then every part updates its set (a node
                joins or leaves a tool, the holder opens, friction's normal forces relax), and
                the passes repeat until no part changes. A pass whose changes are all first
                switches (a contact front moving on) does not count against max_passes.
    Newton      K dq = -R (consistent tangent, the parts' stiffness in it) with the known
                corrections lifted where they are not yet met (the supports' in the first
                iteration, so that a prescribed displacement spreads through the structure by
                the converged tangent; a tool's -gap in every iteration); a part's own unknown
                (the open holder's lift) is solved with the same factors; q += alpha dq
    line search alpha is first limited so that no node moves further than the parts allow
                (a trust region), then shortened by secant steps on the energy slope
                s(alpha) = dq . R(q + alpha dq) where the step overshoots the energy minimum
                along dq (s(alpha) > |s(0)|), halved where the material update fails or |R| is
                not finite. A step that mostly meets known corrections (the supports' jump, or
                parts' corrections above 1 % of the step) is a linear prediction of the free
                rows' response, about which the slope says nothing: it is only limited.
    converged   |R_free| <= rtol max(|lambda f_ext|, |element forces|) (the parts' own
                equations included) with the known corrections met to the parts' tolerance,
                or below the round-off floor 1e3 eps max(K_ii) h (a very thin sheet), or a
                correction at round-off level (|dq| <= stol |q|) with |R_free| <= 1e3 rtol max(...)

A pass may end before it converges where a part's set will change anyway (ends_pass). Where
the passes fail, the increment is tried once more where a part offers another way (retry).
"""

import time
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.errors import InputError
from shellform.nonlinear.system import System
from shellform.results.log import say


def shorten(alpha: float, s0: float, s1: float) -> float | None:
    """The line search on the energy slope s(alpha) = dq . R(q + alpha dq): None where alpha is
    kept (s1 <= |s0|, not past the energy minimum along dq by much, or no descent s0 >= 0), else
    a shorter alpha by a secant step towards s = 0, by a factor in [0.1, 0.5]."""
    if s1 <= abs(s0) or s0 >= 0:
        return None
    return alpha * max(0.1, min(0.5, s0 / (s0 - s1)))


@dataclass
class Controls:
    initial_step: float = 0.1  # first dlambda
    min_step: float = 1e-4
    max_step: float = 0.25
    max_iterations: int = 12  # Newton iterations per pass
    rtol: float = 1e-9  # |R_free| <= rtol * max(|element forces|, |lambda f_ext|)
    stol: float = 1e-13  # or a Newton correction at round-off: |dq|_inf <= stol |q|_inf
    easy_iterations: int = 4  # converged in at most this many: grow the next step by `growth`
    growth: float = 1.5
    cut: float = 0.25
    line_search: int = 6  # halvings
    max_passes: int = 12  # passes per increment, not counting those that only move a contact front

    def check(self):
        for name in ("initial_step", "min_step", "max_step", "rtol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"process.{name}", f"must be > 0, got {v}")
        if self.min_step > self.initial_step or self.initial_step > self.max_step:
            raise InputError("process.initial_step", "needs min_step <= initial_step <= max_step")
        if self.max_iterations < 1:
            raise InputError("process.max_iterations", f"must be >= 1, got {self.max_iterations}")


class Newton(System):
    """Newton with passes on the sheet model and its parts (the driver steps it along the path)."""

    MAX_PASSES = 60  # all passes of an increment, front ones included (a front crosses a row of nodes per pass)

    # -- one increment -------------------------------------------------------------------------
    def newton(self, lam, reversal=False):
        """The increment to lam from the current q: passes of Newton until no part changes;
        where they fail, once more as a part offers (retry). After a load reversal the first
        tangent is the elastic one (elastic unloading). Returns (converged, iterations (of
        every try), residuals, ev)."""
        start = self.q.x.array.copy()
        ok, its, res, ev = self.settle(lam, reversal)
        if ok:
            return ok, its, res, ev
        how = next((h for h in (part.retry() for part in self.parts) if h), None)
        if how is None:
            return ok, its, res, ev
        if self.verbose:
            self.progress.note(f"  the passes failed ({self.cause}); {how}, and the increment is tried again")
        self.q.x.array[:] = start
        ok, more, res, ev = self.settle(lam, reversal)
        return ok, its + more, res, ev

    def settle(self, lam, reversal=False):
        """One try at the increment to lam: passes of Newton on the parts' fixed constraints,
        each followed by the parts' updates, until no part changes. Returns (converged,
        iterations, residuals, ev)."""
        c = self.controls
        for part in self.parts:
            part.start(lam, bool(self._dlam_prev))
        self.passes = self.set_changes = 0
        self.line_search_factors, self.pass_residuals = [], []
        iterations, residuals, ev, counted, changes, lines = 0, [], None, 0, 0, []
        while counted < c.max_passes and self.passes < self.MAX_PASSES:
            self.passes += 1
            ok, its, res, ev, early = self._newton_on_set(lam, reversal and self.passes == 1)
            iterations += its
            residuals += res
            self.pass_residuals.append(res)
            if not ok:
                return False, iterations, residuals, ev
            changes, back, settled, lines = 0, 0, True, []
            t0 = time.perf_counter()
            for part in self.parts:
                change = part.update(lam, changes)
                changes, back, settled = changes + change.changes, back + change.back, settled and change.settled
                lines += [change.line] if change.line else []
            self.times["parts_s"] += time.perf_counter() - t0
            counted += not (changes > 0 and back == 0)  # a front moving on is not counted
            if self.trace:
                say(f"    pass {self.passes}: {its} iterations, |R| {res[0]:.3e} -> {res[-1]:.3e}, " + ", ".join(lines))
            self.set_changes += changes
            if changes == 0 and settled and not early:
                return True, iterations, residuals, ev
        self.cause = f"the parts did not settle in {self.passes} passes (last pass: {', '.join(lines)})"
        return False, iterations, residuals, ev

    def _newton_on_set(self, lam, reversal):
        """Newton on the parts' fixed constraints: (converged, iterations, residuals, ev, early)."""
        for part in self.parts:
            part.begin_pass()
        try:
            return self._fixed_set(lam, reversal)
        finally:
            for part in self.parts:
                part.stepped(False)

    def _fixed_set(self, lam, reversal):
        c = self.controls
        supports = self._set_dirichlet(lam)  # the supports' jump, met by the first step
        jump = max(self.constrain(lam), supports)
        norm, scale, ev = self.trial(lam, elastic_tangent=reversal)
        residuals, step = [norm], np.inf
        for it in range(c.max_iterations + 1):
            if not np.isfinite(norm) or ev.failed:
                self.cause = ev.cause() or "the residual is not finite"
                return False, it, residuals, ev, False
            self.scale = scale
            if self.trace:
                say(f"    iterate: |R| {norm:.3e} of {scale:.3e}, known corrections {jump:.2e}")
            met = jump <= self.known_tolerance
            if met and (norm <= c.rtol * scale or (step <= c.stol * self._largest(self.q.x.array)
                                                   and norm <= 1e3 * c.rtol * scale)):
                return True, it, residuals, ev, False
            if it == c.max_iterations:
                break
            R0 = self.b.copy()
            ok = self.solve(jump)
            own = [part.border(self) for part in self.parts] if ok else []
            if not ok or not np.all(np.isfinite(own)):
                R0.destroy()
                self.cause = "the linear solve failed (singular tangent or a non-finite correction)"
                return False, it, residuals, ev, False
            s0 = self.dq.x.petsc_vec.dot(R0) + sum(part.slope() for part in self.parts)  # dq . R(q) < 0
            R0.destroy()
            for part in self.parts:
                part.stepped(True)
            ok, norm, scale, ev, jump, step, move = self._line_search(lam, s0, jump, supports)
            if not ok:
                return False, it + 1, residuals, ev, False
            supports = 0.0
            residuals.append(norm)
            if any(part.ends_pass(move, lam) for part in self.parts):
                return True, it + 1, residuals, ev, True  # the set changes: end the pass here
        self.cause = f"no convergence in {c.max_iterations} iterations" + (" on a fixed set" if self.parts else "")
        return False, c.max_iterations, residuals, ev, False

    def _line_search(self, lam, s0, jump, supports):
        """q += alpha dq (module docstring). Returns (accepted, |R|, scale, ev, known
        corrections, alpha |dq|_inf, alpha times the largest nodal move)."""
        c, comm = self.controls, self.model.mesh.comm
        dq = self.to_xyz(self.dq.x.array)
        move = np.linalg.norm(dq.reshape(-1, BS)[: self.n_owned, :3], axis=1).max(initial=0.0)
        move = comm.allreduce(float(move), op=MPI.MAX)
        bound = min([np.inf] + [part.largest_move() for part in self.parts])
        alpha = min(1.0, bound / max(move, 1e-300))
        searching = self.searching and supports == 0 and jump <= max(self.known_tolerance, 1e-2 * move)
        x0 = self.q.x.array.copy()
        norm = scale = ev = None
        for _ in range(c.line_search + 1):
            self.q.x.array[:] = x0 + alpha * dq
            for part in self.parts:
                part.move(alpha)
            jump = self.constrain(lam)
            norm, scale, ev = self.trial(lam)
            if not np.isfinite(norm) or ev.failed:
                alpha *= 0.5  # outside the material's reach: shorten
                continue
            s1 = self.energy_slope(dq) if searching else 0.0
            if self.trace:
                say(f"      step: alpha {alpha:.3g} of a largest nodal move {move:.3g}, |R| {norm:.3e}, energy slope "
                    f"{s0:.3e} -> {s1:.3e}, known corrections {jump:.2e}")
            shorter = shorten(alpha, s0, s1) if searching else None
            if shorter is None:
                break
            alpha = shorter
        else:
            self.cause = f"the line search found no acceptable step ({ev.cause() or 'no energy descent'})"
            return False, norm, scale, ev, jump, 0.0, 0.0
        if alpha < 1.0 and supports > 0:  # the supports' prescribed values, held
            held = self._in_frames()
            held[self.support_dofs] = self.g[self.support_dofs]
            self.q.x.array[:] = self.edge_frames.from_frames(held) if self.edge_frames is not None else held
            jump = self.constrain(lam)
            norm, scale, ev = self.trial(lam)
        self.line_search_factors.append(alpha)
        return True, norm, scale, ev, jump, alpha * self._largest(self.dq.x.array), alpha * move

