"""Named supports on the sides of the blank, as Dirichlet conditions on carrier components.

On a side with in-plane normal n and tangent s (left/right: n = x; bottom/top: n = y):

    simply_supported  w = 0, w,s = 0 (w vanishes along the side), u_s = 0 (shell diaphragm)
    clamped           w = 0, w,x = w,y = 0, u = v = 0
    symmetry          w,n = 0, u_n = 0
    free              nothing

Components that the active effects do not carry (u, v without membrane) are skipped.
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


def boundary_conditions(V, components, facet_tags, supports) -> list[fem.DirichletBC]:
    """Homogeneous Dirichlet conditions for the supports {side: name} on the carrier V."""
    fdim = facet_tags.dim
    dofs: dict[str, list[np.ndarray]] = {}
    for side, support in supports.items():
        facets = facet_tags.find(SIDE_TAG[side])
        for comp in fixed_components(support, side):
            if comp in components:
                sub = V.sub(components.index(comp))
                dofs.setdefault(comp, []).append(fem.locate_dofs_topological(sub, fdim, facets))
    bcs = []
    for comp, parts in dofs.items():
        sub = V.sub(components.index(comp))
        bcs.append(fem.dirichletbc(np.float64(0), np.unique(np.concatenate(parts)).astype(np.int32), sub))
    return bcs
