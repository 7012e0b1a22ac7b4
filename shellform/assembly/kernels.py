"""FFCx kernels of the UFL functional, wrapped as DOLFINx forms on the carrier space.

For every owned cell the wrapper kernel (a numba cfunc with the UFCx signature)
  1. tabulates the second variation of pi_g on the mixed reference element: the FFCx cell
     kernel once and the FFCx ``ds`` kernel once per local facet (the element's own boundary,
     where the string-net terms live);
  2. condenses the assumed strains and multipliers (condensation.condensed_matrix);
  3. pulls the result back to the physical carrier values with T(J) (slope_map).
DOLFINx then assembles, applies boundary conditions and lifts as for any form, in serial or MPI.

The cfuncs are compiled at every start (they hold the addresses of this process's FFCx
kernels); the numerical work they call is cached by numba.
"""

from dataclasses import dataclass

import basix.ufl
import cffi
import numba
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import IntegralType, form_cpp_class
from dolfinx.mesh import CellType
from dolfinx.jit import ffcx_jit

from shellform.forms import functional
from shellform.forms.fields import HybridFields, ShellParameters
from shellform.assembly import condensation, slope_map
from shellform.assembly.hybrid_element import HybridElement
from shellform.errors import InputError

try:  # the module moves in FFCx 0.12
    from ffcx.codegeneration.utils import empty_void_pointer, numba_ufcx_kernel_signature
except ImportError:  # pragma: no cover
    from ffcx.codegeneration.numba.utils import empty_void_pointer, numba_ufcx_kernel_signature

_ffi = cffi.FFI()
_signature = numba_ufcx_kernel_signature(np.float64, np.float64)


def reference_fields(element: HybridElement, z) -> HybridFields:
    parts = dict(zip(element.sub_names, ufl.split(z)))
    return HybridFields(**{k: parts.get(k) for k in ("u", "w", "g", "eps_p", "eps_b", "N", "M")})


@dataclass
class CompiledForm:
    """One FFCx-compiled UFL form: its cell and exterior-facet kernels and constant layout."""

    cell: object
    facet: object | None
    constants: list
    num_coefficients: int

    @classmethod
    def compile(cls, comm, form: ufl.Form):
        ufcx, _, _ = ffcx_jit(comm, form, form_compiler_options={"scalar_type": "float64"})
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


_PARAMETERS = ("E", "nu", "thickness", "kappa0", "pressure")


def _signature_of(params: ShellParameters) -> tuple:
    """Which parameters are present and their shapes: what the compiled kernels depend on."""
    sig = []
    for name in _PARAMETERS:
        c = getattr(params, name)
        if c is not None:
            sig.append((name, tuple(c.ufl_shape)))
    return tuple(sig)


