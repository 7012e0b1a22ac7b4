"""Planar anisotropy (issue 33): Hill 1948 from r0, r45, r90 (or the yield stresses) with a
rolling direction, against its closed forms; the consistent tangent with a turned rolling
direction against finite differences; a yielded anisotropic strip turned rigidly; the
registration of the yield functions; input errors naming the field."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

import shellform.material
from criterion_checks import assert_derivatives, assert_section_tangent
from material_data import AA2090, AA2090_DATA, esaform_data
from shellform import effects, scene
from shellform.errors import InputError
from shellform.material import CRITERION_
from shellform.material import (
    SheetMaterial, criteria, flow_stress, hill48, point, return_map, section_response, through_thickness_rule,
    yld2000,
)

E, NU, SY = 200e3, 0.3, 250.0
EY = SY / E
STEEL = {"r0": 1.79, "r45": 1.51, "r90": 2.27}  # NUMISHEET'93 mild steel
ALUMINIUM = {"r0": 0.71, "r45": 0.58, "r90": 0.70}
ANGLES = range(0, 91, 15)
POLY6_DATA = esaform_data()  # Poly6 fitted to the ESAFORM 2021 AA6016-T4 data (the demo's)


def hill48_material(values, rolling_direction=0.0, hardening="swift", **curve):
    curve = curve or dict(K=500.0, eps0=0.02, n=0.25)
    return SheetMaterial(E, NU, hardening=hardening, yield_function="hill48", yield_parameters=values,
                         rolling_direction=rolling_direction, **curve)


def yld2000_material(rolling_direction=0.0, perfect=False, alpha=None, a=8.0):
    curve = dict(K=SY, eps0=1.0, n=0.0) if perfect else dict(K=500.0, eps0=0.02, n=0.25)
    return SheetMaterial(E, NU, hardening="swift", yield_function="yld2000", rolling_direction=rolling_direction,
                         yield_parameters={"alpha": AA2090 if alpha is None else alpha, "a": a}, **curve)


def perfect(values, rolling_direction=0.0):
    return hill48_material(values, rolling_direction, K=SY, eps0=1.0, n=0.0).pack()


@pytest.mark.parametrize("values", [STEEL, ALUMINIUM], ids=["steel", "aluminium"])
@pytest.mark.parametrize("theta", ANGLES)
def test_hill48_lankford_and_yield_stress_against_closed_forms(values, theta):
    """Uniaxial tension along x with the rolling direction at -theta from x (the load at theta
    to the rolling direction): r(theta) and sigma(theta)/sigma0 of the material point equal
    Hill's closed forms to 1e-8; at 0, 45, 90 degrees r is the given r0, r45, r90."""
    mat = hill48_material(values, rolling_direction=-theta).pack()
    r = point.lankford(mat, 0.05)
    assert r == pytest.approx(hill48.r_theta(values, theta), rel=1e-8)
    if theta in (0, 45, 90):
        assert r == pytest.approx(values[f"r{theta}"], rel=1e-8)
    ratio = point.stress_ratio_yield(perfect(values, -theta), 0.0) / SY
    assert ratio == pytest.approx(hill48.sigma_theta(values, theta), rel=1e-8)


def test_hill48_from_yield_stresses():
    """Given sigma0, sigma45, sigma90, sigma_b the material point yields at them: uniaxial at
    0, 45, 90 degrees to the rolling direction and balanced biaxially, to 1e-8."""
    stresses = {"sigma0": 1.0, "sigma45": 0.96, "sigma90": 1.04, "sigma_b": 1.02}
    for theta, key in ((0, "sigma0"), (45, "sigma45"), (90, "sigma90")):
        mat = perfect(stresses, -theta)
        assert point.stress_ratio_yield(mat, 0.0) / SY == pytest.approx(stresses[key], rel=1e-8)
    assert point.stress_ratio_yield(perfect(stresses, 20.0), 1.0) / SY == pytest.approx(1.02, rel=1e-8)


