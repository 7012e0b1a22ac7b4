"""A pressure that varies over the plan, and one per unit area of the curved surface
(forms/loads.py, PressureField): both routes integrate the field the scene writes."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import math

import numpy as np
import pytest

from shellform import linear, scene
from shellform.errors import InputError
from shellform.nonlinear.problem import SheetProblem

D_ONE = {"E": 12 * (1 - 0.09) / 0.01**3, "nu": 0.3, "thickness": 0.01}  # D = 1
SQUARE = {"geometry": {"lx": 1.0, "ly": 1.0, "region": "quarter"}, "mesh": {"n": 12},
          "supports": {"left": "symmetry", "bottom": "symmetry", "right": "simply_supported",
                       "top": "simply_supported"}}
SHEET = ["bending", "membrane", "geometric_nonlinearity"]


def test_a_sine_pressure_on_the_simply_supported_square_gives_navier_s_one_term():
    """p = p0 cos(pi x) cos(pi y) on the unit square centred at the origin, simply supported:
    w0 = p0 a^4 / (4 pi^4 D) exactly (one term of Navier's series). The linear plate and the
    nonlinear sheet at a small load give it within 0.05 % on the 12 x 12 quarter, and each
    other to 1e-8; the same scenes with a uniform pressure give the uniform plate's 0.00406."""
    shape = "cos(pi*x)*cos(pi*y)"
    plate = scene.from_dict({**SQUARE, "effects": ["bending"], "material": D_ONE,
                             "loads": {"pressure": 1.0, "pressure_shape": shape}})
    w_plate = linear.solve(plate).value("w")
    p0 = 1e-5
    sheet = scene.from_dict({**SQUARE, "effects": SHEET, "material": D_ONE,
                             "loads": {"pressure": p0, "pressure_shape": shape},
                             "process": {"initial_step": 1.0, "max_step": 1.0}})
    p = SheetProblem.from_scene(sheet, verbose=False)
    p.driver.run(1.0)
    w_sheet = p.value("w", 0.0, 0.0) / p0
    exact = 1 / (4 * math.pi**4)
    assert w_plate == pytest.approx(exact, rel=5e-4) and w_sheet == pytest.approx(w_plate, rel=1e-8)
    uniform = linear.solve(scene.from_dict({**SQUARE, "effects": ["bending"], "material": D_ONE,
                                            "loads": {"pressure": 1.0}})).value("w")
    assert uniform == pytest.approx(0.00406235, rel=5e-4)


@pytest.mark.parametrize("per, shape", [("surface", ""), ("plan", ""), ("surface", "1 + x*y")])
def test_a_pressure_per_unit_surface_area_loads_the_curved_surface_s_area(per, shape):
    """On z0 = 0.3 (x^2 - y^2) + 0.2 x y the sheet's load vector (its w rows, whose shape functions
    sum to one) totals the integral of p shape J over the plan, J = sqrt(1 + |grad z0|^2) per unit
    surface area and 1 per unit plan area (a 40 x 40 Gauss rule here)."""
    z0 = "0.3*(x**2 - y**2) + 0.2*x*y"
    s = scene.from_dict({**SQUARE, "effects": SHEET + ["shallow_curvature"], "mesh": {"n": 8},
                         "material": D_ONE, "surface": {"z0": z0},
                         "supports": {**SQUARE["supports"], "right": "clamped", "top": "clamped"},
                         "loads": {"pressure": 1.0, "pressure_per": per, "pressure_shape": shape}})
    p = SheetProblem.from_scene(s, verbose=False)
    total = p.model.pressure_vectors.reshape(-1, 3, 9)[:, :, 2].sum()
    g, w = np.polynomial.legendre.leggauss(40)
    x, W = 0.25 * (g + 1), 0.25 * w
    X, Y = np.meshgrid(x, x)
    J = np.sqrt(1 + (0.6 * X + 0.2 * Y) ** 2 + (0.2 * X - 0.6 * Y) ** 2) if per == "surface" else 1.0
    f = (1 + X * Y) if shape else 1.0
    exact = float((J * f * np.outer(W, W)).sum())
    assert total == pytest.approx(exact, rel=1e-10)
    assert (total > 0.2505) == (per == "surface")  # the curved surface's area exceeds its plan's 0.25


@pytest.mark.parametrize("loads, field", [
    ({"pressure": 1.0, "pressure_shape": "x +"}, "loads.pressure_shape"),
    ({"pressure": 1.0, "pressure_shape": "__import__('os')"}, "loads.pressure_shape"),
    ({"pressure": 1.0, "pressure_per": "area"}, "loads.pressure_per"),
])
def test_a_bad_pressure_field_is_refused_naming_it(loads, field):
    with pytest.raises(InputError) as err:
        scene.from_dict({**SQUARE, "effects": ["bending"], "material": D_ONE, "loads": loads})
    assert err.value.field == field, str(err.value)


def test_a_pressure_shape_that_is_not_finite_on_the_mesh_is_refused_before_any_solve():
    """1/x is finite where the scene's check samples it, not on the symmetry line x = 0."""
    s = scene.from_dict({**SQUARE, "effects": ["bending"], "material": D_ONE,
                         "loads": {"pressure": 1.0, "pressure_shape": "1/x"}})
    with pytest.raises(InputError) as err:
        linear.solve(s)
    assert err.value.field == "loads.pressure_shape" and "not finite at (0," in str(err.value)