class ElementKernels:
    """The cfuncs of one element configuration, compiled once and shared by every mesh.

    FFCx kernels depend on the reference cell and the coordinate element only, not on a mesh;
    the UFL forms are therefore built on a mesh-free domain with placeholder constants.
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
        placeholders = {name: ufl.Constant(domain, shape=shape) for name, shape in param_signature}
        params = ShellParameters(**{n: placeholders.get(n) for n in _PARAMETERS})
        Z = ufl.FunctionSpace(domain, element.mixed)
        z = ufl.Coefficient(Z)
        dz, tz = ufl.TestFunction(Z), ufl.TrialFunction(Z)
        fields = reference_fields(element, z)
        n = ufl.FacetNormal(domain)
        pi = functional.hybrid_functional(fields, params, element.effects, n)
        self._a = CompiledForm.compile(comm, ufl.derivative(ufl.derivative(pi, z, dz), z, tz))
        work = functional.external_work(fields, params, element.effects)
        self._L = CompiledForm.compile(comm, ufl.derivative(work, z, dz)) if work else None
        for f in (self._a, self._L):
            if f is not None and f.num_coefficients:
                raise NotImplementedError("state-dependent forms need the nonlinear driver")
        # Packed constants of the wrapper forms: every parameter, in _PARAMETERS order.
        self.constant_names = [name for name, _ in param_signature]
        layout, start = {}, 0
        for name, shape in param_signature:
            size = int(np.prod(shape)) if shape else 1
            layout[id(placeholders[name])] = (start, start + size)
            start += size
        self._nconst = max(start, 1)
        self._layout = layout
        self.matrix = self._matrix_kernel()
        self.vector = self._vector_kernel() if self._L else None
        self.recovery = self._recovery_kernel()

    # -- cfuncs -------------------------------------------------------------------------------
    def _tabulate(self):
        """A numba function filling the mixed element matrix Az of one cell."""
        cell, facet = self._a.cell, self._a.facet
        gather, nconst, nz = self._a.gather(self._layout), self._nconst, self.element.dim
        ffi = _ffi
        nfacets = 3 if facet is not None else 0  # membrane alone has no string-net terms
        facet = facet if facet is not None else cell  # typed placeholder, never called

        @numba.njit
        def tabulate(c_, coords_, perm):
            c = numba.carray(c_, (nconst,))
            ck = np.zeros(max(gather.size, 1))
            for i in range(gather.size):
                ck[i] = c[gather[i]]
            Az = np.zeros((nz, nz))
            wz = np.zeros(1)
            local = np.zeros(1, dtype=np.int32)
            cell(ffi.from_buffer(Az), ffi.from_buffer(wz), ffi.from_buffer(ck), coords_,
                 ffi.from_buffer(local), perm, empty_void_pointer())
            for f in range(nfacets):  # the element's own boundary: the string-net integrals
                local[0] = f
                facet(ffi.from_buffer(Az), ffi.from_buffer(wz), ffi.from_buffer(ck), coords_,
                      ffi.from_buffer(local), perm, empty_void_pointer())
            return Az

        return tabulate

    def _matrix_kernel(self):
        tabulate = self._tabulate()
        e = self.element
        iq, ie, il = e.q, e.eps, e.lam
        cols, codes = e.slope_map_tables()
        nc, mapped = e.carrier_dim, self.mapped

        @numba.cfunc(_signature, nopython=True)
        def kernel(A_, w_, c_, coords_, local, perm, data):
            A = numba.carray(A_, (nc, nc))
            coords = numba.carray(coords_, (9,))
            K_ref = condensation.condensed_matrix(tabulate(c_, coords_, perm), iq, ie, il)
            coef = slope_map.coefficients(slope_map.jacobian(coords), codes, mapped)
            A[:, :] = 0.0
            slope_map.pull_back_matrix(K_ref, cols, coef, A)

        return kernel

    def _vector_kernel(self):
        cell = self._L.cell
        gather, nconst, nz = self._L.gather(self._layout), self._nconst, self.element.dim
        e = self.element
        iq = e.q
        cols, codes = e.slope_map_tables()
        nc, mapped = e.carrier_dim, self.mapped
        ffi = _ffi

        @numba.cfunc(_signature, nopython=True)
        def kernel(b_, w_, c_, coords_, local, perm, data):
            b = numba.carray(b_, (nc,))
            coords = numba.carray(coords_, (9,))
            c = numba.carray(c_, (nconst,))
            ck = np.zeros(max(gather.size, 1))
            for i in range(gather.size):
                ck[i] = c[gather[i]]
            bz = np.zeros(nz)
            wz = np.zeros(1)
            cell(ffi.from_buffer(bz), ffi.from_buffer(wz), ffi.from_buffer(ck), coords_, local,
                 perm, empty_void_pointer())
            b_ref = np.empty(iq.size)  # the loads act on nodal fields only: no condensation
            for i in range(iq.size):
                b_ref[i] = bz[iq[i]]
            coef = slope_map.coefficients(slope_map.jacobian(coords), codes, mapped)
            b[:] = 0.0
            slope_map.pull_back_vector(b_ref, cols, coef, b)

        return kernel

    def _recovery_kernel(self):
        tabulate = self._tabulate()
        e = self.element
        iq, ie, il = e.q, e.eps, e.lam
        cols, codes = e.slope_map_tables()
        nc, mapped, ngroups, ns = e.carrier_dim, self.mapped, len(e.groups), e.sym_dim
        avg = e.centroid_average()

        @numba.cfunc(_signature, nopython=True)
        def kernel(b_, w_, c_, coords_, local, perm, data):
            out = numba.carray(b_, (6 * ngroups,))
            q = numba.carray(w_, (nc,))
            coords = numba.carray(coords_, (9,))
            coef = slope_map.coefficients(slope_map.jacobian(coords), codes, mapped)
            q_ref = np.empty(iq.size)
            slope_map.push_forward(q, cols, coef, q_ref)
            eps, lam = condensation.recover(tabulate(c_, coords_, perm), iq, ie, il, q_ref)
            for g in range(ngroups):
                for k in range(3):
                    s, r = 0.0, 0.0
                    for j in range(ns):
                        s += avg[k, j] * eps[g * ns + j]
                        r += avg[k, j] * lam[g * ns + j]
                    out[6 * g + k] = s
                    out[6 * g + 3 + k] = r

        return kernel


def check_mesh(mesh) -> None:
    """The element needs a 2D mesh of affine triangles (the blank plane)."""
    cell = mesh.topology.cell_type
    if mesh.topology.dim != 2 or cell != CellType.triangle:
        raise InputError("mesh", f"shellform needs a 2D mesh of triangles, got {cell.name} cells "
                         f"of dimension {mesh.topology.dim}")
    if mesh.geometry.cmaps[0].degree != 1:
        raise InputError("mesh", f"shellform needs affine (degree 1) triangles, got degree {mesh.geometry.cmaps[0].degree}")


class HybridShellForms:
    """Stiffness, load and recovery forms of the hybrid shell element on one mesh."""

    def __init__(self, mesh, element: HybridElement, params: ShellParameters, mapped: bool = True):
        check_mesh(mesh)
        self.mesh, self.element, self.params, self.mapped = mesh, element, params, mapped
        self.kernels = ElementKernels.get(element, params, mapped, mesh.comm)
        self.constants = [getattr(params, name) for name in self.kernels.constant_names]
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
