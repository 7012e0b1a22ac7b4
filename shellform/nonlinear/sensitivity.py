"""Sensitivities from one run: direct differentiation through the increments.

For a parameter p of the sheet (a material constant, the thickness, the pressure), each
converged increment n -> n+1 satisfies, on the free rows of the carrier q,

    R(q_n+1, h_n, p) = 0,        h_n+1 = H(q_n+1, h_n, p),

R the residual (the element forces of the material update from the committed state h_n, less
lambda f_ext), H the update of the material state h (plastic strains, equivalent plastic strain,
thickness stretch), the known rows (the
supports) independent of p. Differentiating along the path (direct differentiation of a
path-dependent problem: Kleiber, Antunez, Hien and Kowalczyk, Parameter Sensitivity in
Nonlinear Mechanics, Wiley 1997, ch. 5 and 7):

    K q'_n+1 = -(dR/dh h'_n + dR/dp)         free rows; q' = 0 on the known rows
    h'_n+1   = dH/dq q'_n+1 + dH/dh h'_n + dH/dp

with ' = d/dp and K the consistent tangent of the converged increment (the tangent of the
return mapping from h_n), computed and factorised once per increment for all parameters. The
two brackets are directional derivatives of the element loop's own map
(q, h_n, p) -> (f_e, h_n+1) (SheetModel.respond), by central differences along (0, h'_n, 1)
and along (q'_n+1, h'_n, 1) with a step eps = STEP |p|: the semi-analytic method (Barthelemy
and Haftka, AIAA J. 28, 1990), exact but for O(eps^2) and the return mapping's tolerance over
eps (1e-12 / 1e-5; docs/sensitivity.md measures both). The second difference also gives the
total derivative of the residual on every row: on the known rows the reactions' sensitivities,
on the free rows about zero (a check that the solve and the differences agree).

Where the response is not differentiable, a layer turning from elastic to plastic (or back)
between p - eps and p + eps, the central difference is the mean of the one-sided derivatives;
such layers are counted per increment (`switches`), so that a jump in a sensitivity can be
traced to the increments where the plastic zone moved across a quadrature point.

With tools (a driver with parts: the semi-inverse contact), the increment is differentiated with
the parts' sets held as converged (the nodes on each tool, the stick and slip states): the
derivative of the fixed-set problem. The known rows are then not all fixed in p: a node on a
tool lies its half thickness h_i from the tool's surface, and h_i = t/2 exp(e33) follows the
committed thickness strain, so the node's normal row takes q' = h_i' = h_i recover(e33'_n) (the
parts' known_derivatives; the driver's lifted solve carries it into the free rows). The tools'
curvature term of the tangent is in K. Coulomb friction's forces depend on p at fixed q through
its history (the committed forces), the committed positions, the normal forces (the reactions'
pseudo-load on the normal rows) and, for a friction coefficient, the coefficient: the part adds
that to the pseudo-load (Part.pseudo_load) and carries its history's derivative by central
differences of its own return mapping with the stick and slip states held (Part.carry), as the
sheet's is carried. On a node the closed holder pinches, friction presses with the holder's
split of its force F (contact/holder_split.py), differentiated the same way in F, the net
normal forces, the positions and the edge load (PinchingHolder.face_derivatives); the held
slopes are known rows (Part.known_derivatives). The drawbeads' rigid-plastic restraint is
differentiated as friction's is, its derivative entering dR itself (contact/drawbead.py); the
open holder's lift is solved with the derivative (below). Ironing's penalty is the element's:
the differences take it with the material's modulus and with the cells' clearance and its
gradient moved along q' (SheetModel.moved_squeeze), and a node on a tool whose faces lie at the
half clearance has the known row c_i'/2 = (n_a + n_b) . x'_i / 2 instead of h_i', a value of
the solved x' itself where the faces are not parallel (Ironing.border_derivative, below). A part
whose forces on the free rows depend on p otherwise says so (Part.derivatives) and the
sensitivities are refused, as is a tool scene without finite strains or one whose parameter
moves the tools (the thickness: the tools are placed around the sheet). Where the set changes between p - dp and p + dp a finite difference
jumps and the derivative of the fixed set does not: the comparison holds on a path whose set
does not change within the difference (docs/sensitivity.md).

The check and the corrections. The total derivative of the residual along (q', h'_n, 1), the
element forces' difference, the parts' own (Part.total_derivative) and the turn of the frames of
the nodes on curved tools (-R0 W_ab t_b . x', the tangent's curvature term along q', which the
differences in the frames held leave out: ContactSet.carry), vanishes on the free rows where K
is the exact Jacobian of the converged increment. Where a part's tangent leaves a term out
(Part.tangent_misses: friction's on a pinched node holds the split's spread and band fixed, each
node's face following its own R0 while the squeeze F - E_in - f E_e couples every pinched node,
and on a curved tool it leaves out the normal's turn towards the friction force), it does not:
the solve is then corrected, K delta = -total on the free rows, q' += delta, while the total passes
CORRECT_ABOVE of the loads' scale (the pseudo-load's and the reactions' derivatives, the
larger) and each correction at least halves it (a defect correction with the increment's
factors, at most MAX_CORRECTIONS; where one no longer halves it, the better of the last two is
kept).

A part's own unknown (the open holder's lift z_H, with its equation F - sum p_i = 0) is solved
with the derivative as Newton's step solves it (Part.border_derivative): q' = q'_a + z' q'_b,
q'_b the response to a unit change of the unknown, z' from the equation differentiated along the
total; a known row that depends on q' (the ironed node's c_i'/2) is set from the solved q' and
its response added; BORDER_PASSES times, each followed by the check and its corrections.

The sensitivity is a Record of the driver (driver.records): `converged` runs with each
converged increment before it is committed, and `checkpoint`/`restore` carry q' and h' through
a resume.
"""