@pytest.mark.parametrize("r", [0.5, 1.0, 1.79])
def test_hill48_with_equal_r_is_hill79_with_m_2(r):
    """r0 = r45 = r90 = r (any rolling direction): the same yield function, gradient and
    Hessian as Hill 1979 with m = 2, and the same return mapping, to rounding."""
    h48 = hill48_material({"r0": r, "r45": r, "r90": r}, rolling_direction=37.0).pack()
    h79 = SheetMaterial(E, NU, r, 2.0, "swift", K=500.0, eps0=0.02, n=0.25).pack()
    rng = np.random.default_rng(3)
    for s in rng.normal(size=(20, 3)) * SY:
        a48, a79 = np.array(criteria.yield_function(*s, h48, 2)), np.array(criteria.yield_function(*s, h79, 2))
        assert np.abs(a48 - a79).max() <= 1e-13 * np.abs(a79).max()
    ep_n, p_n = np.array([0.003, -0.001, 0.002]), 0.004
    for d in rng.normal(size=(6, 3)):
        e = ep_n + 3 * EY * d / np.linalg.norm(d)
        out = []
        for mat in (h48, h79):
            s, D, ep = np.zeros(3), np.zeros((3, 3)), np.zeros(3)
            p, st = return_map(e, ep_n, p_n, mat, s, D, ep)
            out.append((st, p, s, D, ep))
        assert out[0][0] == out[1][0] == 1
        assert out[0][1] == pytest.approx(out[1][1], rel=1e-12)
        for a, b in zip(out[0][2:], out[1][2:]):
            assert np.abs(a - b).max() <= 1e-11 * np.abs(b).max()


def test_each_registered_criterion_is_dispatched_to_its_file():
    """The packed id of every name in CRITERIA is its place there and reaches that criterion's own
    yield_function (the four give different values at this stress)."""
    mats = {"hill79": SheetMaterial(E, NU, 1.7, 6.0, "swift", K=500.0, eps0=0.02, n=0.25).pack(),
            "hill48": hill48_material(STEEL, 25.0).pack(), "yld2000": yld2000_material(25.0).pack(),
            "poly6": SheetMaterial(E, NU, hardening="swift", K=500.0, eps0=0.02, n=0.25, yield_function="poly6",
                                   rolling_direction=25.0, yield_parameters=POLY6_DATA).pack()}
    assert set(mats) == set(criteria.CRITERIA)
    s = np.array([210.0, -80.0, 55.0])
    values = [criteria.yield_function(*s, mat, 0)[0] for mat in mats.values()]
    assert min(abs(x - y) for i, x in enumerate(values) for y in values[i + 1:]) > 1.0
    for name, mat in mats.items():
        own = criteria.CRITERIA[name].yield_function(*s, mat, 2)
        assert criteria.yield_function(*s, mat, 2) == own
        assert mat[CRITERION_] == list(criteria.CRITERIA).index(name)


def test_the_dispatch_is_generated_from_the_registry():
    """criteria.dispatch_source over n modules, run as plain Python over stand-ins: every id
    0..n-1 reaches its own module (id 0 the fall-through); the registry's modules are those
    REGISTRY names."""
    stand_ins = tuple(SimpleNamespace(yield_function=lambda *args, i=i: i) for i in range(5))
    namespace = {"CRITERION_": CRITERION_, **{f"criterion_{i}": m for i, m in enumerate(stand_ins)}}
    exec(criteria.dispatch_source(stand_ins), namespace)
    mat = np.zeros(CRITERION_ + 1)
    for i in range(len(stand_ins)):
        mat[CRITERION_] = float(i)
        assert namespace["yield_function"](0.0, 0.0, 0.0, mat, 2) == i
    assert criteria.MODULES == tuple(getattr(shellform.material, name) for name in criteria.REGISTRY)


def test_the_scene_keys_of_each_criterion_come_from_its_file():
    """The scene's yield functions and their keys are the registered files' NAME and PARAMETERS;
    every key is a field of [material] that takes its meaning with the effect 'anisotropy'."""
    assert scene.YIELD_FUNCTIONS == tuple(criteria.CRITERIA) == tuple(m.NAME for m in criteria.MODULES)
    assert scene.YIELD_PARAMETERS == {m.NAME: m.PARAMETERS for m in criteria.MODULES}
    material_fields = {f.name for f in dataclasses.fields(scene.Material)}
    anisotropy_keys = effects.EFFECTS["anisotropy"].keys
    for m in criteria.MODULES:
        for key in m.PARAMETERS:
            assert key in material_fields, (m.NAME, key)
            assert f"material.{key}" in anisotropy_keys, (m.NAME, key)
            assert key in ("r", "m") or key in scene.ANISOTROPY_PARAMETERS + scene.ANISOTROPY_LISTS, (m.NAME, key)


DIRECTIONS = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, -0.3, 0.8],
              [0.2, 0.5, -1.5], [-1.0, 0.4, 0.6], [0.0, 0.0, 1.0]]


