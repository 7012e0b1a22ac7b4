"""The nonlinear sheet on one mesh: carrier, per-cell data, material state, element forces.

``SheetModel.evaluate(q)`` runs the element loop (shellform.assembly.sheet_kernels) over the
owned cells at the carrier state q and hands the element vectors and matrices to DOLFINx through
two cell-wise "copy" forms (assemble.py), so DOLFINx owns assembly, ghosts and boundary
conditions. The material state (plastic strain and equivalent plastic strain per quadrature
point and thickness layer) is committed only when an increment converges.
"""

import time
from dataclasses import dataclass

import numba
import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.kernels import check_mesh
from shellform import effects as effects_registry
from shellform.errors import InputError
from shellform.assembly.sheet_element import BS, COMPONENTS, NDOF
from shellform.assembly import assumed_membrane
from shellform.assembly.sheet_kernels import SheetKernels
from shellform.material import hencky, ironing, plane_stress, section
from shellform.material.stability import membrane_stability
from shellform.material.update import section_update
from shellform.nonlinear.assemble import CellArrayForms
from shellform import _jit as jit


@dataclass
class Evaluation:
    """Counts and times of one evaluation of the element loops."""

    plastic_layers: int  # quadrature-point layers that flowed plastically
    failures: int  # layers whose return mapping did not converge
    element_s: float  # kinematics and element tensors (FFCx kernels, maps)
    constitutive_s: float  # the section update
    guard: int = 0  # section points past the strain guard (non-finite or > 1000 % strain)

    @property
    def failed(self) -> bool:
        return bool(self.failures or self.guard)

    def cause(self) -> str:
        """What stopped the material update, in words ('' if nothing did)."""
        words = []
        if self.guard:
            words.append(f"strain guard: {self.guard} section points past 1000 % strain or not finite")
        if self.failures:
            words.append(f"return mapping failed in {self.failures} layers")
        return "; ".join(words)


CELLS_PER_THREAD = 256  # below this many cells a thread costs more to start than it saves


