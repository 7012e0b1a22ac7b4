"""Point loads on vertex values of the carrier (uniform pressure is a UFL term: forms/loads.py)."""

import numpy as np
from mpi4py import MPI

from shellform.errors import InputError


def vertex_dof(V, x, y, tol) -> tuple[int, bool]:
    """Local block index of the carrier vertex at (x, y) owned by this rank (-1 if none), and
    whether any rank owns one."""
    coords = V.tabulate_dof_coordinates()
    owned = V.dofmap.index_map.size_local
    d = np.hypot(coords[:owned, 0] - x, coords[:owned, 1] - y)
    i = int(np.argmin(d)) if owned else -1
    here = i >= 0 and d[i] <= tol
    found = V.mesh.comm.allreduce(int(here), op=MPI.SUM) > 0
    return (i if here else -1), found


def add_point_loads(b, V, components, points, tol):
    """b[w, u, v at the vertex] += fz, fx, fy for each point load (the components the carrier
    has); the vertex must exist in the mesh."""
    if not points:
        return
    bs = len(components)
    array = b.getArray(readonly=False)
    for k, p in enumerate(points):
        i, found = vertex_dof(V, p.x, p.y, tol)
        if not found:
            raise InputError(f"loads.point[{k}]", f"no mesh vertex at ({p.x}, {p.y})")
        if i >= 0:
            for name, f in (("w", p.fz), ("u", p.fx), ("v", p.fy)):
                if f != 0.0:
                    array[bs * i + components.index(name)] += f


def value_at(u, components, name, x, y, tol) -> float:
    """A carrier component at the vertex (x, y), the same on every rank."""
    i, found = vertex_dof(u.function_space, x, y, tol)
    if not found:
        raise InputError("point", f"no mesh vertex at ({x}, {y})")
    v = u.x.array[len(components) * i + components.index(name)] if i >= 0 else 0.0
    return u.function_space.mesh.comm.allreduce(v if i >= 0 else 0.0, op=MPI.SUM) / max(
        1, u.function_space.mesh.comm.allreduce(int(i >= 0), op=MPI.SUM))
