"""The reference element of the hybrid functional and the carrier that holds the unknowns.

Carrier: a blocked P1 space on the mesh, one block per vertex with the physical nodal values,

    membrane + bending: (u, v, w, w_x, w_y)      bending only: (w, w_x, w_y)
    with cubic_membrane: (u, v, u_x, u_y, v_x, v_y, w, w_x, w_y)

DOLFINx owns its dofmap, ghosts, boundary conditions and output unchanged.

Reference element (one triangle, fields of forms.fields.HybridFields), a basix mixed element:

    nodal (q):   u  P1 vector       [membrane]  (cubic_membrane: the reduced cubic, as w)
                 w  reduced cubic   [bending]
                 g  P1 vector       [bending]  the string-net normal slope carrier
    local:       eps_p              assumed membrane strain (DG0 symmetric tensor)
                 eps_b              assumed curvature (DG1 symmetric tensor)
                 N, M               their multipliers (same spaces, same order)

The assumed membrane strain is constant, the space of sym grad u for the P1 in-plane
displacement: the curvature-coupled part w kappa0 of f^p enters through its cell mean only, so
that the in-plane displacement can balance it and the element does not lock in membrane when
membrane and bending couple (docs/locking.md). On a flat shell the two choices are the same.
With the effect cubic_membrane the in-plane displacement is the reduced cubic (u, v and their
gradients at the vertices) and the assumed membrane strain quadratic (DG2), which holds sym grad u
of every cubic: no deformation mode is left without stiffness, and the panel bends in plane
(docs/locking.md).

The same fields also come as three mixed elements of their own, ``nodal`` (u, w, g), ``strains``
(eps_p, eps_b) and ``multipliers`` (N, M), in which the condensation's blocks are separate
forms (shellform.assembly.kernels); their dofs are in the order of q, eps and lam above.

The map carrier -> q is linear with per-cell coefficients (identity or entries of J), at most
two nonzeros per reference row; it is tabulated here as index tables for shellform.assembly.slope_map.
"""

from dataclasses import dataclass, field

import basix.ufl
import numpy as np

from shellform import effects as registry
from shellform.assembly import slope_map
from shellform.elements import reduced_cubic

GROUPS = tuple(e.name for e in registry.EFFECTS.values() if e.kind == "form term")  # order of the local fields
STRAIN_COMPONENTS = ("xx", "yy", "xy")