@pytest.mark.parametrize("criterion", ["hill48", "yld2000", "poly6"])
@pytest.mark.parametrize("hardening", ["perfect", "swift"])
def test_consistent_tangent_with_a_turned_rolling_direction(criterion, hardening):
    """Hill 1948 (steel r values), Yld2000-2d (AA2090-T3) and Poly6 (fitted to AA6016-T4),
    rolling direction 30 degrees: D_out equals the central difference of return_map's stress to
    1e-6, and is symmetric."""
    if criterion == "hill48":
        mat = perfect(STEEL, 30.0) if hardening == "perfect" else hill48_material(STEEL, 30.0).pack()
    elif criterion == "yld2000":
        mat = yld2000_material(30.0, perfect=hardening == "perfect").pack()
    else:
        curve = dict(K=SY, eps0=1.0, n=0.0) if hardening == "perfect" else dict(K=500.0, eps0=0.02, n=0.25)
        mat = SheetMaterial(E, NU, hardening="swift", yield_function="poly6", rolling_direction=30.0,
                            yield_parameters=POLY6_DATA, **curve).pack()
    ey = flow_stress(0.0, mat)[0] / E
    ep_n, p_n = np.array([0.003, -0.001, 0.002]), 0.004
    h = 1e-5 * ey

    def rmap(e):
        s, D, ep = np.zeros(3), np.zeros((3, 3)), np.zeros(3)
        p, st = return_map(e, ep_n, p_n, mat, s, D, ep)
        return s, D, st

    for d in DIRECTIONS:
        e = ep_n + 3 * ey * np.array(d) / np.linalg.norm(d)
        _, D, st = rmap(e)
        assert st == 1
        D_fd = np.zeros((3, 3))
        for j in range(3):
            de = np.zeros(3)
            de[j] = h
            D_fd[:, j] = (rmap(e + de)[0] - rmap(e - de)[0]) / (2 * h)
        assert np.abs(D - D_fd).max() <= 1e-6 * np.abs(D).max()
        np.testing.assert_allclose(D, D.T, atol=1e-12 * E)


@pytest.mark.parametrize("criterion", ["hill48", "yld2000"])
@pytest.mark.parametrize("finite", [False, True])
def test_section_tangent_with_a_turned_rolling_direction(criterion, finite):
    """The layered section (5 layers, all plastic) of Hill 1948 and of Yld2000-2d with the
    rolling direction at 30 degrees: its tangent equals central differences of its resultants
    (small and finite strains)."""
    mat = (hill48_material(STEEL, 30.0) if criterion == "hill48" else yld2000_material(30.0)).pack()
    zeta, wz = through_thickness_rule(5)

    def section(x, ep_n, p_n):
        S, D, ep, p = np.zeros(6), np.zeros((6, 6)), np.zeros((5, 3)), np.zeros(5)
        st, _ = section_response(x[:3].copy(), x[3:].copy(), 1.0, 0.8, zeta, wz, ep_n, p_n, mat, finite, False,
                                 S, D, ep, p)
        return S, D, st, ep, p

    x0 = np.array([0.3, -0.05, 0.1, 0.05, -0.02, 0.03])
    _, _, st, ep_n, p_n = section(x0, np.zeros((5, 3)), np.zeros(5))
    assert st == 5
    x = x0 + np.array([0.05, 0.01, -0.02, 0.01, 0.0, 0.01])
    S, D, st, _, _ = section(x, ep_n, p_n)
    assert st == 5
    assert_section_tangent(lambda y: section(y, ep_n, p_n)[0], x, D)


def test_rigid_rotation_of_a_yielded_anisotropic_sheet(turned_states):
    """A strip of Hill 1948 (steel r values, rolling direction 30 degrees from x) stretched by
    1.3 (yielded), then turned rigidly by 100 degrees about an inclined axis: resultants,
    plastic strains, equivalent plastic strain and thickness stretch are unchanged to 1e-10
    (the anisotropy axes are material directions of the total-Lagrangian strains)."""
    from shellform.studies import strip

    mat = SheetMaterial(E=206e3, nu=0.3, hardening="swift", K=565.32, eps0=0.007117, n=0.2589,
                        yield_function="hill48", yield_parameters=STEEL, rolling_direction=30.0)
    p, _ = strip.strip(mat, 1.3, steps=3)
    model = p.model
    states = turned_states(p)
    assert model.p.min() > 0.1
    assert np.abs(states[0][1][..., 2]).max() > 1e-3  # the turned axes give a plastic shear strain
    for a, b in zip(*states):
        assert np.abs(a - b).max() <= 1e-10 * max(np.abs(a).max(), 1.0)


