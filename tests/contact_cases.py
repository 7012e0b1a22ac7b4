"""Cases the contact tests share: a flat rigid face, a plate under a flat punch, a strip pinched
between flat tools, the paper's cup on a coarse mesh (drawn, and one increment further), and a
central-difference check of the contact driver's tangent."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform import scene
from shellform import supports as named_supports
from shellform.contact.problem import DrawingProblem
from shellform.contact.semi_inverse import SemiInverseDriver
from shellform.material import Hill79Material
from shellform.mesh import SIDE_TAG, rectangle
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.model import SheetModel

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


class FlatTool:
    """A rigid flat face at z_face over |x| <= a (and |y| <= b), pushing along `sign` z."""

    axis = np.array([0.0, 0.0, 1.0])  # it travels by dz along z

    def __init__(self, z_face, a, b=np.inf, sign=-1.0):
        self.z_face, self.a, self.b, self.sign = z_face, a, b, sign

    def gap(self, x, offset=0.0, dz=0.0):
        over = (np.abs(x[:, 0]) <= self.a) & (np.abs(x[:, 1]) <= self.b)
        gap = np.where(over, self.sign * (x[:, 2] - (self.z_face + dz)) - offset, np.inf)
        n = np.zeros_like(x)
        n[:, 2] = self.sign
        return gap, n

    def shape(self, x, offset=0.0, dz=0.0):
        """A flat face does not curve: H = dn/dx = 0."""
        return np.zeros((len(x), 3, 3))


def plate(n=8, L=100.0, t=1.0):
    rect = rectangle(MPI.COMM_WORLD, L, L, region="quarter", n=n)
    model = SheetModel(rect.mesh, Hill79Material(E=210000.0, nu=0.3).pack(), t, ("geometric_nonlinearity",))
    sup = {"left": "symmetry", "bottom": "symmetry", "right": "simply_supported", "top": "simply_supported"}
    bcs = named_supports.boundary_conditions(model.V, model.components, rect, sup,
                                             fixed=named_supports.sheet_fixed_components)
    return rect, model, bcs


def side_sum(driver, rect, sides, comp):
    """Sum of the residual (the support's force) over the dofs of a component on the sides."""
    V = driver.model.V
    facets = np.concatenate([rect.facet_tags.find(SIDE_TAG[side]) for side in sides])
    dofs = fem.locate_dofs_topological(V.sub(comp), 1, np.unique(facets))
    owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    return MPI.COMM_WORLD.allreduce(float(driver.residual_full[dofs[dofs < owned]].sum()), op=MPI.SUM)


def strip(mu=0.15, F=1000.0, t=1.0, friction_rtol=1e-10, drawbeads=(), **controls):
    """A 100 x 20 strip pinched over |x| <= 40 between a flat die and a flat holder pressing with
    F (and over drawbeads); its right end is pulled by lambda * 2 mm along x."""
    from shellform.contact.semi_inverse import ContactControls

    rect = rectangle(MPI.COMM_WORLD, 100.0, 20.0, region="full", n=10)
    model = SheetModel(rect.mesh, Hill79Material(E=210000.0, nu=0.3).pack(), t, ("geometric_nonlinearity",))
    die, holder = FlatTool(-t / 2, 40.0, sign=1.0), FlatTool(t / 2, 40.0, sign=-1.0)
    V = model.V
    qbar = fem.Function(V)
    right = rect.facet_tags.find(SIDE_TAG["right"])
    bcs = []
    for k, value in ((0, 2.0), (1, 0.0), (2, 0.0)):
        dofs = fem.locate_dofs_topological(V.sub(k), 1, right)
        qbar.x.array[dofs] = value
        bcs.append(fem.dirichletbc(np.float64(0), dofs, V.sub(k)))
    contact = ContactControls(penetration=1e-3 * t, friction_rtol=friction_rtol)
    d = SemiInverseDriver(model, bcs, [die], [0.0], friction=mu, holder=holder, holder_force=F, prescribed=qbar,
                          contact=contact, drawbeads=drawbeads, controls=Controls(**{"initial_step": 0.1, "rtol": 1e-10,
                                                                "max_iterations": 25, **controls}), verbose=False)
    return rect, d


def square_cup(n=8, changes=None, **tools):
    """The paper's cup on n x n with tools keys and other changes {"section.key": value}."""
    return scene.load(ROOT / "demos" / "square_cup.toml").changed(
        {"mesh.n": n, **{f"tools.{k}": v for k, v in tools.items()}, **(changes or {})})


def tangent_error(d, lam, rows, columns, h=1e-6):
    """Largest |K e_j - (R(q + h v) - R(q - h v)) / 2h| on `rows` over the (j, v) in columns (a
    tangent column and the perturbation of q, global coordinates, that it stands for), relative
    to the largest entry; the frames, friction and normal forces follow q as in Newton."""
    def residual(tangent):
        d.linearize(lam, tangent)
        return d.b.getArray()[rows].copy()

    residual(True)
    K = d.A.copy()
    worst, size = 0.0, 0.0
    for j, v in columns:
        e, Ke = K.createVecs()
        e.set(0.0)
        e.setValue(j, 1.0)
        e.assemble()
        K.mult(e, Ke)
        q0 = d.q.x.array.copy()
        d.q.x.array[:] = q0 + h * v
        plus = residual(False)
        d.q.x.array[:] = q0 - h * v
        minus = residual(False)
        d.q.x.array[:] = q0
        column = Ke.getArray()[rows]
        worst = max(worst, np.abs((plus - minus) / (2 * h) - column).max())
        size = max(size, np.abs(column).max())
    residual(True)
    return worst / size


def drawn_cup(stroke):
    """The coarse cup drawn `stroke` mm, then the next increment (0.2 mm) converged, not committed."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(stroke / s.tools.stroke)
    lam = d.lam + 0.2 / s.tools.stroke
    assert d.newton(lam)[0]
    return d, lam
