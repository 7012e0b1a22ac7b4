"""FFCx kernels of the UFL functional, wrapped as DOLFINx forms on the carrier space.

The second variation of pi_g splits into blocks between the nodal values q, the assumed strains
eps and the multipliers lam (shellform.assembly.condensation). Each block the condensation needs
is its own FFCx form, on the fields it couples (HybridElement.part):

    C = d2 pi / d lam d q     per cell: cell integral + the string-net integrals on its 3 facets
    G = -d2 pi / d lam d eps, H = d2 pi / d eps2     once per mesh, on the reference triangle

For every owned cell the wrapper kernel (a numba cfunc with the UFCx signature) tabulates C,
condenses (K = C^T X C / |det J|, X from G and H) and pulls the result back to the physical
carrier values with T(J) (slope_map). DOLFINx then assembles, applies boundary conditions and
lifts as for any form, in serial or MPI.

The cfuncs are compiled at every start (they hold the addresses of this process's FFCx
kernels); the numerical work they call is cached by numba. FFCx compiles at -O3 for this CPU.
"""

from dataclasses import dataclass
from functools import cached_property

import basix.ufl
import numba
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import IntegralType, form_cpp_class
from dolfinx.mesh import CellType
from dolfinx.jit import ffcx_jit
from ufl.algorithms import expand_derivatives

from shellform.forms import functional
from shellform.forms.fields import HybridFields, ShellParameters
from shellform.forms.loads import PressureField
from shellform.forms.reference_surface import ReferenceSurface
from shellform.assembly import condensation, slope_map
from shellform.assembly.hybrid_element import HybridElement
from shellform.errors import InputError
from shellform import _jit as jit

try:  # the module moves in FFCx 0.12
    from ffcx.codegeneration.utils import numba_ufcx_kernel_signature
except ImportError:  # pragma: no cover
    from ffcx.codegeneration.numba.utils import numba_ufcx_kernel_signature

JIT_OPTIONS = jit.FFCX_JIT_OPTIONS  # -O3 for this CPU, in a cache of its own (shellform._jit)
_signature = numba_ufcx_kernel_signature(np.float64, np.float64)


def reference_fields(element: HybridElement, z) -> HybridFields:
    """The fields of one coefficient on the whole mixed element (the sheet's weak Hessian)."""
    parts = dict(zip(element.sub_names, ufl.split(z)))
    return HybridFields(**{k: parts.get(k) for k in ("u", "w", "g", "eps_p", "eps_b", "N", "M")})


def part_fields(element: HybridElement, domain) -> tuple[dict, HybridFields]:
    """One coefficient each on the nodal, strain and multiplier elements, and the fields of
    forms.fields split from them."""
    coefficients, parts = {}, {}
    for kind in ("nodal", "strains", "multipliers"):
        names, el = element.part(kind)
        z = ufl.Coefficient(ufl.FunctionSpace(domain, el))
        coefficients[kind] = z
        parts.update(zip(names, ufl.split(z)))
    return coefficients, HybridFields(**{k: parts.get(k) for k in ("u", "w", "g", "eps_p", "eps_b", "N", "M")})


def second_variation(pi, a, b) -> ufl.Form:
    """d2 pi / da db: test functions on a's element (rows), trial functions on b's (columns)."""
    return ufl.derivative(ufl.derivative(pi, a, ufl.TestFunction(a.ufl_function_space())), b,
                          ufl.TrialFunction(b.ufl_function_space()))


