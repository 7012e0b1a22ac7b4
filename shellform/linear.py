"""Linear static analysis of a scene: scene -> mesh -> forms -> assembly -> solve -> result.

One solve of K q = f with the condensed, mapped hybrid element. Timings are split into
compile (FFCx + numba), assembly and solve, as the accuracy-against-time studies report them.
"""

import time
from dataclasses import dataclass, field

import dolfinx.fem.petsc as fem_petsc
import numpy as np
from dolfinx import fem, la
from mpi4py import MPI
from petsc4py import PETSc

from shellform.forms.fields import ShellParameters
from shellform import loads, supports
from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly.kernels import HybridShellForms
from shellform.edge_frames import EdgeConstraints
from shellform.mesh import blank
from shellform.errors import InputError
from shellform.scene import Scene


@dataclass
class LinearResult:
    scene: Scene
    forms: HybridShellForms
    q: fem.Function  # carrier solution: per vertex the active components
    timings: dict = field(default_factory=dict)
    size: float = 1.0  # the blank's extent (a length scale for tolerances)

    @property
    def components(self) -> tuple[str, ...]:
        return self.forms.element.carrier_components

    @property
    def num_cells(self) -> int:
        return self.forms.mesh.topology.index_map(2).size_global

    @property
    def num_dofs(self) -> int:
        return self.forms.num_dofs

    def value(self, name: str, x: float = 0.0, y: float = 0.0) -> float:
        """A nodal value (e.g. 'w') at the vertex (x, y)."""
        tol = 1e-9 * self.size
        return loads.value_at(self.q, self.components, name, x, y, tol)

    def cell_fields(self) -> dict[str, fem.Function]:
        """Centroid values of the assumed strains and stress resultants, as DG0 functions.

        membrane_strain, membrane_force, curvature, moment: components (xx, yy, xy), tensor
        off-diagonal (curvature xy = -w,xy; engineering twist = 2 x it).
        """
        e = self.forms.element
        mesh = self.forms.mesh
        W = fem.functionspace(mesh, ("DG", 0, (6 * len(e.groups),)))
        vec = fem.assemble_vector(self.forms.recovery_form(self.q, W))
        vec.scatter_reverse(la.InsertMode.add)
        values = vec.array.reshape(-1, 6 * len(e.groups))
        names = {"membrane": ("membrane_strain", "membrane_force"), "bending": ("curvature", "moment")}
        out = {}
        V3 = fem.functionspace(mesh, ("DG", 0, (3,)))
        for g, group in enumerate(e.groups):
            for k, name in enumerate(names[group]):
                f = fem.Function(V3, name=name)
                n = V3.dofmap.index_map.size_local
                f.x.array[: 3 * n] = values[:n, 6 * g + 3 * k : 6 * g + 3 * k + 3].ravel()
                f.x.scatter_forward()
                out[name] = f
        return out


def parameters(mesh, scene: Scene) -> ShellParameters:
    c = lambda v: fem.Constant(mesh, np.float64(v))  # noqa: E731
    m = scene.material
    kappa0 = scene.curvature()  # a ReferenceSurface (compiled into the kernels) or principal curvatures
    if isinstance(kappa0, np.ndarray):
        kappa0 = fem.Constant(mesh, kappa0)
    pressure = c(scene.loads.pressure) if "bending" in scene.effects else None
    return ShellParameters(E=c(m.E), nu=c(m.nu), thickness=c(m.thickness), kappa0=kappa0, pressure=pressure,
                           pressure_field=scene.pressure_field() if pressure is not None else None)


def mesh(scene: Scene, comm=MPI.COMM_WORLD):
    return blank(comm, scene, [(p.x, p.y) for p in scene.loads.point])


def compile_forms(scene: Scene, msh) -> HybridShellForms:
    element = HybridElement(tuple(scene.effects))
    return HybridShellForms(msh, element, parameters(msh, scene), mapped=scene.solver.mapped)


def along_axes(rect, named: dict) -> bool:
    """Whether every supported (not free) edge group of the blank lies along x or y."""
    return all(support == "free" or supports.edge_axis(rect, group) is not None for group, support in named.items())


def boundary_conditions(scene: Scene, rect, forms: HybridShellForms):
    """The scene's named supports on the sides of the meshed rectangle (with cubic_membrane the
    in-plane slopes are held as the sheet's are: a value fixed along a side fixes its derivative
    along the side)."""
    fixed = supports.sheet_fixed_components if forms.element.cubic_membrane else supports.fixed_components
    return supports.boundary_conditions(forms.V, forms.element.carrier_components, rect, scene.supports, fixed=fixed)


def assemble_system(forms: HybridShellForms, bcs, point_loads=(), tol=1e-9):
    """K and f with the Dirichlet conditions applied (lifted), point loads on owned vertices."""
    A = fem_petsc.assemble_matrix(forms.stiffness, bcs=bcs)
    A.assemble()
    if forms.load is not None:
        b = fem_petsc.assemble_vector(forms.load)
    else:
        b = fem_petsc.create_vector(forms.V)
        b.set(0.0)
    fem_petsc.apply_lifting(b, [forms.stiffness], bcs=[bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)  # owned entries final
    loads.add_point_loads(b, forms.V, forms.element.carrier_components, point_loads, tol)
    fem_petsc.set_bc(b, bcs)
    return A, b


def lu_solve(A, b, V) -> fem.Function:
    """q = A^-1 b by MUMPS LU; A and b are destroyed."""
    q = fem.Function(V, name="carrier")
    ksp = PETSc.KSP().create(V.mesh.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.solve(b, q.x.petsc_vec)
    reason = ksp.getConvergedReason()
    ksp.destroy(), A.destroy(), b.destroy()
    if reason < 0:
        raise RuntimeError(f"linear solve failed (PETSc reason {reason})")
    q.x.scatter_forward()
    return q


def solve(scene: Scene, comm=MPI.COMM_WORLD, blank_mesh=None) -> LinearResult:
    """The scene solved on its own mesh, or on `blank_mesh` (a BlankMesh with the scene's groups)."""
    t = time.perf_counter()
    rect = blank_mesh or mesh(scene, comm)
    axes = along_axes(rect, scene.supports)  # supported edges along x and y: Dirichlet conditions on components
    if not axes and "cubic_membrane" in scene.effects:
        raise InputError("effects", "'cubic_membrane' holds supports on edges along x and y only; this blank has "
                         "a supported curved or oblique edge (its frames are not built for the in-plane slopes)")
    t0 = time.perf_counter()
    forms = compile_forms(scene, rect.mesh)
    t1 = time.perf_counter()
    tol = 1e-9 * rect.size
    if axes:
        A, b = assemble_system(forms, boundary_conditions(scene, rect, forms), scene.loads.point, tol)
        edges = None
    else:  # edges of any direction: in their own frames
        edges = EdgeConstraints(forms.V, forms.element.carrier_components, rect, scene.supports)
        A, b = edges.apply(*assemble_system(forms, [], scene.loads.point, tol))
    t2 = time.perf_counter()
    q = lu_solve(A, b, forms.V)
    if edges is not None:
        edges.recover(q)
    t3 = time.perf_counter()
    if not np.all(np.isfinite(q.x.array)):
        raise FloatingPointError("the solution has non-finite values: is the structure supported?")
    timings = {"mesh_s": t0 - t, "compile_s": t1 - t0, "assemble_s": t2 - t1, "solve_s": t3 - t2,
               "total_s": t3 - t}
    return LinearResult(scene, forms, q, timings, rect.size)
