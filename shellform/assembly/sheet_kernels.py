"""FFCx kernels of the nonlinear sheet (forms.kirchhoff_love) and the per-cell numba loop.

Compiled once per (effects, quadrature degree) on a mesh-free domain, like ElementKernels:

    hessian    d2/dz2 of the weak-Hessian constraint (bending-only hybrid element)
    strain     the expression e(z) at the quadrature points
    force      d/dz int S . e              (coefficients z, S)
    tangent    int de . D . te + S . d2e   (coefficients z, S, D)
    pressure   d/dz int p U_3              (dead pressure per unit p)
    edge_strain, edge_gradient   E and dE/dz at the edge points      (the assumed membrane strain)
    gradient, geometric          B = de/dz at the points, int S . d2e (the assumed membrane strain;
                                 B also where the tools' faces press, the effect ironing)

The last four are compiled only when a sheet that needs them is built (SheetKernels.require):
a first run without the assumed membrane strain or ironing does not compile them (7 s of CPU
of the cold run's 20 s of FFCx kernels, docs/performance.md, "Where a cold first run's time goes").

Two numba loops over the owned cells do the element around the constitutive update (which is
shellform.material.update.section_update, a loop of its own so that its time is measured apart),
each in shares of the cells run on threads at once (shellform._jit.over_threads):

    strain_loop   gather the carrier values q, map them (z = Q q), strains e at the points
                  (the membrane rows tied to the edges: shellform.assembly.assumed_membrane)
    tensor_loop   r = Q^T r_z and K = Q^T K_z Q from the resultants S and section tangents D

Assembly is DOLFINx's (shellform.nonlinear.assemble).
"""


import basix.ufl
import numpy as np
import ufl
from dolfinx.jit import ffcx_jit

from shellform.forms import kirchhoff_love as kl
from shellform.assembly import assumed_membrane, condensation, slope_map
from shellform.assembly.kernels import JIT_OPTIONS, reference_fields
from shellform.assembly.sheet_element import NDOF, SheetElement, build_q, congruence
from shellform import _jit as jit
from shellform._jit import kernel_address

_OPTIONS = {"scalar_type": "float64"}


def _cell_kernel(comm, form):
    ufcx, _, _ = ffcx_jit(comm, form, form_compiler_options=_OPTIONS, jit_options=JIT_OPTIONS)
    if ufcx.form_integral_offsets[1] != 1:
        raise RuntimeError(f"expected one cell integral, FFCx made {ufcx.form_integral_offsets[1]}")
    return ufcx.form_integrals[0].tabulate_tensor_float64, ufcx


def packed_offsets(ufcx, form, coefficients) -> np.ndarray:
    """Offset of each of `coefficients` in the kernel's packed w (-1 where the form lacks it).

    FFCx packs only the coefficients a form still depends on after differentiation (the
    linearised strains' tangent has no z and no S), in its own order.
    """
    original = form.coefficients()
    out, start = -np.ones(len(coefficients), dtype=np.int64), 0
    for i in range(ufcx.num_coefficients):
        c = original[ufcx.original_coefficient_positions[i]]
        for k, ck in enumerate(coefficients):
            if c == ck:
                out[k] = start
        start += c.ufl_element().dim
    return out


def _address(kernel) -> int:
    """A kernel's address, 0 for one not compiled (SheetKernels.require)."""
    return 0 if kernel is None else kernel_address(kernel)


def _facet_kernel(ufcx):
    off = [ufcx.form_integral_offsets[i] for i in range(3)]
    return ufcx.form_integrals[off[1]].tabulate_tensor_float64


class SheetKernels:
    """The compiled kernels of one configuration of the nonlinear sheet."""

    _cache: dict = {}

    @classmethod
    def get(cls, nonlinear: bool, shallow, comm, quadrature_degree: int = 4):
        """shallow: False (flat), True (a constant kappa0 in the kernels' constants) or a
        forms.reference_surface.ReferenceSurface (z0 compiled into the kernels)."""
        key = (nonlinear, shallow, quadrature_degree)
        if key not in cls._cache:
            cls._cache[key] = cls(nonlinear, shallow, comm, quadrature_degree)
        return cls._cache[key]

    def __init__(self, nonlinear, shallow, comm, quadrature_degree):
        self.element = el = SheetElement(quadrature_degree)
        self.nonlinear, self.shallow = nonlinear, shallow
        cell = "triangle"
        domain = ufl.Mesh(basix.ufl.element("Lagrange", cell, 1, shape=(2,)))
        x = ufl.SpatialCoordinate(domain)
        n = ufl.FacetNormal(domain)

        # The weak Hessian of one component: the bending-only hybrid element of issue 2.
        Zh = ufl.FunctionSpace(domain, el.hessian.mixed)
        zh = ufl.Coefficient(Zh)
        f = reference_fields(el.hessian, zh)
        c = kl.weak_hessian_constraint(f.M, f.eps_b, f.w, f.g, n)
        ah = ufl.derivative(ufl.derivative(c, zh, ufl.TestFunction(Zh)), zh, ufl.TrialFunction(Zh))
        self.hessian_cell, ufcx = _cell_kernel(comm, ah)
        self.hessian_facet = _facet_kernel(ufcx)

        # The energy element and its quadrature fields S (6) and D (36) per point.
        Z = ufl.FunctionSpace(domain, el.energy)
        z = ufl.Coefficient(Z)
        dz, tz = ufl.TestFunction(Z), ufl.TrialFunction(Z)
        qdeg = quadrature_degree
        Sq = ufl.Coefficient(ufl.FunctionSpace(domain, basix.ufl.quadrature_element(cell, (6,), degree=qdeg)))
        Dq = ufl.Coefficient(ufl.FunctionSpace(domain, basix.ufl.quadrature_element(cell, (36,), degree=qdeg)))
        D = ufl.as_matrix([[Dq[6 * i + j] for j in range(6)] for i in range(6)])
        dx = ufl.dx(metadata={"quadrature_degree": qdeg})
        parts = ufl.split(z)
        U, H = parts[0], parts[1:]
        kappa0 = (shallow if hasattr(shallow, "slopes") else ufl.Constant(domain, shape=(2, 2))) if shallow else None
        e = kl.section_strain(U, H, x, kappa0, nonlinear)
        de, te = ufl.derivative(e, z, dz), ufl.derivative(e, z, tz)
        fforce = kl.internal_work(de, Sq, dx)
        ftangent = kl.tangent(e, de, te, Sq, D, z, dz, tz, dx, nonlinear)
        self.force, ufcx_f = _cell_kernel(comm, fforce)
        self.tangent, ufcx_t = _cell_kernel(comm, ftangent)
        self.force_offsets = packed_offsets(ufcx_f, fforce, [z, Sq, Dq])
        self.tangent_offsets = packed_offsets(ufcx_t, ftangent, [z, Sq, Dq])
        p = ufl.Constant(domain)
        self.pressure, _ = _cell_kernel(comm, ufl.derivative(kl.dead_pressure(p, U, dx), z, dz))
        self._pressure_form = lambda field: ufl.derivative(kl.dead_pressure(field.density(x), U, dx), z, dz)
        self._pressure_fields, self._comm = {}, comm
        ufcx_e, _, _ = ffcx_jit(comm, (e, el.points), form_compiler_options=_OPTIONS,
                                jit_options=JIT_OPTIONS)
        self.strain = ufcx_e.tabulate_tensor_float64
        self.nconst = 4 if shallow is True else 0  # a constant kappa0 in every kernel that sees it
        self.edge_gradients = assumed_membrane.cubic_gradients()  # reference, at the edge points
        # the kernels only the assumed membrane strain or ironing calls: compiled when a sheet
        # first needs them (require), not before (docs/performance.md, issue 44)
        self._fields = (z, dz, tz, e, de, Sq, Dq, dx)
        self.edge_strain = self.edge_gradient = self.gradient = self.geometric = None
        self.geometric_offsets = self.tangent_offsets
        self.assumed, self.pressed = False, False
        self.strain_loop = self._strain_loop()
        self.tensor_loop = self._tensor_loop()

    def require(self, assumed: bool, pressed: bool) -> None:
        """Compile the kernels a sheet with the assumed membrane strain (assumed: E and dE/dz at
        the edge points, B = de/dz at the area points, the initial-stress tangent on its own)
        or pressed by the tools' faces (pressed, the effect ironing: B) calls, where not done
        yet, and bind the loops to them. Until then the loops hold address 0 for them, which
        they never call: beta = 1 and no cell pressed."""
        assumed, pressed = assumed and not self.assumed, (assumed or pressed) and not self.pressed
        if not (assumed or pressed):
            return
        comm, el = self._comm, self.element
        z, dz, tz, e, de, Sq, Dq, dx = self._fields
        if pressed:
            ufcx_b, _, _ = ffcx_jit(comm, (de, el.points), form_compiler_options=_OPTIONS, jit_options=JIT_OPTIONS)
            self.gradient, self.pressed = ufcx_b.tabulate_tensor_float64, True
        if assumed:
            edges = assumed_membrane.edge_points()
            E = ufl.as_vector([e[i] for i in range(3)])
            ufcx_m, _, _ = ffcx_jit(comm, (E, edges), form_compiler_options=_OPTIONS, jit_options=JIT_OPTIONS)
            ufcx_dm, _, _ = ffcx_jit(comm, (ufl.derivative(E, z, dz), edges), form_compiler_options=_OPTIONS,
                                     jit_options=JIT_OPTIONS)
            self.edge_strain, self.edge_gradient = ufcx_m.tabulate_tensor_float64, ufcx_dm.tabulate_tensor_float64
            if self.nonlinear:
                fgeo = ufl.derivative(ufl.derivative(kl.internal_work(e, Sq, dx), z, dz), z, tz)
                self.geometric, ufcx_g = _cell_kernel(comm, fgeo)
                self.geometric_offsets = packed_offsets(ufcx_g, fgeo, [z, Sq, Dq])
            self.assumed = True
        self.strain_loop = self._strain_loop()
        self.tensor_loop = self._tensor_loop()

    # -- the loops, bound to this configuration's kernels and tables -----------------------------
    def setup(self, cells_coords, P_out, F_out, pressure_field=None) -> None:
        """Per cell P (H = P q_c) and the element pressure vector for p = 1, spread by
        `pressure_field` (forms.loads.PressureField: its kernel compiled once per field)."""
        kernel = self.pressure
        if pressure_field is not None:
            if pressure_field not in self._pressure_fields:
                self._pressure_fields[pressure_field] = _cell_kernel(self._comm, self._pressure_form(pressure_field))[0]
            kernel = self._pressure_fields[pressure_field]
        el = self.element
        he = el.hessian
        setup_loop(kernel_address(self.hessian_cell), kernel_address(self.hessian_facet), kernel_address(kernel),
                   he.q, he.eps, he.lam, *el.hessian_tables, *el.q_map(), el.component_columns(), he.dim, el.nz,
                   el.sym_dim, cells_coords, P_out, F_out)

    def _strain_loop(self):
        """strain_loop(threads, cells, ...): the loop's shares on `threads` threads."""
        el = self.element
        bound = (kernel_address(self.strain), _address(self.edge_strain), *el.q_map(), el.component_columns(),
                 el.nz, self.nconst)
        return lambda threads, *args: jit.over_threads(strain_loop, threads, *bound, *args)

    def _tensor_loop(self):
        """tensor_loop(threads, cells, ...): the loop's shares on `threads` threads."""
        el = self.element
        bound = (kernel_address(self.force), kernel_address(self.tangent), _address(self.geometric),
                 _address(self.gradient), _address(self.edge_gradient), self.force_offsets, self.tangent_offsets,
                 self.geometric_offsets, *el.q_map(),
                 el.component_columns(), el.nz, el.nqp, self.nconst, self.edge_gradients, el.weights)
        return lambda threads, *args: jit.over_threads(tensor_loop, threads, *bound, *args)


# -- numba loops (cached: the kernels come in as addresses) ------------------------------------
@jit.njit
def setup_loop(hc, hf, pk, iq, ie, il, hcols, hcodes, qcols, qcodes, ccols, nzh, nz, ns, cells_coords, P_out,
               F_out):
    """Per cell: P (H = P q_c) and the element pressure vector for p = 1."""
    Ah = np.zeros((nzh, nzh))
    wz = np.zeros(1)
    ck = np.zeros(1)
    one = np.ones(1)
    local = np.zeros(1, dtype=np.int32)
    perm = np.zeros(1, dtype=np.uint8)
    Q = np.zeros((nz, NDOF))
    fz = np.zeros(nz)
    for cidx in range(cells_coords.shape[0]):
        coords = cells_coords[cidx]
        Ah[:, :] = 0.0
        local[0] = 0
        jit.call_kernel(hc, Ah, wz, ck, coords, local, perm)
        for f in range(3):
            local[0] = f
            jit.call_kernel(hf, Ah, wz, ck, coords, local, perm)
        # G H + C q_ref = 0  ->  H = -G^-1 C T q_c
        G = np.empty((ns, ns))
        C = np.empty((ns, iq.size))
        for a in range(ns):
            for b in range(ns):
                G[a, b] = Ah[il[a], ie[b]]
            for b in range(iq.size):
                C[a, b] = Ah[il[a], iq[b]]
        J = slope_map.jacobian(coords)
        coef = slope_map.coefficients(J, hcodes, True)
        CT = np.zeros((ns, 9))
        for a in range(ns):
            for r in range(iq.size):
                for k in range(2):
                    if hcols[r, k] >= 0:
                        CT[a, hcols[r, k]] += C[a, r] * coef[r, k]
        CT *= -1.0
        condensation.cholesky_solve(condensation.cholesky(G), CT)
        for a in range(ns):
            for b in range(9):
                P_out[cidx, a, b] = CT[a, b]
        build_q(J, P_out[cidx], qcols, qcodes, ccols, Q)
        fz[:] = 0.0
        local[0] = 0
        jit.call_kernel(pk, fz, wz, one, coords, local, perm)
        np.dot(Q.T, fz, F_out[cidx])


@jit.njit
def _scratch(consts, nconst):
    """A loop's per-thread buffers: the constants and the kernel's index arguments."""
    c = np.zeros(max(nconst, 1))
    for i in range(nconst):
        c[i] = consts[i]
    return c, np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.uint8)


@jit.njit(nogil=True)
def strain_loop(counter, strain, edge_strain, qcols, qcodes, ccols, nz, nconst, cells, cells_coords, dofs, x, P, consts,
                beta, tying, z_out, e_out):
    """z = Q q and the section strains e at the quadrature points of the cells, a chunk of them
    at a time from the threads' shared counter (jit.over_threads, jit.next_chunk); the membrane
    rows are the assumed membrane strain where beta < 1 (assumed_membrane)."""
    # the views taken below count no references (jit.borrowed)
    cells, cells_coords, dofs, x, P = jit.borrowed(cells), jit.borrowed(cells_coords), jit.borrowed(dofs), \
        jit.borrowed(x), jit.borrowed(P)
    beta, tying, z_out, e_out = jit.borrowed(beta), jit.borrowed(tying), jit.borrowed(z_out), jit.borrowed(e_out)
    Q = np.zeros((nz, NDOF))
    q = np.empty(NDOF)
    E_edge = np.zeros((9, 3))
    c, local, perm = _scratch(consts, nconst)
    n = cells.size
    start = jit.next_chunk(counter)
    while start < n:
        for k in range(start, min(start + jit.CHUNK, n)):
            cidx = cells[k]
            coords = cells_coords[cidx]
            build_q(slope_map.jacobian(coords), P[cidx], qcols, qcodes, ccols, Q)
            for v in range(3):
                for b in range(9):
                    q[9 * v + b] = x[9 * dofs[cidx, v] + b]
            np.dot(Q, q, z_out[k])
            e = e_out[k].ravel()
            e[:] = 0.0
            jit.call_kernel(strain, e, z_out[k], c, coords, local, perm)
            if beta[cidx] < 1.0:
                E_edge[:, :] = 0.0
                jit.call_kernel(edge_strain, E_edge.reshape(E_edge.size), z_out[k], c, coords, local, perm)
                assumed_membrane.assumed_strain(E_edge, tying[cidx], beta[cidx], e_out[k])
        start = jit.next_chunk(counter)


@jit.njit
def _pack(w, offsets, nz, nqp, z, S, D):
    """The kernel's coefficients z, S and D at their offsets in w (those it has)."""
    for offset, v in ((offsets[0], z), (offsets[1], S), (offsets[2], D)):
        if offset >= 0:
            for i in range(v.size):
                w[offset + i] = v[i]


@jit.njit(nogil=True)
def tensor_loop(counter, force, tangent, geometric, gradient, edge_gradient, fo, to, go, qcols, qcodes, ccols, nz, nqp,
                nconst, grads, weights, cells, cells_coords, P, consts, beta, tying, z, S, D, ironed_d, ironed,
                want_tangent, R_out, K_out):
    """r = Q^T r_z(z, S) and K = Q^T K_z(z, S, D) Q for the cells, a chunk of them at a time
    from the threads' shared counter (jit.over_threads, jit.next_chunk). Where beta < 1 the
    membrane strain is the assumed one (shellform.assembly.assumed_membrane, whose docstring has
    the terms). Where the tools' faces press a cell (shellform.material.ironing: ironed[:, 0]
    phi'' > 0, ironed[:, 1] phi', ironed[:, 2:] the clearance's gradient n_i at its three
    vertices, ironed_d d_g at its points), r gets the faces' push -phi' A0 / 3 n_i on each
    vertex's u, v, w and K the rank-one phi'' / A0 v v^T, v = Q^T G - A0 / 3 sum_i n_i (vertex
    i's rows), G = sum_g A0 w_g B_g^T d_g."""
    # the views taken below count no references (jit.borrowed)
    cells, cells_coords, P, beta, tying = jit.borrowed(cells), jit.borrowed(cells_coords), jit.borrowed(P), \
        jit.borrowed(beta), jit.borrowed(tying)
    z, S, D, R_out, K_out = jit.borrowed(z), jit.borrowed(S), jit.borrowed(D), jit.borrowed(R_out), jit.borrowed(K_out)
    ironed_d, ironed = jit.borrowed(ironed_d), jit.borrowed(ironed)
    Q = np.zeros((nz, NDOF))
    w = np.zeros(nz + 42 * nqp)
    rz = np.zeros(nz)
    Kz = np.zeros((nz, nz))
    QtK, KQ = np.zeros((NDOF, nz)), np.zeros((nz, NDOF))
    Sp = np.zeros((nqp, 6))
    B, Bm = np.zeros((nqp, 6, nz)), np.zeros((9, 3, nz))
    Bt, DB, wdet = np.zeros((6 * nqp, nz)), np.zeros((6 * nqp, nz)), np.zeros(nqp)
    sigma = np.zeros((9, 3))
    G = np.zeros(nz)
    v = np.zeros(NDOF)
    c, local, perm = _scratch(consts, nconst)
    n = cells.size
    start = jit.next_chunk(counter)
    while start < n:
        for k in range(start, min(start + jit.CHUNK, n)):
            cidx = cells[k]
            coords = cells_coords[cidx]
            J = slope_map.jacobian(coords)
            build_q(J, P[cidx], qcols, qcodes, ccols, Q)
            bk = beta[cidx]
            assumed = bk < 1.0
            for g in range(nqp):
                for a in range(6):
                    Sp[g, a] = S[k, g, a] * bk if assumed and a < 3 else S[k, g, a]
            rz[:] = 0.0
            if assumed:
                detJ = abs(slope_map.determinant(J))
                for g in range(nqp):
                    wdet[g] = weights[g] * detJ
                assumed_membrane.tied_stress(S[k], wdet, tying[cidx], sigma)
                Bm[:, :, :] = 0.0
                jit.call_kernel(edge_gradient, Bm.reshape(Bm.size), z[k], c, coords, local, perm)
                assumed_membrane.tied_force(Bm, sigma, 1.0 - bk, rz)
            _pack(w, fo, nz, nqp, z[k], Sp.ravel(), D[k].ravel())
            jit.call_kernel(force, rz, w, c, coords, local, perm)
            np.dot(Q.T, rz, R_out[k])
            pressed = ironed[k, 0] > 0.0
            if pressed:
                area = 0.5 * abs(slope_map.determinant(J))
                for i in range(3):
                    for a in range(3):
                        R_out[k, 9 * i + a] -= ironed[k, 1] * area / 3.0 * ironed[k, 2 + 3 * i + a]
            if not want_tangent:
                continue
            Kz[:, :] = 0.0
            if assumed:
                B[:, :, :] = 0.0
                jit.call_kernel(gradient, B.reshape(B.size), z[k], c, coords, local, perm)
                assumed_membrane.material_tangent(B, Bm, tying[cidx], bk, D[k].reshape(nqp, 36), wdet, Kz, Bt, DB)
                if geometric != 0:
                    _pack(w, go, nz, nqp, z[k], Sp.ravel(), D[k].ravel())
                    jit.call_kernel(geometric, Kz, w, c, coords, local, perm)
                    assumed_membrane.tied_initial_stress(J, grads, sigma, 1.0 - bk, Kz)
            else:
                _pack(w, to, nz, nqp, z[k], Sp.ravel(), D[k].ravel())
                jit.call_kernel(tangent, Kz, w, c, coords, local, perm)
            congruence(Kz, J, P[cidx], qcols, qcodes, ccols, QtK, KQ, K_out[k])
            if pressed:
                if not assumed:  # the compatible membrane rows B_g (the assumed ones are in Bt already)
                    B[:, :, :] = 0.0
                    jit.call_kernel(gradient, B.reshape(B.size), z[k], c, coords, local, perm)
                    for i in range(nqp):
                        for r in range(3):
                            for j in range(nz):
                                Bt[6 * i + r, j] = B[i, r, j]
                G[:] = 0.0
                for i in range(nqp):
                    for r in range(3):
                        f = 2.0 * area * weights[i] * ironed_d[k, i, r]
                        for j in range(nz):
                            G[j] += f * Bt[6 * i + r, j]
                for i in range(NDOF):
                    v[i] = 0.0
                    for j in range(nz):
                        v[i] += Q[j, i] * G[j]
                for i in range(3):
                    for a in range(3):
                        v[9 * i + a] -= area / 3.0 * ironed[k, 2 + 3 * i + a]
                f = ironed[k, 0] / area
                for i in range(NDOF):
                    for j in range(NDOF):
                        K_out[k, i, j] += f * v[i] * v[j]
        start = jit.next_chunk(counter)