@dataclass
class CompiledForm:
    """One FFCx-compiled UFL form: its cell and exterior-facet kernels and constant layout."""

    cell: object
    facet: object | None
    constants: list
    num_coefficients: int

    @classmethod
    def compile(cls, comm, form: ufl.Form):
        ufcx, _, _ = ffcx_jit(comm, form, form_compiler_options={"scalar_type": "float64"}, jit_options=JIT_OPTIONS)
        off = [ufcx.form_integral_offsets[i] for i in range(3)]
        kern = lambda i: ufcx.form_integrals[i].tabulate_tensor_float64  # noqa: E731
        cell = kern(off[0]) if off[1] > off[0] else None
        facet = kern(off[1]) if off[2] > off[1] else None
        if ufcx.num_constants != len(form.constants()):
            raise RuntimeError("FFCx and UFL disagree on the constants of a form")
        return cls(cell, facet, list(form.constants()), ufcx.num_coefficients)

    def gather(self, layout: dict) -> np.ndarray:
        """Indices into the wrapper's packed constants, in this kernel's constant order."""
        idx = [np.arange(layout[id(c)][0], layout[id(c)][1]) for c in self.constants]
        return np.concatenate(idx).astype(np.int64) if idx else np.zeros(0, dtype=np.int64)


_PARAMETERS = ("E", "nu", "thickness", "kappa0", "pressure", "pressure_field")


def _signature_of(params: ShellParameters) -> tuple:
    """Which parameters are present and their shapes: what the compiled kernels depend on."""
    sig = []
    for name in _PARAMETERS:
        c = getattr(params, name)
        if isinstance(c, ReferenceSurface | PressureField):  # kappa0 = -grad grad z0, p's field: compiled in
            sig.append((name, c))
        elif c is not None:
            sig.append((name, tuple(c.ufl_shape)))
    return tuple(sig)


