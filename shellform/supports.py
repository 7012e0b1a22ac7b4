"""Named supports on the edges of the blank, as Dirichlet conditions on carrier components.

This is the route of edges along x or y, where n and s are the axes themselves: every edge of a
rectangle, the symmetry lines of a circle or polygon. (Curved and oblique edges of the linear
plate and shell turn their DOFs into the edge's frame: shellform.edge_frames.)
On an edge with in-plane normal n and tangent s (left/right: n = x; bottom/top: n = y):

    simply_supported  w = 0, w,s = 0 (w vanishes along the side), u_s = 0 (shell diaphragm)
    clamped           w = 0, w,x = w,y = 0, u = v = 0
    symmetry          w,n = 0, u_n = 0
    free              nothing

Components that the active effects do not carry (u, v without membrane) are skipped.

The nonlinear sheet carries U = (u, v, w) and its gradient (shellform.assembly.sheet_element);
a value fixed along a side fixes its derivative along the side too:

    simply_supported  w, u_s and their derivatives along the side (a diaphragm; u_n free)
    clamped           u, v, w and their derivatives along the side, and w,n
    clamped_sliding   as clamped, but free to slide along the side (u_s free): Levy's clamped plate
    symmetry          u_n and its derivative along the side, w,n and u_s,n
"""

import numpy as np
from dolfinx import fem

from mpi4py import MPI

from shellform.edge_frames import SheetEdgeFrames, facet_normals
from shellform.errors import InputError

_FIXED = {  # support -> components fixed, in terms of the side's normal (n) and tangent (s)
    "simply_supported": ("w", "w,s", "u_s"),
    "clamped": ("w", "w,n", "w,s", "u_n", "u_s"),
    "symmetry": ("w,n", "u_n"),
    "free": (),
}


def _component(role: str, normal: str) -> str:
    tangent = "y" if normal == "x" else "x"
    return {
        "w": "w", "w,n": f"w_{normal}", "w,s": f"w_{tangent}",
        "u_n": "u" if normal == "x" else "v", "u_s": "v" if normal == "x" else "u",
    }[role]


def fixed_components(support: str, normal: str) -> tuple[str, ...]:
    return tuple(_component(r, normal) for r in _FIXED[support])


_SHEET_FIXED = {  # roles: displacement (u_n, u_s, w) with a derivative suffix ",n" or ",s"
    "simply_supported": ("w", "w,s", "u_s", "u_s,s"),
    "clamped": ("u_n", "u_n,s", "u_s", "u_s,s", "w", "w,s", "w,n"),
    "clamped_sliding": ("u_n", "u_n,s", "w", "w,s", "w,n"),
    "symmetry": ("u_n", "u_n,s", "w,n", "u_s,n"),
    "free": (),
}


def sheet_fixed_components(support: str, normal: str) -> tuple[str, ...]:
    """The nonlinear sheet's carrier components fixed by a support on an edge of that normal axis."""
    tangent = "y" if normal == "x" else "x"
    name = {"u_n": "u" if normal == "x" else "v", "u_s": "v" if normal == "x" else "u", "w": "w"}
    out = []
    for role in _SHEET_FIXED[support]:
        base, _, d = role.partition(",")
        out.append(name[base] if not d else f"{name[base]}_{normal if d == 'n' else tangent}")
    return tuple(out)


def edge_axis(blank, group: str, tol: float = 1e-9) -> str | None:
    """'x' or 'y': the axis every facet normal of a boundary group lies along (on all ranks);
    None for a curved or oblique edge."""
    _, _, n = facet_normals(blank, blank.facets(group))
    along = (bool(np.all(np.abs(n[:, 1]) <= tol)), bool(np.all(np.abs(n[:, 0]) <= tol)))
    along = tuple(blank.mesh.comm.allreduce(int(a), op=MPI.MIN) > 0 for a in along)
    return "x" if along[0] else "y" if along[1] else None


def split_by_direction(blank, supports) -> tuple[dict[str, str], dict[str, str]]:
    """The nonlinear sheet's supports: ({group: support} on edges along x or y, {group: support}
    on curved or oblique edges, held in their frames: shellform.edge_frames.SheetEdgeFrames);
    a support those frames do not hold on a curved or oblique edge is an InputError."""
    straight, curved = {}, {}
    for group, support in supports.items():
        if support == "free":
            continue
        if edge_axis(blank, group) is not None:
            straight[group] = support
        elif support in SheetEdgeFrames.ROLES:
            curved[group] = support
        else:
            raise InputError(f"supports.{group}", f"this edge is curved or oblique: the nonlinear sheet holds such "
                             f"an edge {', '.join(map(repr, SheetEdgeFrames.ROLES))} (in its frame), got {support!r}"
                             + (" (a symmetry line is straight)" if support == "symmetry" else ""))
    return straight, curved


def boundary_conditions(V, components, blank, supports, fixed=fixed_components) -> list[fem.DirichletBC]:
    """Homogeneous Dirichlet conditions for the supports {group: name} of a BlankMesh on the carrier V."""
    fdim = blank.facet_tags.dim
    dofs: dict[str, list[np.ndarray]] = {}
    for group, support in supports.items():
        if support == "free":
            continue
        facets = blank.facets(group)
        axis = edge_axis(blank, group)
        if axis is None:
            raise InputError(f"supports.{group}", "this edge is curved or oblique: its support needs the edge's "
                             "frame (shellform.edge_frames), which the contact driver does not take")
        for comp in fixed(support, axis):
            if comp in components:
                sub = V.sub(components.index(comp))
                dofs.setdefault(comp, []).append(fem.locate_dofs_topological(sub, fdim, facets))
    bcs = []
    for comp, parts in dofs.items():
        sub = V.sub(components.index(comp))
        bcs.append(fem.dirichletbc(np.float64(0), np.unique(np.concatenate(parts)).astype(np.int32), sub))
    return bcs
