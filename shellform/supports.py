"""Named supports on the sides of the blank, as Dirichlet conditions on carrier components.

On a side with in-plane normal n and tangent s (left/right: n = x; bottom/top: n = y):

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

from shellform.mesh import SIDE_TAG

NORMAL = {"left": "x", "right": "x", "bottom": "y", "top": "y"}

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


def fixed_components(support: str, side: str) -> tuple[str, ...]:
    return tuple(_component(r, NORMAL[side]) for r in _FIXED[support])


_SHEET_FIXED = {  # roles: displacement (u_n, u_s, w) with a derivative suffix ",n" or ",s"
    "simply_supported": ("w", "w,s", "u_s", "u_s,s"),
    "clamped": ("u_n", "u_n,s", "u_s", "u_s,s", "w", "w,s", "w,n"),
    "clamped_sliding": ("u_n", "u_n,s", "w", "w,s", "w,n"),
    "symmetry": ("u_n", "u_n,s", "w,n", "u_s,n"),
    "free": (),
}


def sheet_fixed_components(support: str, side: str) -> tuple[str, ...]:
    """The nonlinear sheet's carrier components fixed by a support on a side."""
    normal = NORMAL[side]
    tangent = "y" if normal == "x" else "x"
    name = {"u_n": "u" if normal == "x" else "v", "u_s": "v" if normal == "x" else "u", "w": "w"}
    out = []
    for role in _SHEET_FIXED[support]:
        base, _, d = role.partition(",")
        out.append(name[base] if not d else f"{name[base]}_{normal if d == 'n' else tangent}")
    return tuple(out)


def boundary_conditions(V, components, facet_tags, supports, fixed=fixed_components) -> list[fem.DirichletBC]:
    """Homogeneous Dirichlet conditions for the supports {side: name} on the carrier V."""
    fdim = facet_tags.dim
    dofs: dict[str, list[np.ndarray]] = {}
    for side, support in supports.items():
        facets = facet_tags.find(SIDE_TAG[side])
        for comp in fixed(support, side):
            if comp in components:
                sub = V.sub(components.index(comp))
                dofs.setdefault(comp, []).append(fem.locate_dofs_topological(sub, fdim, facets))
    bcs = []
    for comp, parts in dofs.items():
        sub = V.sub(components.index(comp))
        bcs.append(fem.dirichletbc(np.float64(0), np.unique(np.concatenate(parts)).astype(np.int32), sub))
    return bcs