class ElementKernels:
    """The cfuncs of one element configuration, compiled once and shared by every mesh.

    FFCx kernels depend on the reference cell and the coordinate element only, not on a mesh;
    the UFL forms are therefore built on a mesh-free domain with placeholder constants. The
    wrapper forms' constants are the parameters (in _PARAMETERS order) followed by the mesh's
    condensation operators (``operators``).
    """

    _cache: dict = {}

    @classmethod
    def get(cls, element: HybridElement, params: ShellParameters, mapped: bool, comm):
        key = (element.effects, _signature_of(params), mapped)
        if key not in cls._cache:
            cls._cache[key] = cls(element, key[1], mapped, comm)
        return cls._cache[key]

    def __init__(self, element: HybridElement, param_signature, mapped, comm):
        self.element, self.mapped = element, mapped
        domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
        placeholders = {name: ufl.Constant(domain, shape=shape) for name, shape in param_signature
                        if not isinstance(shape, ReferenceSurface | PressureField)}
        x = ufl.SpatialCoordinate(domain)
        surfaces = {name: s.kappa0(x) if isinstance(s, ReferenceSurface) else s for name, s in param_signature
                    if isinstance(s, ReferenceSurface | PressureField)}
        params = ShellParameters(**{n: placeholders.get(n, surfaces.get(n)) for n in _PARAMETERS})
        z, fields = part_fields(element, domain)
        n = ufl.FacetNormal(domain)
        pi = functional.hybrid_functional(fields, params, element.effects, n)
        q, eps, lam = z["nodal"], z["strains"], z["multipliers"]
        if not expand_derivatives(second_variation(pi, q, q)).empty():
            raise NotImplementedError("the condensation assumes pi_g couples the nodal values only to the "
                                      "multipliers (no nodal-nodal block)")
        self._C = CompiledForm.compile(comm, second_variation(pi, lam, q))
        self._G = CompiledForm.compile(comm, -second_variation(pi, lam, eps))
        self._H = CompiledForm.compile(comm, second_variation(pi, eps, eps))
        work = functional.external_work(fields, params, element.effects)
        self._L = None
        if work:
            self._L = CompiledForm.compile(comm, ufl.derivative(work, q, ufl.TestFunction(q.ufl_function_space())))
        for f in (self._C, self._G, self._H, self._L):
            if f is not None and f.num_coefficients:
                raise NotImplementedError("state-dependent forms need the nonlinear driver")
        # Packed constants of the wrapper forms: every parameter, in _PARAMETERS order.
        self.constant_names = list(placeholders)
        layout, start = {}, 0
        for name, shape in ((n, s) for n, s in param_signature if n in placeholders):
            size = int(np.prod(shape)) if shape else 1
            layout[id(placeholders[name])] = (start, start + size)
            start += size
        self._nparams = start
        self._layout = layout
        self.ne, self.nq = len(element.lam), len(element.q)
        self._nconst = start + 3 * self.ne * self.ne  # the wrappers' constants: parameters, then operators
        self.matrix = self._matrix_kernel()
        self.vector = self._vector_kernel() if self._L else None

    # -- per mesh ---------------------------------------------------------------------------
    def operators(self, parameters: np.ndarray) -> np.ndarray:
        """The condensation operators (L, G^-1, G^-1 H) of the reference triangle for these
        parameter values, flattened (the wrappers' last constant).

        They hold on every affine cell once scaled by |det J|; that is checked here on a sheared
        cell, so that a form whose assumed-strain blocks depend on the cell's shape or position
        is refused instead of condensed wrongly.
        """
        scaled = []
        for coords in (_REFERENCE, _SHEARED):
            det = abs(slope_map.determinant(slope_map.jacobian(coords)))
            _, G, H = self.blocks(parameters, coords)
            scaled.append((G / det, H / det))
        (G, H), (G2, H2) = scaled
        for X, X2, name in ((G, G2, "G"), (H, H2, "H")):
            if not np.allclose(X, X2, rtol=1e-10, atol=1e-12 * np.abs(X).max()):
                raise NotImplementedError(f"the assumed-strain block {name} of this functional does not scale with "
                                          "the cell's area; the condensation needs it to")
        return np.concatenate([M.ravel() for M in condensation.reference_operators(G, H)])

    def blocks(self, parameters: np.ndarray, coords: np.ndarray):
        """(C, G, H) of one cell (coordinate dofs, 3 x 3 flattened) for these parameter values."""
        ne, nq = self.ne, self.nq
        return tuple(tabulate(f, parameters[f.gather(self._layout)], coords, shape)
                     for f, shape in ((self._C, (ne, nq)), (self._G, (ne, ne)), (self._H, (ne, ne))))

    # -- cfuncs -------------------------------------------------------------------------------
    # Each cfunc binds this configuration's kernel addresses and tables and calls a cached numba
    # function with them, so that only the thin cfunc is compiled in every process.
    def _bound(self):
        e, C = self.element, self._C
        cols, codes = e.slope_map_tables()
        return (_address(C.cell), _address(C.facet), C.gather(self._layout), cols, codes, self.mapped,
                self._nparams, self.ne, self.nq)

    def _matrix_kernel(self):
        bound = self._bound()
        nc, nconst = self.element.carrier_dim, self._nconst

        @numba.cfunc(_signature, nopython=True)
        def kernel(A_, w_, c_, coords_, local, perm, data):
            condensed_matrix(*bound, numba.carray(c_, (nconst,)), numba.carray(coords_, (9,)),
                             numba.carray(A_, (nc, nc)))

        return kernel

    def _vector_kernel(self):
        # a tuple, so that numba types the values as such (captured one by one they would be
        # literals, and the cached function would be compiled again in every process)
        bound = (_address(self._L.cell), self._L.gather(self._layout), *self.element.slope_map_tables(),
                 self.mapped, self.nq)
        nc, nconst = self.element.carrier_dim, self._nconst

        @numba.cfunc(_signature, nopython=True)
        def kernel(b_, w_, c_, coords_, local, perm, data):
            load_vector(*bound, numba.carray(c_, (nconst,)), numba.carray(coords_, (9,)), numba.carray(b_, (nc,)))

        return kernel

    @cached_property
    def recovery(self):
        """Centroid values of the assumed strains eps = G^-1 C q and the multipliers
        lam = G^-1 H eps, per group (xx, yy, xy of each); compiled when first asked for."""
        bound = self._bound()
        e = self.element
        nc, nconst, ngroups = e.carrier_dim, self._nconst, len(e.groups)
        avg = e.centroid_average()

        @numba.cfunc(_signature, nopython=True)
        def kernel(b_, w_, c_, coords_, local, perm, data):
            recovered(*bound, avg, numba.carray(c_, (nconst,)), numba.carray(coords_, (9,)),
                      numba.carray(w_, (nc,)), numba.carray(b_, (6 * ngroups,)))

        return kernel