@dataclass
class HybridElement:
    effects: tuple[str, ...]
    carrier_components: tuple[str, ...] = field(init=False)
    mixed: basix.ufl._ElementBase = field(init=False)
    sub_names: tuple[str, ...] = field(init=False)
    offsets: dict[str, slice] = field(init=False)

    def __post_init__(self):
        self.effects = registry.canonical(self.effects)
        has_m, has_b = "membrane" in self.effects, "bending" in self.effects
        if not (has_m or has_b):
            raise ValueError("a hybrid element needs the membrane or the bending effect")
        self.cubic_membrane = "cubic_membrane" in self.effects
        if self.cubic_membrane and not has_m:
            raise ValueError("cubic_membrane needs the membrane effect")
        cell = "triangle"
        p1v = basix.ufl.element("Lagrange", cell, 1, shape=(2,))
        self.strain_degrees = {"membrane": 2 if self.cubic_membrane else 0, "bending": 1}
        space = {gr: basix.ufl.element("DG", cell, k, shape=(2, 2), symmetry=True)
                 for gr, k in self.strain_degrees.items()}
        subs: list[tuple[str, basix.ufl._ElementBase]] = []
        comps: list[str] = []
        if has_m and self.cubic_membrane:
            subs.append(("u", basix.ufl.blocked_element(reduced_cubic.element(), shape=(2,))))
            comps += ["u", "v", "u_x", "u_y", "v_x", "v_y"]
        elif has_m:
            subs.append(("u", p1v))
            comps += ["u", "v"]
        if has_b:
            subs += [("w", reduced_cubic.element()), ("g", p1v)]
            comps += ["w", "w_x", "w_y"]
        self.groups = tuple(gr for gr in GROUPS if gr in self.effects)  # the form-term effects, in order
        strain_name = {"membrane": "eps_p", "bending": "eps_b"}
        mult_name = {"membrane": "N", "bending": "M"}
        subs += [(strain_name[gr], space[gr]) for gr in self.groups]
        subs += [(mult_name[gr], space[gr]) for gr in self.groups]
        self.carrier_components = tuple(comps)
        self.sub_names = tuple(n for n, _ in subs)
        self.mixed = basix.ufl.mixed_element([e for _, e in subs])
        nodal = [(n, e) for n, e in subs if n in ("u", "w", "g")]
        self.parts = {"nodal": nodal, "strains": [(strain_name[gr], space[gr]) for gr in self.groups],
                      "multipliers": [(mult_name[gr], space[gr]) for gr in self.groups]}
        self.offsets, start = {}, 0
        for name, e in subs:
            self.offsets[name] = slice(start, start + e.dim)
            start += e.dim
        nodal = [n for n in ("u", "w", "g") if n in self.offsets]
        self.q = np.concatenate([np.arange(self.offsets[n].start, self.offsets[n].stop) for n in nodal])
        self.eps = np.concatenate([self._range(strain_name[gr]) for gr in self.groups])
        self.lam = np.concatenate([self._range(mult_name[gr]) for gr in self.groups])
        self.strain_dims = tuple(space[gr].dim for gr in self.groups)  # eps dofs per group

    def part(self, kind: str):
        """(names, element) of the nodal, strain or multiplier fields alone."""
        names, elements = zip(*self.parts[kind])
        return names, basix.ufl.mixed_element(list(elements))

    def _range(self, name):
        s = self.offsets[name]
        return np.arange(s.start, s.stop)

    @property
    def block_size(self) -> int:
        return len(self.carrier_components)

    @property
    def dim(self) -> int:
        return self.mixed.dim

    @property
    def carrier_dim(self) -> int:
        return 3 * self.block_size

    def component(self, name: str) -> int:
        return self.carrier_components.index(name)

    def slope_map_tables(self) -> tuple[np.ndarray, np.ndarray]:
        """Per reference row of q: up to two (carrier column, coefficient code) pairs.

        Coefficient codes: 0 -> none, 1 -> 1.0, 2 + 2a + b -> J[a, b] (a, b in {0, 1}), where
        J[a, b] = dx_a/dX_b. Reference slope dw/dX_i = sum_j J[j, i] dw/dx_j (slopes = J^T grad).
        """
        nq, bs = len(self.q), self.block_size
        cols = -np.ones((nq, 2), dtype=np.int32)
        codes = np.zeros((nq, 2), dtype=np.int32)
        row = {r: k for k, r in enumerate(self.q)}
        for v in range(3):
            if "u" in self.offsets and self.cubic_membrane:
                for c, name in enumerate("uv"):  # blocked reduced cubic: dof 2 j + c, j = 3 v + k
                    rows = [row[self.offsets["u"].start + 2 * (3 * v + k) + c] for k in range(3)]
                    slope_map.cubic_vertex_rows(cols, codes, rows, bs * v + self.component(name),
                                                [bs * v + self.component(f"{name}_{x}") for x in "xy"])
            elif "u" in self.offsets:
                for i in range(2):  # blocked P1: node-major, component-minor
                    r = row[self.offsets["u"].start + 2 * v + i]
                    cols[r, 0], codes[r, 0] = bs * v + self.component("u") + i, 1
            if "w" in self.offsets:
                rows = [row[self.offsets["w"].start + 3 * v + k] for k in range(3)]
                slope_map.cubic_vertex_rows(cols, codes, rows, bs * v + self.component("w"),
                                            [bs * v + self.component("w_x") + j for j in range(2)])
                for i in range(2):
                    r = row[self.offsets["g"].start + 2 * v + i]
                    cols[r, 0], codes[r, 0] = bs * v + self.component("w_x") + i, 1
        return cols, codes

    def centroid_average(self) -> np.ndarray:
        """(3 groups, eps dofs): centroid value (xx, yy, xy) of each group's assumed strain.

        basix.ufl blocks a symmetric 2x2 tensor as (xx, xy, yy), node-major; the weights of the
        nodes are the scalar DG basis functions at the centroid.
        """
        avg = np.zeros((3 * len(self.groups), sum(self.strain_dims)))
        centroid = np.array([[1.0 / 3.0, 1.0 / 3.0]])
        start = 0
        for g, (gr, dim) in enumerate(zip(self.groups, self.strain_dims)):
            scalar = basix.ufl.element("DG", "triangle", self.strain_degrees[gr])
            phi = scalar.tabulate(0, centroid)[0, 0]  # (nodes,)
            for out, comp in enumerate((0, 2, 1)):  # xx, yy, xy
                avg[3 * g + out, start + comp:start + dim:3] = phi
            start += dim
        return avg