@pytest.mark.parametrize("values, field", [
    ({"r0": 1.5, "r45": 1.2}, "material.r90"),
    ({"r0": -1.5, "r45": 1.2, "r90": 2.0}, "material.r0"),
    ({"r0": 1.5, "r45": 0.0, "r90": 2.0}, "material.r45"),
    ({"r0": 1.5, "r45": 1.2, "r90": 2.0, "sigma0": 1.0}, "material.r0"),
    ({"sigma0": 1.0, "sigma45": 1.0, "sigma90": 1.0}, "material.sigma_b"),
    ({"sigma0": 1.0, "sigma45": 3.0, "sigma90": 1.0, "sigma_b": 1.0}, "material.sigma45"),
    ({"sigma0": 1.0, "sigma45": 1.0, "sigma90": 1.0, "sigma_b": 0.4}, "material.sigma_b"),
])
def test_hill48_input_errors_name_the_field(values, field):
    with pytest.raises(InputError) as err:
        hill48_material(values)
    assert err.value.field == field


SHEET = ["bending", "membrane", "geometric_nonlinearity", "plasticity"]
SWIFT = {"E": 206000.0, "nu": 0.3, "thickness": 0.78, "hardening": "swift", "K": 565.32, "eps0": 0.007117,
         "n": 0.2589}


def test_scene_material_with_hill48_and_a_rolling_direction():
    """[material] yield_function = "hill48", r0, r45, r90, rolling_direction: the scene's
    material packs Hill's P matrix and the turned axes."""
    s = scene.from_dict({"effects": SHEET + ["anisotropy"],
                         "material": {**SWIFT, "yield_function": "hill48", "r0": 1.79, "r45": 1.51, "r90": 2.27,
                                      "rolling_direction": 90.0}})
    mat = s.hill79().pack()
    from shellform.material import COS_, PAR_, ROTATED_, SIN_
    F, G, H, N = hill48.coefficients(STEEL)
    np.testing.assert_allclose(mat[PAR_:PAR_ + 4], [G + H, -H, F + H, 2 * N], rtol=1e-15)
    assert (mat[ROTATED_], mat[SIN_]) == (1.0, 1.0) and abs(mat[COS_]) < 1e-16


@pytest.mark.parametrize("material, effects, field", [
    ({"yield_function": "hill48", "r0": 1.8, "r45": 1.5, "r90": 2.3}, SHEET, "material.yield_function"),
    ({"rolling_direction": 45.0}, SHEET, "material.rolling_direction"),
    ({"yield_function": "barlat89"}, SHEET + ["anisotropy"], "material.yield_function"),
    ({"yield_function": "hill48", "r0": 1.8, "r45": 1.5}, SHEET + ["anisotropy"], "material.r90"),
    ({"r0": 1.8}, SHEET + ["anisotropy"], "material.r0"),
    ({"yield_function": "hill48", "r": 1.8, "r0": 1.8, "r45": 1.5, "r90": 2.3}, SHEET + ["anisotropy"],
     "material.r"),
    ({"yield_function": "hill48", "r0": -1.8, "r45": 1.5, "r90": 2.3}, SHEET + ["anisotropy"], "material.r0"),
])
def test_scene_anisotropy_errors_name_the_field(material, effects, field):
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": effects, "material": {**SWIFT, **material}})
    assert err.value.field == field


# ---- Yld2000-2d --------------------------------------------------------------------------------

def yld2000_by_eigenvalues(s, alpha, a):
    """sigma_bar by its definition: the principal values of X' = L' s and X'' = L'' s."""
    L1, L2 = yld2000.matrices(alpha)

    def principal(X):
        return np.linalg.eigvalsh(np.array([[X[0], X[2]], [X[2], X[1]]]))[::-1]

    x1, x2 = principal(L1 @ s), principal(L2 @ s)
    phi = abs(x1[0] - x1[1]) ** a + abs(2 * x2[1] + x2[0]) ** a + abs(2 * x2[0] + x2[1]) ** a
    return (phi / 2) ** (1 / a)