# -- the cell work of the cfuncs (cached: the kernels come in as addresses) ----------------------
@jit.njit
def gathered(gather, c):
    """A kernel's own constants from the wrappers' packed ones."""
    ck = np.zeros(max(gather.size, 1))
    for i in range(gather.size):
        ck[i] = c[gather[i]]
    return ck


@jit.njit
def element_tensor(cell, facet, ck, coords, A):
    """A += the cell integral and the facet integrals on the cell's three facets, the element's
    own boundary where the string-net terms live (address 0: the form has no such integral)."""
    wz = np.zeros(1)
    local = np.zeros(1, dtype=np.int32)
    perm = np.zeros(1, dtype=np.uint8)
    if cell != 0:
        jit.call_kernel(cell, A, wz, ck, coords, local, perm)
    if facet != 0:
        for f in range(3):
            local[0] = f
            jit.call_kernel(facet, A, wz, ck, coords, local, perm)


@jit.njit
def constraint(cell, facet, gather, ne, nq, c, coords):
    """C (ne x nq) of one cell (a flat plate's C has no cell part, a membrane's no facet part)."""
    C = np.zeros((ne, nq))
    element_tensor(cell, facet, gathered(gather, c), coords, C)
    return C


@jit.njit
def condensed_matrix(cell, facet, gather, cols, codes, mapped, npar, ne, nq, c, coords, A):
    """The condensed, mapped element matrix A (carrier values) of one cell."""
    C = constraint(cell, facet, gather, ne, nq, c, coords)
    J = slope_map.jacobian(coords)
    coef = slope_map.coefficients(J, codes, mapped)
    L = c[npar: npar + ne * ne].reshape((ne, ne))
    condensation.scaled_condensed_matrix(C, L, abs(slope_map.determinant(J)), cols, coef, A)


@jit.njit
def load_vector(cell, gather, cols, codes, mapped, nq, c, coords, b):
    """b = T^T b_ref: the loads act on the nodal fields only (no condensation)."""
    b_ref = np.zeros(nq)
    element_tensor(cell, 0, gathered(gather, c), coords, b_ref)
    coef = slope_map.coefficients(slope_map.jacobian(coords), codes, mapped)
    b[:] = 0.0
    slope_map.pull_back_vector(b_ref, cols, coef, b)