from dataclasses import dataclass, replace
from functools import partial
from typing import NamedTuple

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.errors import InputError
from shellform.results.listeners import Record
from shellform.scene.schema import DRAWBEAD_PARAMETER, FRICTION_KEYS, FRICTION_TOOLS

STEP = 1e-5  # the central differences' step, relative to the parameter
CORRECT_ABOVE = 1e-4  # a solve is corrected while its free rows' total passes this share of the loads' scale
CORRECTED_BY = 0.5  # ... and each correction shrinks it at least by this factor
MAX_CORRECTIONS = 8
BORDER_PASSES = 2  # a part's own unknown solved with the derivative (Part.border_derivative), then again
KEYS = ("ep", "p", "stretch")  # the material state (SheetModel.history)


@dataclass
class Parameter:
    """A number the sheet's equations depend on, by name (its scene key) and value. A kind
    says how a value enters: `respond(value)` -> the keywords of SheetModel.respond at that
    value (material, thickness), `external(driver, lam)` -> dR/dp from the loads (owned
    rows, solve coordinates; None where the loads do not depend on it), and `beads(lines,
    value)` -> the drawbeads' lines at that value."""

    name: str
    value: float
    rates = None  # d(coefficient)/dp per tool of the contact set, the holder's last (a friction parameter)
    holder_force = False  # the holder's force is this value (over the model's symmetry)

    def respond(self, value: float) -> dict:
        return {}

    def external(self, driver, lam: float):
        return None

    def beads(self, lines, value: float) -> tuple:
        """The drawbeads' lines (contact/drawbead.py DrawbeadLine) at that value: as they are."""
        return tuple(lines)


@dataclass
class MaterialParameter(Parameter):
    """A constant of the material: pack(value) -> the packed material array at that value."""

    pack: object = None

    def respond(self, value: float) -> dict:
        return {"material": self.pack(value)}


@dataclass
class ThicknessParameter(Parameter):
    """The sheet's initial thickness."""

    def respond(self, value: float) -> dict:
        return {"thickness": value}


@dataclass
class FrictionParameter(Parameter):
    """A Coulomb coefficient (tools.friction, tools.punch_friction, ...): the sheet does not
    depend on it; the friction part does, on the tools it is the coefficient of (rates: 1 on
    those, 0 on the others)."""

    rates: tuple = ()


@dataclass
class HolderForceParameter(Parameter):
    """The force-controlled holder's force on the whole blank (tools.blank_holder_force): the
    sheet does not depend on it; the holder's split of it over the pinched nodes does, and
    friction presses with that split (contact/holder.py)."""

    holder_force = True


@dataclass
class DrawbeadParameter(Parameter):
    """A drawbead's restraint or uplift per unit length (tools.drawbead[i].restraint, .uplift):
    the sheet does not depend on it; the drawbeads' part does (contact/drawbead.py), through
    `beads(lines, value)`, the beads with this one's force at value."""

    index: int = 0
    key: str = "restraint"

    def beads(self, lines, value: float) -> tuple:
        return tuple(replace(line, **{self.key: value}) if i == self.index else line for i, line in enumerate(lines))


@dataclass
class ReleasedParameter(Parameter):
    """A parameter of a drawn sheet whose tools withdraw (contact/springback.py): the sheet
    depends on it as in the drawing (`of`'s respond), and the released forces, R -= lambda f,
    move with it: dR/dp = -lambda f', f' (`dforce`, owned rows, x, y, z) the drawn state's
    internal forces' derivative (Sensitivity.released)."""

    of: Parameter = None
    dforce: np.ndarray = None

    def respond(self, value: float) -> dict:
        return self.of.respond(value)

    def external(self, driver, lam: float):
        return -lam * self.dforce


@dataclass
class PressureParameter(Parameter):
    """The dead pressure at load factor 1 (its value the driver's): R = f_int - lambda p f,
    so dR/dp = -lambda f_ext / p."""

    def external(self, driver, lam: float):
        if self.value == 0.0:
            raise InputError(f"output.sensitivities ({self.name})", "needs a pressure other than 0")
        return -lam * driver.f_ext.getArray(readonly=True) / self.value


def scene_parameters(scene) -> list[Parameter]:
    """The parameters a scene names in `[output] sensitivities` (checked with the scene:
    "material.<number>", "material.thickness", "loads.pressure"; a tool scene's "tools.friction"
    and a tool's own "tools.punch_friction", ...: the coefficient of the tools (punch, die,
    holder) that carry it; "tools.blank_holder_force")."""
    out = []
    for name in scene.output.sensitivities:
        section, _, key = name.partition(".")
        if section == "tools" and key in FRICTION_KEYS:
            t = scene.tools
            own = {tool: getattr(t, f"{tool}_friction") for tool in FRICTION_TOOLS}
            carried = [own[tool] is None if key == "friction" else key == f"{tool}_friction" for tool in own]
            out.append(FrictionParameter(name, float(getattr(t, key)), rates=tuple(float(c) for c in carried)))
        elif DRAWBEAD_PARAMETER.fullmatch(name):
            index, key = DRAWBEAD_PARAMETER.fullmatch(name).groups()
            out.append(DrawbeadParameter(name, float(getattr(scene.tools.drawbead[int(index)], key)), index=int(index),
                                         key=key))
        elif name == "tools.blank_holder_force":
            out.append(HolderForceParameter(name, float(scene.tools.blank_holder_force)))
        elif name == "material.thickness":
            out.append(ThicknessParameter(name, float(scene.material.thickness)))
        elif name == "loads.pressure":
            out.append(PressureParameter(name, float(scene.loads.pressure)))
        else:
            out.append(MaterialParameter(name, float(getattr(scene.material, key)),
                                         lambda value, key=key: scene.with_material(key, value).hill79().pack()))
    return out


class Sensitivity(Record):
    """d/dp of the carrier, the material state and the residual along the path, for each
    parameter (module docstring). A record of `driver` (results/listeners.py Record): add it
    with driver.records.append."""

    def __init__(self, driver, parameters):
        self.driver, self.model = driver, driver.model
        self.parameters = list(parameters)
        if driver.parts:
            why = next((w for w in (part.derivatives() for part in driver.parts) if w), None)
            if why is None and not self.model.finite:
                why = "a tool scene's sensitivities need the effect 'finite_strain' (the nodes' thickness)"
            if why is None and any(isinstance(p, ThicknessParameter) for p in self.parameters):
                why = "material.thickness places the tools around the sheet: not differentiated with tools yet"
            if why is not None:
                raise InputError("output.sensitivities", f"{why}; a tool scene's sensitivities need rigid tools, "
                                 "with or without friction, drawbeads, a holder and ironing")
        self._known = fem.Function(self.model.V)  # the known rows' derivatives, shared with the ghosts
        zeros = lambda a: np.zeros_like(a)  # noqa: E731
        start = self.model.history()
        self.dq = {p.name: zeros(driver.q.x.array) for p in self.parameters}
        self.dh = {p.name: {k: zeros(start[k]) for k in KEYS} for p in self.parameters}
        self.dR = {p.name: zeros(driver.residual_full) for p in self.parameters}
        self.switches = []  # per increment: layers that turned elastic/plastic within +-eps, all parameters
        # per increment: the largest total |dR/dp| on the free rows over the scale of the loads'
        # (the pseudo-load's and the reactions' derivatives, the larger: a check), the corrections
        # its solves took (all parameters)
        self.free_residual, self.corrections = [], []
        self._step = fem.Function(self.model.V)  # a correction's solve
        self.corrected = any(part.tangent_misses() for part in driver.parts)  # the solves are corrected

    # -- the record's protocol ------------------------------------------------------------------
    def converged(self, driver, lam: float) -> None:
        """The increment to lam converged and is not committed yet: q'_n+1, h'_n+1 and dR/dp,
        with the consistent tangent at the converged state, from h_n (the parts put back as
        the last iterate left them: Driver.linearized)."""
        with driver.linearized(lam):
            self._differentiate(driver, lam)

    def _differentiate(self, driver, lam: float) -> None:
        model, comm = self.model, self.model.mesh.comm
        h_n = model.history()
        q = driver.q.x.array.copy()
        switched, ratio, corrections = 0, 0.0, 0
        owned = driver.n_owned * BS
        free = np.ones(owned, dtype=bool)
        free[driver.bc_dofs[driver.bc_dofs < owned]] = False
        for par in self.parameters:
            eps = self.step(par.name)
            dh = self.dh[par.name]
            f = [model.respond(q, _along(h_n, dh, s * eps), **par.respond(par.value + s * eps))[0] for s in (1, -1)]
            rhs = driver.assembled(f[0] - f[1]) / (2 * eps)
            load = par.external(driver, lam)
            if load is not None:
                rhs[: load.size] += load
            dx_n = self.dq[par.name].reshape(-1, BS)[: driver.n_owned, :3].copy()  # the committed positions'
            sheet = rhs[:owned].copy()  # the sheet's and the loads' dR/dp at fixed q (the linear total's start)
            for part in driver.parts:
                part.pseudo_load(par.name, rhs[:owned].reshape(-1, BS), dx_n, eps, par)
            rhs[~free] = 0.0
            # the known rows' derivatives (solve coordinates, ghosts from their owners)
            if driver.parts:
                de33 = self.thickness_strain(par.name)  # d/dp of ln(t/t0) per cell, committed (h_n, dh)
                self._known.x.array[:] = 0.0
                for part in driver.parts:
                    part.known_derivatives(self._known.x.array[:owned].reshape(-1, BS), de33)
                self._known.x.scatter_forward()
                delta = self._known.x.array.copy()
            else:  # the supports keep theirs: 0 where their values do not depend on p, a springback's held node its drawn one
                delta = np.zeros_like(q)
                delta[driver.bc_dofs] = self.dq[par.name][driver.bc_dofs]
            out = driver.dq  # the step's work array, free after convergence
            if not driver.solve_lifted(delta, out, extra=-rhs):
                raise RuntimeError(f"the sensitivity solve for {par.name} failed at load factor {lam:.6g}")
            pseudo = comm.allreduce(float(np.abs(rhs[:owned][free]).max(initial=0.0)), op=MPI.MAX)
            real = partial(self._total, par, out, q, h_n, dh, eps, dx_n, load, free, lam)
            if self.corrected:  # first on the sheet's linear share, then on the element loop's
                linear = partial(self._linear_total, out, dx_n, sheet, free, lam, eps, par)
                corrections += self._correct(par, out, q, lam, linear(), pseudo, linear)[1]
                taken, taken_corrections = self._correct(par, out, q, lam, real(), pseudo, real)
                corrections += taken_corrections
            else:
                taken = real()
            for _ in range(BORDER_PASSES):  # a part's own unknown (the open holder's lift), then the total again
                if not any([part.border_derivative(par.name, driver, out, taken.dR, par) for part in driver.parts]):
                    break
                taken = real()
                if self.corrected:
                    taken, taken_corrections = self._correct(par, out, q, lam, taken, pseudo, real)
                    corrections += taken_corrections
            scale = max(pseudo, taken.size)  # the pseudo-load's or the reactions' derivatives, the larger
            ends = taken.ends
            self.dq[par.name] = taken.dq
            self.dh[par.name] = {k: (ends[0][1][k] - ends[1][1][k]) / (2 * eps) for k in KEYS}
            self.dR[par.name] = taken.dR[:owned]
            yielded = [e[1]["p"] > h_n["p"] for e in ends]
            switched += int(np.sum(yielded[0] != yielded[1]))
            ratio = max(ratio, taken.worst / scale if scale > 0 else 0.0)
        self.switches.append(comm.allreduce(switched, op=MPI.SUM))
        self.free_residual.append(ratio)
        self.corrections.append(corrections)

    def _correct(self, par, out, q, lam, taken, pseudo, measure) -> tuple["_Taken", int]:
        """Defect corrections of the solved derivative in `out` (module docstring), `taken`
        (_Taken) its total as measure() takes it: (the last total, the corrections taken)."""
        scale = max(pseudo, taken.size)
        before, previous, corrections = np.inf, None, 0
        for _ in range(MAX_CORRECTIONS):
            if not taken.worst > CORRECT_ABOVE * scale:
                break
            if not taken.worst < CORRECTED_BY * before:  # no longer converging: keep the better one
                if taken.worst > before:
                    out.x.array[:] = previous
                    taken = measure()
                break
            corrections += 1  # K misses a part's terms: solve again for what the total leaves
            before, previous = taken.worst, out.x.array.copy()
            if not self.driver.solve_lifted(np.zeros_like(q), self._step, extra=-taken.free_total):
                raise RuntimeError(f"the sensitivity correction for {par.name} failed at load factor {lam:.6g}")
            out.x.array[:] += self._step.x.array
            taken = measure()
        return taken, corrections

    def _linear_total(self, out, dx_n, sheet, free, lam, eps, par) -> "_Taken":
        """The total dR/dp along the solved derivative in `out` with the sheet's share linear in
        q', sheet + K q' (K the element tangents of the converged increment, the sheet's own
        Jacobian): the corrections' first estimate, with no element loop (ends None)."""
        driver = self.driver
        dR = sheet + driver.apply_tangent(out.x.array)[: sheet.size]
        return self._with_parts(par, driver.to_xyz(out.x.array), None, dR, dx_n, free, lam, eps)

    def _total(self, par, out, q, h_n, dh, eps, dx_n, load, free, lam) -> "_Taken":
        """The solved derivative in `out` (solve coordinates) taken through the element loop and
        the parts (_Taken)."""
        driver, model, comm = self.driver, self.model, self.model.mesh.comm
        owned = driver.n_owned * BS
        dq = driver.to_xyz(out.x.array)
        ends = [model.respond(q + s * eps * dq, _along(h_n, dh, s * eps), squeeze=model.moved_squeeze(s * eps * dq),
                              **par.respond(par.value + s * eps)) for s in (1, -1)]
        dR = driver.assembled(ends[0][0] - ends[1][0]) / (2 * eps)
        if load is not None:
            dR[: load.size] += load
        return self._with_parts(par, dq, ends, dR, dx_n, free, lam, eps)

    def _with_parts(self, par, dq, ends, dR, dx_n, free, lam, eps) -> "_Taken":
        """The sheet's dR/dp (every owned row) with the parts' forces' derivatives (_Taken)."""
        driver, comm = self.driver, self.model.mesh.comm
        owned = driver.n_owned * BS
        for part in driver.parts:
            part.carry(par.name, dq.reshape(-1, BS)[: driver.n_owned, :3], dx_n, dR[:owned].reshape(-1, BS), lam,
                       eps, par)
        total = dR[:owned].copy()  # with the parts' forces: about zero on the free rows
        for part in driver.parts:
            part.total_derivative(par.name, total.reshape(-1, BS))
        size = comm.allreduce(float(np.abs(total).max(initial=0.0)), op=MPI.MAX)
        total[~free] = 0.0
        return _Taken(dq, ends, dR, total, comm.allreduce(float(np.abs(total).max(initial=0.0)), op=MPI.MAX), size)

    def checkpoint(self) -> dict:
        nodes, cells = {}, {}
        for i, par in enumerate(self.parameters):
            nodes[f"sensitivity{i}_dq"] = self.dq[par.name][: self.driver.n_owned * BS].reshape(-1, BS).copy()
            for part in self.driver.parts:
                nodes.update({f"sensitivity{i}_{k}": v for k, v in part.derivative_state(par.name).items()})
            for k in KEYS:
                cells[f"sensitivity{i}_{k}"] = self.dh[par.name][k]
        return {"nodes": nodes, "cells": cells}

    def restore(self, state: dict) -> None:
        work = self.driver.dq.x  # to share the owned rows with the ghosts
        for i, par in enumerate(self.parameters):
            key = f"sensitivity{i}_dq"
            if key not in state["nodes"]:
                raise InputError("resume", "the checkpoint carries no sensitivities for this scene's parameters")
            work.array[:] = 0.0
            work.array[: self.driver.n_owned * BS] = state["nodes"][key].ravel()
            work.scatter_forward()
            self.dq[par.name] = work.array.copy()
            for part in self.driver.parts:
                own = {k: state["nodes"][f"sensitivity{i}_{k}"] for k in part.derivative_state(par.name)}
                if own:
                    part.restore_derivative_state(par.name, own)
            for k in KEYS:
                self.dh[par.name][k][...] = state["cells"][f"sensitivity{i}_{k}"]

    def released(self, driver) -> "Sensitivity":
        """The sensitivities carried on through the springback `driver` (the drawn sheet of this
        one's driver, the tools' forces f released as a nodal load: contact/springback.py), from
        where the drawing left them: q' and h' of the drawn state, and f' its element forces'
        dR/dp (residual(): the derivative of f_int at the converged drawn state, every row; on
        the tools' rows the reactions') turned from the nodes' frames, held, into x, y, z, 0 on
        the springback's supports as f is."""
        owned = driver.n_owned * BS
        parameters = []
        for par in self.parameters:
            dforce = self.driver.to_xyz(self.dR[par.name][:owned])
            dforce[driver.bc_dofs[driver.bc_dofs < owned]] = 0.0
            parameters.append(ReleasedParameter(par.name, par.value, of=par, dforce=dforce))
        out = Sensitivity(driver, parameters)
        for par in self.parameters:
            out.dq[par.name][:] = self.dq[par.name]
            out.dh[par.name] = {k: v.copy() for k, v in self.dh[par.name].items()}
        return out

    # -- what a run reads -----------------------------------------------------------------------
    def step(self, name: str) -> float:
        """The central differences' step of the parameter `name`: STEP of its value (STEP where it is 0)."""
        value = next(par.value for par in self.parameters if par.name == name)
        return STEP * abs(value) if value else STEP

    def carrier(self, name: str) -> np.ndarray:
        """dq/dp (x, y, z; the local array, ghosts included) at the last converged increment."""
        return self.dq[name]

    def residual(self, name: str) -> np.ndarray:
        """dR/dp on the owned rows, reactions included: summed over a support's rows, the
        sensitivity of its reaction (SheetProblem.reaction(..., residual=))."""
        return self.dR[name]

    def state(self, name: str) -> dict:
        """d/dp of the material state (history()'s keys) at the last converged increment."""
        return self.dh[name]

    def thickness_strain(self, name: str) -> np.ndarray:
        """d/dp of SheetModel.thickness_strain per owned cell (finite strains: the mean of
        d ln lambda3 = lambda3' / lambda3 over the points)."""
        if not self.model.finite:
            raise InputError(f"output.sensitivities ({name})", "the thickness strain's sensitivity needs finite_strain")
        return (self.dh[name]["stretch"] / self.model.history()["stretch"]).mean(axis=1)


class _Taken(NamedTuple):
    """A solved derivative taken through the element loop and the parts: dq (x, y, z), the two
    ends of the differences (SheetModel.respond's), dR/dp (the sheet's, every row), the total
    dR/dp on the free rows (0 on the known ones: what a correction solves for), its largest
    entry, and the largest total on all owned rows (the reactions' derivatives among them)."""

    dq: np.ndarray
    ends: list
    dR: np.ndarray
    free_total: np.ndarray
    worst: float
    size: float


def _along(h: dict, dh: dict, step: float) -> dict:
    """The material state h + step dh (new arrays)."""
    return {k: h[k] + step * dh[k] for k in KEYS}
