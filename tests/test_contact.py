"""The mixed semi-inverse contact: nodal frames, equilibrium with a rigid punch, release on
unloading, Coulomb friction between flat tools, the force-controlled blank holder, and a
short square-cup draw (penetration, holder equilibrium, contact set settling)."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from shellform import scene
from shellform import supports as named_supports
from shellform.contact.frames import nodal_frames, rotate_cell_arrays
from shellform.contact.problem import DrawingProblem
from shellform.contact.semi_inverse import SemiInverseDriver
from shellform.material import Hill79Material
from shellform.mesh import SIDE_TAG, rectangle
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.model import SheetModel

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


class FlatTool:
    """A rigid flat face at z_face over |x| <= a (and |y| <= b), pushing along `sign` z."""

    def __init__(self, z_face, a, b=np.inf, sign=-1.0):
        self.z_face, self.a, self.b, self.sign = z_face, a, b, sign

    def gap(self, x, offset=0.0, dz=0.0):
        over = (np.abs(x[:, 0]) <= self.a) & (np.abs(x[:, 1]) <= self.b)
        gap = np.where(over, self.sign * (x[:, 2] - (self.z_face + dz)) - offset, np.inf)
        n = np.zeros_like(x)
        n[:, 2] = self.sign
        return gap, n


def test_nodal_frames_keep_symmetry_slots():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(50, 3))
    n[:10, 0] = 0.0  # nodes on x = 0
    n[10:20, 1] = 0.0  # nodes on y = 0
    n[20:22, :2] = 0.0  # the flat faces, both signs
    n[21, 2] = -1.0
    n /= np.linalg.norm(n, axis=1)[:, None]
    F = nodal_frames(n)
    assert np.allclose(np.einsum("nij,nkj->nik", F, F), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(F), 1.0)
    assert np.array_equal(F[:, 2], n)
    assert np.all(F[:10, 0] == [1.0, 0.0, 0.0])  # u stays one slot on x = 0
    assert np.all(np.abs(F[10:20, 1]) == [0.0, 1.0, 0.0])  # v stays one slot on y = 0
    assert np.all(F[20:22, 0] == [1.0, 0.0, 0.0])


def test_rotated_cell_arrays_are_t_k_tt():
    rng = np.random.default_rng(1)
    dofs = np.array([[0, 1, 2], [2, 3, 0]], dtype=np.int32)
    rotated = np.array([True, False, True, True])
    frames = nodal_frames(rng.normal(size=(4, 3)) / np.sqrt(3))
    frames = np.array([np.linalg.qr(f)[0] for f in frames])
    vec, mat = rng.normal(size=(2, 27)), rng.normal(size=(2, 27, 27))
    v2, m2 = vec.copy(), mat.copy()
    rotate_cell_arrays(dofs, rotated, frames, v2, m2, True)
    for c in range(2):
        T = np.eye(27)
        for a in range(3):
            if rotated[dofs[c, a]]:
                T[9 * a: 9 * a + 3, 9 * a: 9 * a + 3] = frames[dofs[c, a]]
        assert np.allclose(v2[c], T @ vec[c], atol=1e-13)
        assert np.allclose(m2[c], T @ mat[c] @ T.T, atol=1e-12)


def _plate(n=8, L=100.0, t=1.0):
    rect = rectangle(MPI.COMM_WORLD, L, L, region="quarter", n=n)
    model = SheetModel(rect.mesh, Hill79Material(E=210000.0, nu=0.3).pack(), t, ("geometric_nonlinearity",))
    sup = {"left": "symmetry", "bottom": "symmetry", "right": "simply_supported", "top": "simply_supported"}
    bcs = named_supports.boundary_conditions(model.V, model.components, rect.facet_tags, sup,
                                             fixed=named_supports.sheet_fixed_components)
    return rect, model, bcs


def _side_sum(driver, rect, sides, comp):
    """Sum of the residual (the support's force) over the dofs of a component on the sides."""
    V = driver.model.V
    facets = np.concatenate([rect.facet_tags.find(SIDE_TAG[side]) for side in sides])
    dofs = fem.locate_dofs_topological(V.sub(comp), 1, np.unique(facets))
    owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    return MPI.COMM_WORLD.allreduce(float(driver.residual_full[dofs[dofs < owned]].sum()), op=MPI.SUM)


def test_flat_punch_on_a_plate_balances_the_supports_and_releases_on_unloading():
    """A flat rigid punch pushes a simply supported plate 2 mm down and goes back: the punch's
    contact force equals the support reactions (to 1e-8), no node penetrates, the contact set
    settles in every increment, and when the punch is lifted every node leaves it."""
    t = 1.0
    rect, model, bcs = _plate(t=t)
    punch = FlatTool(t / 2, 15.0, 15.0)
    d = SemiInverseDriver(model, bcs, [punch], [-2.0], controls=Controls(initial_step=0.25, rtol=1e-10),
                          verbose=False)
    forces = []

    def check(dr):
        r = dr.reactions()
        on = dr.state.tool == 0
        # z of the punch's force on the sheet: F^T r on the punch nodes
        fz = np.einsum("nk,nk->n", dr.frames[: dr.n_owned][on][:, :, 2], r[on])
        punch_z = MPI.COMM_WORLD.allreduce(float(fz.sum()), op=MPI.SUM)
        support = _side_sum(dr, rect, ("right", "top"), 2)
        forces.append(punch_z)
        peak = max(abs(f) for f in forces)
        assert abs(punch_z + support) <= 1e-8 * peak, (punch_z, support)
        gap, _ = punch.gap(dr.positions(), 0.5 * t, dr.lam * -2.0)
        assert -gap.min() <= dr.contact.penetration
        assert dr.history[-1].contact["passes"] < dr.contact.max_passes

    d.run(1.0, on_increment=check)
    assert forces[-1] < 0 and abs(forces[-1]) > 10.0  # the punch pushes down with a real force
    assert MPI.COMM_WORLD.allreduce(int((d.state.tool == 0).sum()), op=MPI.SUM) > 0
    d.run(-0.1, on_increment=check)  # unload and lift the punch 0.2 mm: the plate springs back off it
    assert MPI.COMM_WORLD.allreduce(int((d.state.tool == 0).sum()), op=MPI.SUM) == 0
    assert abs(forces[-1]) < 1e-6 * max(abs(f) for f in forces)


def test_strip_dragged_between_flat_tools_carries_mu_times_the_clamping_force():
    """A strip pinched between a flat die and a flat force-controlled holder (F = 1 kN) is
    pulled 2 mm at one end: once it slides, the pull equals mu times the sum of the normal
    forces on both faces (to 1e-8) and 2 mu F (to 1e-4); the holder's forces sum to F at every
    increment, and no tangential force exceeds mu times its normal force."""
    t, mu, F = 1.0, 0.15, 1000.0
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
    d = SemiInverseDriver(model, bcs, [die], [0.0], friction=mu, holder=holder, holder_force=F, prescribed=qbar,
                          controls=Controls(initial_step=0.1, rtol=1e-10, max_iterations=25), verbose=False)
    comm = MPI.COMM_WORLD

    def check(dr):
        assert abs(dr.holder.total(dr._fz_holder) - F) <= 1e-7 * F
        on = dr.state.tool == 0
        p = np.maximum(dr.state.pressure, 0.0) - dr._fz_holder
        ft = np.linalg.norm(dr._friction[:, :2], axis=1)
        # the magnitude uses p of the previous iterate (a fixed point converged with Newton)
        assert np.all(ft <= mu * p * (1 + 1e-6) + 1e-9)
        assert np.all(p[on] >= 0)

    d.run(1.0, on_increment=check)
    pull = _side_sum(d, rect, ("right",), 0)
    normal = comm.allreduce(float((np.maximum(d.state.pressure, 0.0) - d._fz_holder).sum()), op=MPI.SUM)
    assert abs(pull - mu * normal) <= 1e-8 * mu * normal
    assert abs(pull - 2 * mu * F) <= 1e-4 * 2 * mu * F
    assert np.all(d._slipping[d.state.tool == 0])  # the whole strip slides on the die


def test_short_square_cup_draw():
    """The square-cup scene on a coarse quarter blank, 1 mm of stroke: the holder's forces sum
    to 19.6 kN at every increment, no node penetrates a tool by more than 1 % of the thickness,
    the contact set settles within each increment and the punch force grows."""
    s = scene.load(ROOT / "demos" / "square_cup.toml")
    s.mesh.n = 8
    p = DrawingProblem.from_scene(s, verbose=False)
    forces = []

    def check(d):
        assert abs(p.holder_force() - s.tools.blank_holder_force) <= 1e-6 * s.tools.blank_holder_force
        assert p.max_penetration() <= 0.01 * s.material.thickness
        assert d.history[-1].contact["passes"] < d.contact.max_passes
        forces.append(p.punch_force())

    p.driver.run(1.0 / s.tools.stroke, on_increment=check)
    assert forces[-1] > forces[0] > 0
    c = p.in_contact()
    assert c["punch"] > 0 and c["die"] > 0 and c["free"] > 0


@pytest.mark.parametrize("bad", [
    ("tools", "punch_gap", -0.1, "tools.punch_gap"),
    ("tools", "punch_half_width", 40.0, "tools.punch_half_width"),
    ("geometry", "lx", 80.0, "geometry.lx"),
])
def test_bad_tool_scenes_name_the_field(bad):
    import tomllib

    from shellform.errors import InputError

    section, key, value, field = bad
    data = tomllib.loads((ROOT / "demos" / "square_cup.toml").read_text())
    data[section][key] = value
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        scene.from_dict(data)