def test_yld2000_value_and_derivatives():
    """sigma_bar equals the definition through eigenvalues to 1e-13; the gradient and Hessian
    equal central differences (1e-7); Euler: s . a = sigma_bar."""
    mat = yld2000_material().pack()
    rng = np.random.default_rng(5)
    stresses = list(rng.normal(size=(12, 3))) + [np.array([1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])]
    for s in stresses:
        assert criteria.yield_function(*s, mat, 0)[0] == pytest.approx(yld2000_by_eigenvalues(s, AA2090, 8.0), rel=1e-13)
    assert_derivatives(mat, stresses)


def test_yld2000_aa2090_reproduces_the_data_it_was_fitted_to():
    """Barlat et al. 2003's AA2090-T3 alphas (a = 8) give back the eight data they were fitted
    to, sigma0, sigma45, sigma90, sigma_b and r0, r45, r90, r_b, to the 4 digits the alphas are
    published with (here within 3e-3 relative), as closed forms of the yield function and as
    a material point: r at 0, 45, 90 degrees by uniaxial tension, sigma(theta) by the
    perfectly plastic point, sigma_b by the equibiaxial path."""
    closed = yld2000.uniaxial_and_biaxial(AA2090, 8.0)
    for k, v in AA2090_DATA.items():
        assert closed[k] == pytest.approx(v, rel=3e-3), k
    for theta in (0, 45, 90):
        r = point.lankford(yld2000_material(-theta).pack(), 0.05)
        assert r == pytest.approx(closed[f"r{theta}"], rel=1e-8)
        ratio = point.stress_ratio_yield(yld2000_material(-theta, perfect=True).pack(), 0.0) / SY
        assert ratio == pytest.approx(closed[f"sigma{theta}"], rel=1e-8)
    biaxial = point.stress_ratio_yield(yld2000_material(perfect=True).pack(), 1.0) / SY
    assert biaxial == pytest.approx(closed["sigma_b"], rel=1e-8)


@pytest.mark.parametrize("theta", ANGLES)
def test_yld2000_lankford_and_yield_stress_at_every_15_degrees(theta):
    """AA2090-T3: the material point's r(theta) (uniaxial tension) and sigma(theta)/sigma_bar
    (perfectly plastic) equal the closed forms of the yield function to 1e-8 at 0, 15, .., 90
    degrees to the rolling direction; the Lankford value swings from 0.21 to 1.58 and back."""
    sigma, r = yld2000.uniaxial(AA2090, 8.0, theta)
    assert point.lankford(yld2000_material(-theta).pack(), 0.05) == pytest.approx(r, rel=1e-8)
    ratio = point.stress_ratio_yield(yld2000_material(-theta, perfect=True).pack(), 0.0) / SY
    assert ratio == pytest.approx(sigma, rel=1e-8)
    assert 0.2 < r < 1.6 and 0.8 < sigma < 1.01


def test_yld2000_fit_recovers_the_published_alphas():
    """The alphas fitted to AA2090-T3's eight data (a = 8) are the published ones to within
    the data's and the alphas' 4 digits (2e-3 absolute), and meet the data to 1e-8; the
    alphas of an exact data set are recovered to 1e-7 (scaled by its sigma0)."""
    fitted = yld2000.fit(AA2090_DATA, 8.0)
    np.testing.assert_allclose(fitted, AA2090, atol=2e-3)
    got = yld2000.uniaxial_and_biaxial(fitted, 8.0)
    for k, v in AA2090_DATA.items():
        assert got[k] == pytest.approx(v, rel=1e-8)
    exact = yld2000.uniaxial_and_biaxial(AA2090, 8.0)
    # (sigma_bar is normalised to sigma0: the exact set's sigma0 is 0.99996, the alphas scale with it)
    np.testing.assert_allclose(yld2000.fit(exact, 8.0), exact["sigma0"] * np.array(AA2090), atol=1e-7)


def test_yld2000_with_unit_alphas_is_isotropic():
    """alpha = 1 (all): Hosford's isotropic criterion; with a = 2 von Mises, i.e. Hill 1979
    with r = 1, m = 2, to rounding."""
    iso = yld2000_material(alpha=[1.0] * 8, a=2.0).pack()
    mises = SheetMaterial(E, NU, 1.0, 2.0, "swift", K=500.0, eps0=0.02, n=0.25).pack()
    for s in np.random.default_rng(7).normal(size=(10, 3)):
        a, b = np.array(criteria.yield_function(*s, iso, 2)), np.array(criteria.yield_function(*s, mises, 2))
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()