@jit.njit
def recovered(cell, facet, gather, cols, codes, mapped, npar, ne, nq, avg, c, coords, q, out):
    """Centroid (xx, yy, xy) of eps = G^-1 C T q / |det J| and lam = G^-1 H eps, per group."""
    J = slope_map.jacobian(coords)
    coef = slope_map.coefficients(J, codes, mapped)
    q_ref = np.empty(nq)
    slope_map.push_forward(q, cols, coef, q_ref)
    Cq = np.zeros(ne)
    C = constraint(cell, facet, gather, ne, nq, c, coords)
    for i in range(ne):
        for j in range(nq):
            Cq[i] += C[i, j] * q_ref[j]
    s = 1.0 / abs(slope_map.determinant(J))
    Ginv = c[npar + ne * ne: npar + 2 * ne * ne].reshape((ne, ne))
    R = c[npar + 2 * ne * ne: npar + 3 * ne * ne].reshape((ne, ne))
    eps, lam = np.zeros(ne), np.zeros(ne)
    for i in range(ne):
        for j in range(ne):
            eps[i] += Ginv[i, j] * Cq[j] * s
    for i in range(ne):
        for j in range(ne):
            lam[i] += R[i, j] * eps[j]
    for g in range(avg.shape[0] // 3):
        for k in range(3):
            a, r = 0.0, 0.0
            for j in range(ne):
                a += avg[3 * g + k, j] * eps[j]
                r += avg[3 * g + k, j] * lam[j]
            out[6 * g + k] = a
            out[6 * g + 3 + k] = r


_REFERENCE = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
_SHEARED = np.array([0.3, -0.2, 0.0, 2.1, 0.4, 0.0, -0.5, 1.6, 0.0])


def _address(kernel) -> int:
    """A kernel's address for the cached cell work (0: the form has no such integral)."""
    return jit.kernel_address(kernel) if kernel is not None else 0


def tabulate(form: CompiledForm, ck: np.ndarray, coords: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The element matrix of `form` on one cell (constants ck in the form's own order)."""
    A = np.zeros(shape)
    element_tensor(_address(form.cell), _address(form.facet), np.ascontiguousarray(ck, dtype=np.float64)
                   if ck.size else np.zeros(1), np.ascontiguousarray(coords, dtype=np.float64), A)
    return A


def check_mesh(mesh) -> None:
    """The element needs a 2D mesh of affine triangles (the blank plane)."""
    cell = mesh.topology.cell_type
    if mesh.topology.dim != 2 or cell != CellType.triangle:
        raise InputError("mesh", f"shellform needs a 2D mesh of triangles, got {cell.name} cells "
                         f"of dimension {mesh.topology.dim}")
    if mesh.geometry.cmaps[0].degree != 1:
        raise InputError("mesh", f"shellform needs affine (degree 1) triangles, got degree {mesh.geometry.cmaps[0].degree}")


class HybridShellForms:
    """Stiffness, load and recovery forms of the hybrid shell element on one mesh.

    The parameters' values are read here, for the condensation operators: forms built before
    a parameter changes keep the old operators.
    """

    def __init__(self, mesh, element: HybridElement, params: ShellParameters, mapped: bool = True):
        check_mesh(mesh)
        self.mesh, self.element, self.params, self.mapped = mesh, element, params, mapped
        self.kernels = ElementKernels.get(element, params, mapped, mesh.comm)
        self.constants = [getattr(params, name) for name in self.kernels.constant_names]
        values = [np.atleast_1d(np.asarray(c.value, dtype=np.float64)).ravel() for c in self.constants]
        ops = self.kernels.operators(np.concatenate(values) if values else np.zeros(0))
        self.constants.append(fem.Constant(mesh, ops))
        self.V = fem.functionspace(mesh, ("Lagrange", 1, (element.block_size,)))
        self.cells = np.arange(mesh.topology.index_map(mesh.topology.dim).size_local, dtype=np.int32)
        self.stiffness = self._form([self.V, self.V], self.kernels.matrix, [])
        self.load = self._form([self.V], self.kernels.vector, []) if self.kernels.vector else None

    def _form(self, spaces, kernel, coefficients):
        coeff_idx = np.arange(len(coefficients), dtype=np.int8)
        integrals = {IntegralType.cell: [(0, kernel.address, self.cells, coeff_idx)]}
        cpp = form_cpp_class(np.float64)(
            [V._cpp_object for V in spaces], integrals, [c._cpp_object for c in coefficients],
            [c._cpp_object for c in self.constants], False, [], mesh=self.mesh._cpp_object,
        )
        return fem.Form(cpp)

    def recovery_form(self, q: fem.Function, W: fem.FunctionSpace):
        """Vector form on a DG0 space W (block 6 per group): centroid strains and resultants."""
        return self._form([W], self.kernels.recovery, [q])

    @property
    def num_dofs(self) -> int:
        """Global number of carrier unknowns (vertices x components)."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs
