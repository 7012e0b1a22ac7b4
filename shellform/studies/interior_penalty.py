"""The plain DOLFINx route to a Kirchhoff plate, as a reference curve for our element: the C0
interior-penalty method with P2 or P3 Lagrange elements (Engel et al. 2002; Brenner and Sung 2005).

The same quarter plate as shellform.studies.plate ([0, a/2]^2, a = 1, D = 1, q = 1, nu = 0.3,
the same structured meshes), simply supported at x = a/2 and y = a/2 (w = 0 strongly, M_nn = 0
naturally), symmetric at x = 0 and y = 0 (dw/dn = 0 weakly, as an interior facet whose other
side mirrors this one; zero shear naturally). With kappa(w) = grad grad w and
M(w) = D ((1 - nu) kappa + nu tr(kappa) I):

    a(w, v) = sum_K int_K M(w) : kappa(v)
              - sum_F int_F ({M_nn(w)} [dv/dn] + {M_nn(v)} [dw/dn])
              + sum_F int_F (alpha D / h_F) [dw/dn] [dv/dn],        L(v) = int q v,

over the interior facets and the symmetry edges ([dw/dn] = dw/dn there, {M_nn} = M_nn); h_F the
facets' mean cell diameter. alpha = 8 for P2 (the value of DOLFINx's biharmonic demo) and 16
for P3. Measured on these meshes (128 to 2,048 cells): alpha = 1 or 2 gives errors that jump
between meshes (too little penalty), alpha = 4 to 32 converge, with errors that grow with alpha
(P2 at 2,048 cells: 8.0e-4 at 4, 1.3e-3 at 8, 3.6e-3 at 32; P3: 2.7e-7, 1.9e-7, 1.3e-7 at 4,
8, 16). Timed as our element is: mesh + assemble + solve (MUMPS), the forms compiled before.
"""

import time

import numpy as np
import ufl
from dolfinx import fem, mesh as dmesh
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

ALPHA = {2: 8.0, 3: 16.0}
SYMMETRY, SUPPORT = 1, 2  # facet tags: the edges x = 0 or y = 0, and x = a/2 or y = a/2


def _mesh(n: int):
    m = dmesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [0.5, 0.5]], [n, n], dmesh.CellType.triangle,
                               diagonal=dmesh.DiagonalType.right)
    m.topology.create_connectivity(1, 2)
    facets = dmesh.exterior_facet_indices(m.topology)
    mid = dmesh.compute_midpoints(m, 1, facets)
    tags = np.where(np.minimum(mid[:, 0], mid[:, 1]) < 1e-12, SYMMETRY, SUPPORT).astype(np.int32)
    order = np.argsort(facets)
    return m, dmesh.meshtags(m, 1, facets[order], tags[order])


def forms(m, tags, degree: int, nu: float, D: float = 1.0, q: float = 1.0):
    """(a, L, V, bc) of the C0 interior-penalty plate on mesh m with facet tags."""
    V = fem.functionspace(m, ("Lagrange", degree))
    w, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    n = ufl.FacetNormal(m)
    h = ufl.CellDiameter(m)
    alpha = fem.Constant(m, PETSc.ScalarType(ALPHA[degree]))

    def moment(u):
        k = ufl.grad(ufl.grad(u))
        return D * ((1 - nu) * k + nu * ufl.tr(k) * ufl.Identity(2))

    def mnn(u, nn):
        return ufl.inner(ufl.dot(moment(u), nn), nn)

    ds = ufl.Measure("ds", domain=m, subdomain_data=tags)
    h_avg = (h("+") + h("-")) / 2
    jump = lambda u: ufl.jump(ufl.grad(u), n)  # noqa: E731  [du/dn] across a facet
    a = (ufl.inner(moment(w), ufl.grad(ufl.grad(v))) * ufl.dx
         - (ufl.avg(mnn(w, n)) * jump(v) + ufl.avg(mnn(v, n)) * jump(w)) * ufl.dS
         + alpha * D / h_avg * jump(w) * jump(v) * ufl.dS
         - (mnn(w, n) * ufl.dot(ufl.grad(v), n) + mnn(v, n) * ufl.dot(ufl.grad(w), n)) * ds(SYMMETRY)
         + alpha * D / h * ufl.dot(ufl.grad(w), n) * ufl.dot(ufl.grad(v), n) * ds(SYMMETRY))
    L = fem.Constant(m, PETSc.ScalarType(q)) * v * ufl.dx
    supported = dmesh.locate_entities_boundary(m, 1, lambda x: np.maximum(x[0], x[1]) > 0.5 - 1e-12)
    bc = fem.dirichletbc(PETSc.ScalarType(0), fem.locate_dofs_topological(V, 1, supported), V)
    return fem.form(a), fem.form(L), V, bc


def solve(n: int, degree: int, nu: float) -> dict:
    """The quarter plate on an n x n x 2 mesh: centre deflection and the times of compilation
    (once per process and degree: the forms are cached by FFCx) and of mesh + assembly + solve."""
    t = time.perf_counter()
    m, tags = _mesh(n)
    t0 = time.perf_counter()
    a, L, V, bc = forms(m, tags, degree, nu)
    t1 = time.perf_counter()
    A = fem_petsc.assemble_matrix(a, bcs=[bc])
    A.assemble()
    b = fem_petsc.assemble_vector(L)
    fem_petsc.apply_lifting(b, [a], bcs=[[bc]])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fem_petsc.set_bc(b, [bc])
    t2 = time.perf_counter()
    ksp = PETSc.KSP().create(m.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    wh = fem.Function(V)
    ksp.solve(b, wh.x.petsc_vec)
    wh.x.scatter_forward()
    t3 = time.perf_counter()
    centre = np.flatnonzero(np.linalg.norm(V.tabulate_dof_coordinates()[:, :2], axis=1) < 1e-12)
    local = [float(wh.x.array[centre[0]])] if centre.size and centre[0] < V.dofmap.index_map.size_local else []
    w0 = next(x for part in m.comm.allgather(local) for x in part)
    for obj in (ksp, A, b):
        obj.destroy()
    return {"cells": m.topology.index_map(2).size_global,
            "dofs": V.dofmap.index_map.size_global, "w_center": w0,
            "mesh_s": t0 - t, "compile_s": t1 - t0, "assemble_s": t2 - t1, "solve_s": t3 - t2,
            "total_s": t3 - t}