@pytest.mark.parametrize("values, field", [
    ({"alpha": AA2090[:7], "a": 8.0}, "material.alpha"),
    ({"alpha": AA2090}, "material.a"),
    ({"alpha": AA2090, "a": 1.5}, "material.a"),
    ({"a": 8.0}, "material.alpha"),
    ({"alpha": AA2090[:6] + [0.0, 0.0], "a": 8.0}, "material.alpha"),
    ({"alpha": AA2090, "a": 8.0, "r0": 0.3}, "material.r0"),
    ({**AA2090_DATA, "r_b": -1.0, "a": 8.0}, "material.r_b"),
    ({k: v for k, v in AA2090_DATA.items() if k != "sigma45"} | {"a": 8.0}, "material.sigma45"),
])
def test_yld2000_input_errors_name_the_field(values, field):
    """Missing or malformed alphas, an exponent below 2, a set whose yield surface is open
    (alpha7 = alpha8 = 0: no yield in pure shear), both alphas and fit data, bad fit data."""
    with pytest.raises(InputError) as err:
        SheetMaterial(E, NU, hardening="swift", K=500.0, eps0=0.02, n=0.25, yield_function="yld2000",
                      yield_parameters=values)
    assert err.value.field == field


def test_scene_material_with_yld2000_fitted_from_the_data():
    s = scene.from_dict({"effects": SHEET + ["anisotropy"],
                         "material": {**SWIFT, "yield_function": "yld2000", "a": 8.0, **AA2090_DATA}})
    from shellform.material import PAR_
    np.testing.assert_allclose(s.hill79().pack()[PAR_:PAR_ + 11], yld2000.pack(yld2000.fit(AA2090_DATA, 8.0), 8.0),
                               rtol=1e-12)
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": SHEET + ["anisotropy"],
                         "material": {**SWIFT, "yield_function": "hill48", "r0": 1.0, "r45": 1.0, "r90": 1.0,
                                      "alpha": AA2090}})
    assert err.value.field == "material.alpha"


@pytest.mark.parametrize("criterion", ["hill48", "yld2000"])
def test_assembled_tangent_with_a_turned_rolling_direction(criterion):
    """A strip of Hill 1948 (steel) or Yld2000-2d (AA2090-T3), rolling direction 30 degrees from
    its axis, finite strains, pulled at one end to a stretch of 1.2; at a state a little further
    on (every plastic layer loading, nothing committed) the assembled tangent equals a central
    difference of the assembled residual, to 1e-5 of its largest entry."""
    from shellform.studies import strip

    params = ({"yield_function": "hill48", "yield_parameters": STEEL} if criterion == "hill48" else
              {"yield_function": "yld2000", "yield_parameters": {"alpha": AA2090, "a": 8.0}})
    mat = SheetMaterial(E=206e3, nu=0.3, hardening="swift", K=565.32, eps0=0.007117, n=0.2589,
                        rolling_direction=30.0, **params)
    p, _ = strip.strip(mat, 1.2, homogeneous=False, steps=4, n=2)
    d = p.driver
    x0 = 1.003 * d.q.x.array  # further along the pull: the layers keep loading

    def residual(x):
        d.q.x.array[:] = x
        _, _, ev = d.residual(1.0, tangent=True)
        assert not ev.failed
        return d.b.getArray().copy(), ev

    _, ev = residual(x0)
    assert ev.plastic_layers > 0
    A = d.A.copy().convert("dense").getDenseArray()
    free = np.setdiff1d(np.arange(x0.size), d.bc_dofs)
    h = 1e-7 * np.abs(x0).max()
    scale = np.abs(A[free][:, free]).max()
    for j in np.random.default_rng(0).choice(free, 12, replace=False):
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        col = (residual(xp)[0] - residual(xm)[0]) / (2 * h)
        assert np.abs(col[free] - A[free, j]).max() <= 1e-5 * scale


def test_a_planar_isotropic_criterion_ignores_the_rolling_direction():
    """Hill 1979 is planar isotropic: a rolling direction packs the same material (no turn);
    Hill 1948 with a turned rolling direction is turned, with one a whole turn of 180 degrees
    away is not."""
    from shellform.material import ROTATED_

    h79 = [SheetMaterial(E, NU, 1.7, 6.0, "swift", K=500.0, eps0=0.02, n=0.25, rolling_direction=rd).pack()
           for rd in (0.0, 30.0)]
    np.testing.assert_array_equal(h79[0], h79[1])
    assert hill48_material(STEEL, 30.0).pack()[ROTATED_] == 1.0
    np.testing.assert_array_equal(hill48_material(STEEL, 180.0).pack(), hill48_material(STEEL, 0.0).pack())