def use_cores(comm, num_cells: int) -> int:
    """Threads of the element and material loops on this rank: the cores this process may run
    on, shared by the ranks on its node, at most NUMBA_NUM_THREADS (read when numba is imported)
    and SHELLFORM_THREADS (`shellform run --threads N` sets it; read when the model is built),
    and no more than one per CELLS_PER_THREAD cells. The loops run their chunks of cells on that
    many threads (shellform._jit.over_threads)."""
    import os

    local = comm.Split_type(MPI.COMM_TYPE_SHARED)
    ranks = local.size
    local.Free()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    cap = min(numba.config.NUMBA_NUM_THREADS, int(os.environ.get("SHELLFORM_THREADS") or numba.config.NUMBA_NUM_THREADS))
    return max(1, min(cap, cores // ranks, num_cells // CELLS_PER_THREAD))


class SheetModel:
    """Mesh, effects, material and state of the nonlinear sheet."""

    components = COMPONENTS

    def __init__(self, mesh, material, thickness: float, effects=("geometric_nonlinearity",),
                 thickness_points: int = 5, kappa0=None, quadrature_degree: int = 4, pressure_field=None):
        check_mesh(mesh)
        if not np.isfinite(thickness):
            raise InputError("material.thickness", f"must be finite, got {thickness}")
        if not thickness > 0:
            raise InputError("material.thickness", f"must be > 0, got {thickness}")
        self.mesh, self.effects = mesh, tuple(effects)
        self.nonlinear = "geometric_nonlinearity" in self.effects
        self.plastic = "plasticity" in self.effects
        self.finite = "finite_strain" in self.effects
        if self.finite:
            effects_registry.require("finite_strain", self.effects)  # its layers need these parts
        self.shallow = kappa0 is not None
        surface = kappa0 if hasattr(kappa0, "slopes") else self.shallow  # z0(x, y) or a constant kappa0
        self.kernels = SheetKernels.get(self.nonlinear, surface, mesh.comm, quadrature_degree)
        self.material = np.asarray(material, dtype=np.float64)
        self.thickness = float(thickness)
        self.consts = np.zeros(4) if surface is not True else np.asarray(kappa0, dtype=np.float64).ravel()
        self.V = fem.functionspace(mesh, ("Lagrange", 1, (BS,)))
        tdim = mesh.topology.dim
        self.num_cells = mesh.topology.index_map(tdim).size_local
        self.cells = np.arange(self.num_cells, dtype=np.int32)
        self.threads = use_cores(mesh.comm, self.num_cells)
        self.dofs = np.ascontiguousarray(self.V.dofmap.list[: self.num_cells], dtype=np.int32)
        self.unrolled_dofs = (BS * self.dofs[:, :, None] + np.arange(BS)).reshape(self.num_cells, NDOF)
        g = mesh.geometry
        self.cell_coords = np.ascontiguousarray(g.x[g.dofmaps[0][: self.num_cells]].reshape(self.num_cells, 9))
        x = self.cell_coords.reshape(-1, 3, 3)
        a, b = x[:, 1, :2] - x[:, 0, :2], x[:, 2, :2] - x[:, 0, :2]
        area = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        self.cell_area = area
        # beta = 1: the compatible membrane strain; below 1 the assumed one (docs/locking.md)
        tied = "assumed_membrane" in self.effects
        beta = assumed_membrane.stabilisation(self.thickness, self.cell_coords, mesh.comm) if tied else 1.0
        self.beta = np.full(self.num_cells, beta)
        self.tying = assumed_membrane.tyings(self.cell_coords) if tied else np.zeros((0, 3, 27))
        self.kernels.require(tied, "ironing" in self.effects)  # the kernels these two call, compiled once
        self.cell_size = float(mesh.comm.allreduce(np.sqrt(area.min()) if area.size else np.inf, op=MPI.MIN))
        el = self.kernels.element
        self.nqp = el.nqp
        self.P = np.zeros((self.num_cells, el.sym_dim, 9))
        self.pressure_vectors = np.zeros((self.num_cells, NDOF))  # a unit dead pressure along +z (spread by pressure_field)
        self.kernels.setup(self.cell_coords, self.P, self.pressure_vectors, pressure_field)
        # Material state: committed (n) and trial, per cell, quadrature point and layer.
        nz = thickness_points if self.plastic else 1
        if self.plastic:
            self.zeta, self.wz = section.through_thickness_rule(thickness_points)
        else:
            self.zeta, self.wz = np.zeros(1), np.ones(1)
        shape = (self.num_cells, self.nqp, nz)
        self.ep_n, self.p_n = np.zeros(shape + (3,)), np.zeros(shape)
        self.ep, self.p = np.zeros(shape + (3,)), np.zeros(shape)
        # the layers' thickness stretch lambda3 per point (finite strain): committed and trial
        self.stretch_n, self.stretch = np.ones(shape[:2]), np.ones(shape[:2])
        self.z = np.zeros((self.num_cells, el.nz))
        self.strain = np.zeros((self.num_cells, self.nqp, 6))
        self.taper = np.zeros((self.num_cells, self.nqp, 3))  # curvature carried without a moment (follow_taper)
        self.resultants = np.zeros((self.num_cells, self.nqp, 6))
        self.tangents = np.zeros((self.num_cells, self.nqp, 6, 6))
        self.stability_n = np.full(self.num_cells, np.nan)  # of the committed state (membrane_stability)
        # ironing (shellform.material.ironing): the tools' clearance over each cell (inf: none)
        # and the pressure on the sheet's faces at each point
        self.ironing = "ironing" in self.effects
        self.clearance = np.full(self.num_cells, np.inf)
        self.face_pressure = np.zeros((self.num_cells, self.nqp))
        self.ironed_d = np.zeros((self.num_cells, self.nqp, 3))  # d_g of the pressed cells' points
        self.ironed = np.zeros((self.num_cells, 11))  # phi'', phi' (0: not pressed), the clearance's gradient
        self.clearance_curvature = np.zeros((self.num_cells, 3, 3, 3))  # its second derivative at the vertices
        self.pressed = 0  # points the last evaluation pressed
        self.forms = CellArrayForms(self.V, self.cells, NDOF)
        self.state_version = 0  # changes with the committed material state (Driver's reuse of an evaluation)

    # -- the element loop -------------------------------------------------------------------
    def evaluate(self, q: fem.Function, tangent: bool = True, elastic_tangent: bool = False) -> Evaluation:
        """Element forces (and tangents) at the carrier state q, into the copy forms."""
        out = {"z": self.z, "strain": self.strain, "ep": self.ep, "p": self.p, "stretch": self.stretch,
               "clearance": self.clearance,
               "resultants": self.resultants, "tangents": self.tangents, "face_pressure": self.face_pressure,
               "ironed_d": self.ironed_d, "ironed": self.ironed, "vectors": self.forms.vectors}
        ev, self.pressed = self._loops(q.x.array, self.ep_n, self.p_n, self.material, self.thickness, out, tangent,
                                       elastic_tangent)
        return ev

    def _loops(self, q, ep_n, p_n, material, thickness, out, tangent=False, elastic_tangent=False):
        """The element and material loops at the carrier array q from the committed state
        (ep_n, p_n) with `material` and `thickness` (and the faces' penalty modulus of that
        material), the cells' clearance `out["clearance"]` (its gradient in out["ironed"]), into
        the arrays of `out` (SheetModel's names; the tangents into the copy forms' matrices with
        `tangent`): (Evaluation, points pressed)."""
        k = self.kernels
        t0 = time.perf_counter()
        k.strain_loop(self.threads, self.cells, self.cell_coords, self.dofs, q, self.P, self.consts, self.beta,
                      self.tying, out["z"], out["strain"])
        t1 = time.perf_counter()
        nplastic, nfail, nguard = section_update(
            out["strain"], self.taper, material, thickness, self.plastic, self.finite, self.zeta, self.wz,
            ep_n, p_n, out["ep"], out["p"], out["stretch"], out["resultants"], out["tangents"],
            elastic_tangent, self.threads)
        pressed = 0
        if self.ironing:
            modulus = ironing.through_thickness_modulus(material)  # the faces' penalty, of this material
            pressed, failed = ironing.squeeze(out["strain"], out["clearance"], thickness, modulus,
                                              2.0 * k.element.weights, out["resultants"], out["tangents"],
                                              out["face_pressure"], out["ironed_d"], out["ironed"])
            nguard += failed  # a mid-surface turned inside out: past the strain guard
        t2 = time.perf_counter()
        k.tensor_loop(self.threads, self.cells, self.cell_coords, self.P, self.consts, self.beta, self.tying, out["z"],
                      out["resultants"], out["tangents"], out["ironed_d"], out["ironed"], tangent, out["vectors"],
                      self.forms.matrices)
        if tangent and pressed:
            self._faces_turn(out["ironed"])
        t3 = time.perf_counter()
        return Evaluation(int(nplastic), int(nfail), (t1 - t0) + (t3 - t2), t2 - t1, int(nguard)), pressed

    def history(self) -> dict:
        """The committed material state an increment starts from, as copies: per cell, point
        and layer the plastic strain "ep" (3) and the equivalent plastic strain "p", and per
        point the layers' thickness stretch "stretch"."""
        return {"ep": self.ep_n.copy(), "p": self.p_n.copy(), "stretch": self.stretch_n.copy()}

    def respond(self, q: np.ndarray, history: dict, material: np.ndarray | None = None,
                thickness: float | None = None, squeeze: tuple | None = None) -> tuple[np.ndarray, dict, bool]:
        """The element forces and the updated material state at the carrier array q (with
        ghosts) from the committed state `history` (as history() gives it), with another
        material, thickness or cells' clearance and its gradient (`squeeze`, as moved_squeeze
        gives them) where given: the map
        (q, h_n, material) -> (f_e, h_n+1) that one evaluation computes (the same loops), on
        arrays of its own, so that nothing of the model's state changes. Returns (element
        vectors (cells, NDOF), the updated state in history()'s keys, whether the material
        update failed)."""
        mat = self.material if material is None else np.asarray(material, dtype=np.float64)
        t = self.thickness if thickness is None else float(thickness)
        out = {"z": np.zeros_like(self.z), "strain": np.zeros_like(self.strain), "ep": np.zeros_like(self.ep),
               "p": np.zeros_like(self.p), "stretch": np.ones_like(self.stretch),
               "resultants": np.zeros_like(self.resultants), "tangents": np.zeros_like(self.tangents),
               "face_pressure": np.zeros_like(self.face_pressure), "ironed_d": np.zeros_like(self.ironed_d),
               "ironed": self.ironed.copy(), "vectors": np.zeros_like(self.forms.vectors), "clearance": self.clearance}
        if squeeze is not None:
            out["clearance"], out["ironed"][:, 2:] = squeeze
        ev, _ = self._loops(q, history["ep"], history["p"], mat, t, out)
        return out["vectors"], {"ep": out["ep"], "p": out["p"], "stretch": out["stretch"]}, ev.failed

    def moved_squeeze(self, dq: np.ndarray) -> tuple | None:
        """The cells' clearances and their gradients with the vertices moved by the carrier's
        change dq (with ghosts), to first order: c + sum_i n_i . dx_i / 3 over the cell's vertices
        and n_i + H_i dx_i (n_i = dc_i/dx_i and H_i = d n_i/dx_i, as squeeze holds them; 0 at a
        vertex that keeps its last clearance). None without the effect 'ironing'."""
        if not self.ironing:
            return None
        dx = dq[self.unrolled_dofs].reshape(self.num_cells, 3, BS)[:, :, :3]
        gradient = self.ironed[:, 2:].reshape(self.num_cells, 3, 3)
        change = np.einsum("cvk,cvk->c", gradient, dx) / 3.0
        moved = gradient + np.einsum("cvkl,cvl->cvk", self.clearance_curvature, dx)
        return self.clearance + change, moved.reshape(self.num_cells, 9)  # inf stays inf

    def _faces_turn(self, ironed: np.ndarray) -> None:
        """The pressed cells' tangents += -phi' A0 / 3 H_i on each vertex's displacement rows:
        the faces' push -phi' A0 / 3 n_i turning with the vertex (shellform.material.ironing)."""
        k = np.flatnonzero(ironed[:, 0] > 0.0)
        blocks = -(ironed[k, 1] * self.cell_area[k] / 3.0)[:, None, None, None] * self.clearance_curvature[k]
        for i in range(3):
            self.forms.matrices[k, BS * i:BS * i + 3, BS * i:BS * i + 3] += blocks[:, i]

    def tensor_arrays(self, tangent: bool) -> None:
        """The element vectors (and tangents) from the last evaluation's strains, stresses and
        section tangents: with tangent=True after an evaluation without, its K alone."""
        self.kernels.tensor_loop(self.threads, self.cells, self.cell_coords, self.P, self.consts, self.beta, self.tying,
                                 self.z, self.resultants, self.tangents, self.ironed_d, self.ironed, tangent,
                                 self.forms.vectors, self.forms.matrices)
        if tangent and self.pressed:
            self._faces_turn(self.ironed)

    def squeeze(self, clearance: np.ndarray, gradient: np.ndarray | None = None,
                curvature: np.ndarray | None = None) -> None:
        """The clearance between two tools over each owned cell (mm; inf where no two tools
        face each other across it), the mean of its vertices' c_i, their gradients dc_i/dx_i
        (cells, 3 vertices, 3; default 0: a clearance fixed in space) and the gradients'
        derivatives H_i = d^2 c_i/dx_i^2 (cells, 3 vertices, 3, 3; default 0: faces that do not
        turn): where the sheet is thicker, the tools press its faces
        (shellform.material.ironing) from the next evaluation on. Refused without the effect
        'ironing'."""
        if not self.ironing:
            raise InputError("effects", "a clearance between tools squeezes the sheet only with the effect 'ironing'")
        clearance = np.asarray(clearance, dtype=float)
        if clearance.shape != self.clearance.shape or np.any(np.isnan(clearance)) or np.any(clearance <= 0):
            raise InputError("clearance", f"needs one positive value (or inf) per owned cell, {self.num_cells}")
        gradient = np.zeros((self.num_cells, 9)) if gradient is None else np.asarray(gradient, dtype=float)
        gradient = gradient.reshape(self.num_cells, 9)
        curvature = (np.zeros_like(self.clearance_curvature) if curvature is None
                     else np.asarray(curvature, dtype=float).reshape(self.clearance_curvature.shape))
        if not (np.array_equal(clearance, self.clearance) and np.array_equal(gradient, self.ironed[:, 2:])
                and np.array_equal(curvature, self.clearance_curvature)):
            self.clearance[...] = clearance
            self.ironed[:, 2:] = gradient
            self.clearance_curvature[...] = curvature
            self.state_version += 1

    def face_forces(self) -> np.ndarray:
        """Per owned cell the force with which the tools' faces press the sheet at the last
        evaluation, int p dA over the current area (N; zero where none presses)."""
        E = self.strain[:, :, :3]
        det = (1.0 + 2.0 * E[..., 0]) * (1.0 + 2.0 * E[..., 1]) - E[..., 2] ** 2
        J = np.sqrt(np.maximum(det, 0.0))
        return 2.0 * self.cell_area * ((self.face_pressure * J) @ self.kernels.element.weights)

    def commit(self) -> None:
        """Accept the trial material state (an increment converged); a plastic sheet's membrane
        stability at it (membrane_stability), from the converged iterate's strains, resultants
        and tangents (an elastic one does not neck: nothing watches it)."""
        if self.plastic:
            membrane_stability(self.strain, self.resultants, self.tangents, self.thickness, self.stability_n,
                               self.threads)
        self.ep_n[...] = self.ep
        self.p_n[...] = self.p
        self.stretch_n[...] = self.stretch
        self.state_version += 1

    def follow_taper(self, cells: np.ndarray, q: fem.Function | None = None) -> None:
        """The sections of `cells` (a mask of the owned cells) carry no moment at the curvature of
        the carrier state q (default: the last evaluated state): it becomes their taper, the
        curvature K - taper measures bending from.

        A sheet lying between two flat faces whose thickness t varies has its mid-surface a half
        thickness above the lower face, so that surface curves, K = -grad grad (t / 2), although no
        fibre of the sheet is bent: both faces of the material stay flat, and a solid sheet of that
        shape carries no moment. The Kirchhoff section, whose normals stay normal to the
        mid-surface, would read that curvature as bending, and with the thickness's kinks at the
        plastic fronts resolved ever more sharply it puts moments ~ D grad t / h and nodal forces
        that grow as the mesh is refined on the faces that hold the sheet (docs/contact.md, "The
        taper of the held flange"). The taper is part of the committed state: a section that
        leaves the faces keeps it, as the solid keeps its shape."""
        strain = self.strain if q is None else self._strains_at(q.x.array)
        self.taper[cells] = strain[cells, :, 3:]
        self.state_version += 1

    def _strains_at(self, q: np.ndarray) -> np.ndarray:
        """The section strains (E, K) at the points of every owned cell at the carrier array q
        (ghosts included), on arrays of their own: the strain loop alone."""
        strain = np.zeros_like(self.strain)
        self.kernels.strain_loop(self.threads, self.cells, self.cell_coords, self.dofs, q, self.P, self.consts,
                                 self.beta, self.tying, np.zeros_like(self.z), strain)
        return strain

    def checkpoint(self) -> dict:
        """The committed material state."""
        return {"ep": self.ep_n, "p": self.p_n, "thickness_stretch": self.stretch_n, "taper": self.taper}

    def restore(self, data, q: fem.Function) -> None:
        """The committed material state from a checkpoint() (refused if it does not fit), at the
        converged carrier state q: the last evaluated state becomes the checkpoint's, evaluated
        at q, so that what is read from it (cell_fields, thickness_strain, volume_change) is what
        the run had there."""
        pairs = (("ep", self.ep_n), ("p", self.p_n), ("thickness_stretch", self.stretch_n),
                 ("taper", self.taper))
        for key, target in pairs:
            if key not in data or data[key].shape != target.shape:
                raise InputError("resume", f"the checkpoint's {key!r} does not fit this model (another mesh "
                                           "or effects)")
        for key, target in pairs:
            target[...] = data[key]
        self.evaluate(q, tangent=False)
        self.ep[...], self.p[...], self.stretch[...] = self.ep_n, self.p_n, self.stretch_n
        self.stability_n[...] = np.nan  # not known until an increment converges
        self.state_version += 1

    # -- output fields ------------------------------------------------------------------------
    def membrane_stability(self) -> np.ndarray:
        """Per owned cell, at the last converged increment: the least over its quadrature points
        of the smallest eigenvalue of the tangent of the nominal membrane force on spin-free rates,
        per unit initial thickness (stress units; shellform.material.stability). At or below 0
        the material point has lost its stability: a neck may start there (Considere's force
        maximum in uniaxial tension). NaN before the first increment after a start or a restore,
        and for an elastic sheet."""
        return self.stability_n

    def cell_centres(self) -> np.ndarray:
        """The owned cells' centroids in the initial (flat blank's) x, y: (cells, 2)."""
        return self.cell_coords.reshape(-1, 3, 3).mean(axis=1)[:, :2]

    def cell_fields(self) -> dict[str, np.ndarray]:
        """Per owned cell, averaged over its quadrature points, at the last evaluated state:
        equivalent plastic strain (max over the layers), thickness strain of the section (mean
        over the layers; ln(t/t0) with finite strains, the small-strain e33 without) and the
        major and minor logarithmic strains of the mid-surface."""
        major, minor = _surface_strains(self.strain)
        return {"equivalent_plastic_strain": self.plastic_strain(), "thickness_strain": self.thickness_strain(),
                "major_strain": major, "minor_strain": minor}

    def surface_strain_rates(self, q: np.ndarray, dq: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Per owned cell d/dp of cell_fields' major and minor strains along a derivative dq of
        the carrier array q (both with ghosts): central differences of the strain loop at
        q +- step dq (the principal strains are smooth but where they are equal)."""
        ends = [_surface_strains(self._strains_at(q + sign * step * dq)) for sign in (1.0, -1.0)]
        return tuple((ends[0][i] - ends[1][i]) / (2.0 * step) for i in range(2))

    def plastic_strain(self) -> np.ndarray:
        """Per owned cell: the equivalent plastic strain, the largest over the layers, averaged
        over the quadrature points."""
        return self.p_n.max(axis=2).mean(axis=1)

    def thickness_strain(self) -> np.ndarray:
        """Per owned cell: ln(t/t0) = mean ln lambda3 with finite strains, else the small-strain
        e33 of the layers (mean over the layers and the quadrature points)."""
        if self.finite:
            return np.log(self.stretch_n).mean(axis=1)
        return _mean_thickness_strain(self.strain, self.taper, self.ep_n, self.material, self.zeta, self.wz, self.thickness)

    def volume_change(self) -> float:
        """(V - V0) / V0 of the whole sheet at the last evaluated state: per cell its initial
        area times the mean area stretch sqrt(det(I + 2E)) of the mid-surface times the thickness
        stretch exp(thickness strain). With finite strains only elastic volume change remains."""
        e = self.strain[:, :, :3]
        J2 = np.sqrt(np.maximum((1 + 2 * e[..., 0]) * (1 + 2 * e[..., 1]) - e[..., 2] ** 2, 0.0)).mean(axis=1)
        t = np.exp(self.thickness_strain())
        comm = self.mesh.comm
        V = comm.allreduce(float(np.sum(self.cell_area * J2 * t)), op=MPI.SUM)
        return V / comm.allreduce(float(np.sum(self.cell_area)), op=MPI.SUM) - 1.0


@jit.njit
def _mean_thickness_strain(strain, taper, ep, mat, zeta, wz, thickness):
    """Per cell: the thickness strain of every layer (plane_stress.thickness_strain) at strains
    e_m + zeta t (k - taper), weighted through the thickness and averaged over the quadrature points."""
    ncells, nqp = strain.shape[0], strain.shape[1]
    e33 = np.zeros(ncells)
    for c in range(ncells):
        acc = 0.0
        for g in range(nqp):
            for k in range(zeta.size):
                layer = strain[c, g, :3] + zeta[k] * thickness * (strain[c, g, 3:] - taper[c, g])
                acc += wz[k] * plane_stress.thickness_strain(layer, ep[c, g, k], mat)
        e33[c] = acc / nqp
    return e33


@jit.njit
def _surface_strains(strain):
    """Per cell: the principal values of the mid-surface Hencky strain 1/2 ln(I + 2E), of the
    tensor averaged over the quadrature points (major >= minor)."""
    ncells, nqp = strain.shape[0], strain.shape[1]
    major, minor = np.zeros(ncells), np.zeros(ncells)
    eps, P, W = np.zeros(3), np.zeros((3, 3)), np.zeros(16)
    for c in range(ncells):
        m = np.zeros(3)
        for g in range(nqp):
            if hencky.log_strain(strain[c, g, :3].copy(), eps, P, W):
                m += eps / nqp
        mean, rad = 0.5 * (m[0] + m[1]), np.sqrt(0.25 * (m[0] - m[1]) ** 2 + 0.25 * m[2] ** 2)
        major[c], minor[c] = mean + rad, mean - rad
    return major, minor
