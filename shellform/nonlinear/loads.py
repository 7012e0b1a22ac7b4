"""Loads of the nonlinear sheet, all proportional to the load factor lambda.

    pressure      dead pressure p along +z per unit blank area (an element vector, sheet_kernels)
    point forces  (fx, fy, fz) at a vertex
    edge moments  m per unit length about a side's tangent: the work m theta of the rotation
                  theta = atan2(w_n, 1 + u_n,n) of the fibre normal to the side (exact for any
                  rotation); positive m turns the side's outward fibre towards +z
"""

from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.sheet_element import BS, COMPONENTS
from shellform.errors import InputError
from shellform.loads import vertex_dof
from shellform.mesh import SIDE_TAG

OUTWARD = {"left": ("x", -1.0), "right": ("x", 1.0), "bottom": ("y", -1.0), "top": ("y", 1.0)}


@dataclass
class PointForce:
    x: float
    y: float
    force: tuple[float, float, float]


@dataclass
class EdgeMoment:
    side: str
    m: float  # per unit length


@dataclass
class SheetLoads:
    pressure: float = 0.0
    pressure_field: object = None  # forms.loads.PressureField (None: uniform per unit plan area)
    points: list[PointForce] = field(default_factory=list)
    moments: list[EdgeMoment] = field(default_factory=list)


def side_vertices(V, facet_tags, side):
    """Owned carrier blocks on a side and their tributary lengths (P1: half of each edge)."""
    dofs = fem.locate_dofs_topological(V, facet_tags.dim, facet_tags.find(SIDE_TAG[side]))
    owned = V.dofmap.index_map.size_local
    coords = V.tabulate_dof_coordinates()
    axis = 1 if OUTWARD[side][0] == "x" else 0  # the coordinate along the side
    s_local = coords[dofs[dofs < owned], axis]
    s_all = np.sort(np.concatenate(V.mesh.comm.allgather(s_local)))
    trib = np.zeros_like(s_all)
    trib[1:] += 0.5 * np.diff(s_all)
    trib[:-1] += 0.5 * np.diff(s_all)
    mine = dofs[dofs < owned]
    lengths = trib[np.searchsorted(s_all, coords[mine, axis])]
    return mine, lengths


class NodalLoads:
    """Point forces and edge moments as nodal contributions to the residual and tangent."""

    def __init__(self, V, facet_tags, loads: SheetLoads, tol: float):
        self.forces = []  # (block, 3 forces)
        for k, p in enumerate(loads.points):
            i, found = vertex_dof(V, p.x, p.y, tol)
            if not found:
                raise InputError(f"loads.point[{k}]", f"no mesh vertex at ({p.x}, {p.y})")
            if i >= 0:
                self.forces.append((i, np.asarray(p.force, dtype=np.float64)))
        self.moments = []  # (blocks, m * lengths, normal axis, sign)
        for mo in loads.moments:
            if mo.side not in SIDE_TAG:
                raise InputError("loads.moment.side", f"unknown side {mo.side!r}")
            blocks, lengths = side_vertices(V, facet_tags, mo.side)
            axis, sign = OUTWARD[mo.side]
            self.moments.append((blocks, sign * mo.m * lengths, axis))
        # Euclidean norm of the nodal forces and moments at lambda = 1 (the residual's scale)
        local = sum(float(f @ f) for _, f in self.forces) + sum(float(m @ m) for _, m, _ in self.moments)
        self.magnitude = float(np.sqrt(V.mesh.comm.allreduce(local, op=MPI.SUM)))

    def add(self, lam, x, R, K=None):
        """R -= lam f(x) (external forces) and K -= lam df/dx, on owned blocks of the carrier.

        R is the local array of the residual vector; K (a PETSc matrix in flush state) gets the
        load stiffness of the moments through local indices.
        """
        for i, f in self.forces:
            R[BS * i: BS * i + 3] -= lam * f
        for blocks, m, axis in self.moments:
            un = COMPONENTS.index("u_x" if axis == "x" else "v_y")
            wn = COMPONENTS.index("w_x" if axis == "x" else "w_y")
            for b, mb in zip(blocks, m):
                a1, a2 = 1.0 + x[BS * b + un], x[BS * b + wn]
                r2 = a1 * a1 + a2 * a2
                # theta = atan2(a2, a1): d theta = (a1 d a2 - a2 d a1) / r2
                R[BS * b + un] -= lam * mb * (-a2 / r2)
                R[BS * b + wn] -= lam * mb * (a1 / r2)
                if K is not None:
                    h11, h22, h12 = 2 * a1 * a2 / r2**2, -2 * a1 * a2 / r2**2, (a2 * a2 - a1 * a1) / r2**2
                    rows = np.array([BS * b + un, BS * b + wn], dtype=np.int32)
                    vals = -lam * mb * np.array([[h11, h12], [h12, h22]])
                    K.setValuesLocal(rows, rows, vals, addv=True)

