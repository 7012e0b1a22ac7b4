"""Finite-strain plasticity (issue 10): the Hencky strain and its derivatives, the section's
consistent tangent at large stretch, and the sheet against closed forms: a strip pulled to a
stretch of 1.5 (nominal stress, Considere's maximum, Lankford ratio), an equibiaxial stretch to
a thickness strain of -0.5, incompressibility at a stretch of 2 and a rigid rotation of a
yielded sheet (shellform.studies.strip; docs/material.md).
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest

from shellform.material import hencky, through_thickness_rule
from shellform.material.section import incompressible_lever, section_response
from shellform.studies import strip
from criterion_checks import assert_section_tangent

STEEL = strip.mild_steel(r=1.5, m=6.0).pack()


def hencky_by_eigenvectors(E):
    """1/2 ln C through the spectral decomposition (the definition), engineering shear."""
    C = np.array([[1 + 2 * E[0], E[2]], [E[2], 1 + 2 * E[1]]])
    c, V = np.linalg.eigh(C)
    e = V @ np.diag(0.5 * np.log(c)) @ V.T
    return np.array([e[0, 0], e[1, 1], 2 * e[0, 1]])


def log_strain(E, T=np.zeros(3)):
    eps, P, W, L = np.zeros(3), np.zeros((3, 3)), np.zeros(16), np.zeros((3, 3))
    assert hencky.log_strain(np.asarray(E, float), eps, P, W)
    hencky.second_order(np.asarray(T, float), E[2], W, L)
    return eps, P, L


@pytest.mark.parametrize("E", [(0.3, -0.1, 0.25), (0.2, 0.2, 0.0), (0.1, 0.1, 1e-9), (1.5, -0.3, 0.1),
                               (1e-4, -2e-4, 3e-4), (0.01, 0.01 + 1e-5, 0.02)])
def test_hencky_strain_and_its_derivatives(E):
    """eps = 1/2 ln C equals the spectral definition, also at (nearly) equal stretches where
    the eigenvectors are undefined; P = d eps/dE and L(T) = T . d2 eps/dE2 equal central
    differences."""
    E = np.array(E)
    T = np.array([0.7, -1.3, 0.4])
    eps, P, L = log_strain(E, T)
    assert np.abs(eps - hencky_by_eigenvectors(E)).max() < 1e-14
    h = 1e-6
    for j in range(3):
        dE = np.zeros(3)
        dE[j] = h
        ep, Pp, _ = log_strain(E + dE)
        em, Pm, _ = log_strain(E - dE)
        assert np.abs((ep - em) / (2 * h) - P[:, j]).max() < 1e-8 * np.abs(P).max()
        assert np.abs((T @ Pp - T @ Pm) / (2 * h) - L[:, j]).max() < 1e-8 * max(np.abs(L).max(), 1.0)
    assert np.abs(L - L.T).max() < 1e-14


def test_hencky_refuses_a_collapsed_element():
    """I + 2E not positive definite (no stretch gives it): refused, nothing written."""
    eps = np.full(3, 7.0)
    assert not hencky.log_strain(np.array([-0.6, 0.1, 0.0]), eps, np.zeros((3, 3)), np.zeros(16))
    assert np.all(eps == 7.0)


def section(em, k, finite, ep_n=None, p_n=None, elastic_tangent=False, lever=0.8):
    zeta, wz = through_thickness_rule(5)
    ep_n = np.zeros((5, 3)) if ep_n is None else ep_n
    p_n = np.zeros(5) if p_n is None else p_n
    S, D, ep, p = np.zeros(6), np.zeros((6, 6)), np.zeros((5, 3)), np.zeros(5)
    st, e33 = section_response(np.asarray(em, float), np.asarray(k, float), 1.0, lever, zeta, wz, ep_n, p_n,
                               STEEL, finite, elastic_tangent, S, D, ep, p)
    return S, D, st, ep, p


@pytest.mark.parametrize("state", ["elastic", "plastic"])
def test_section_tangent_at_large_stretch(state):
    """The layered section's tangent dS/dE = P^T (dT/deps) P + L(T), integrated through the
    thickness, equals central differences of its resultants: elastic (a stretch of 1.5 in one
    step from a state already yielded there, then unloaded) and plastic."""
    em0, k0 = np.array([0.3, -0.05, 0.1]), np.array([0.05, -0.02, 0.03])
    _, _, st, ep_n, p_n = section(em0, k0, True)
    assert st == 5
    step = np.array([0.05, 0.01, -0.02, 0.01, 0.0, 0.01])
    x = np.concatenate([em0, k0]) + step if state == "plastic" else 0.997 * np.concatenate([em0, k0])
    S, D, st, _, _ = section(x[:3], x[3:], True, ep_n, p_n)
    assert st == (5 if state == "plastic" else 0)
    h = 1e-7
    for j in range(6):
        dx = np.zeros(6)
        dx[j] = h
        Sp = section((x + dx)[:3], (x + dx)[3:], True, ep_n, p_n)[0]
        Sm = section((x - dx)[:3], (x - dx)[3:], True, ep_n, p_n)[0]
        assert np.abs((Sp - Sm) / (2 * h) - D[:, j]).max() < 1e-6 * np.abs(D).max()


def test_incompressible_lever_is_the_thickness_of_a_sheet_that_keeps_its_volume():
    """h = t / J: stretches (1.3, 0.9) turned by 30 degrees give J = 1.17 exactly (the strain's
    shear included), dh/dem equals central differences, and a strain no stretch gives (I + 2E
    not positive definite) keeps h = t with a zero derivative."""
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    R = np.array([[c, -s], [s, c]])
    F = R @ np.diag([1.3, 0.9]) @ R.T
    E = 0.5 * (F.T @ F - np.eye(2))
    em = np.array([E[0, 0], E[1, 1], 2 * E[0, 1]])
    d = np.zeros(3)
    assert incompressible_lever(em, 0.8, d) == pytest.approx(0.8 / 1.17, rel=1e-14)
    h = 1e-7
    for j in range(3):
        de = np.zeros(3)
        de[j] = h
        ends = [incompressible_lever(em + sign * de, 0.8, np.zeros(3)) for sign in (1, -1)]
        fd = (ends[0] - ends[1]) / (2 * h)
        assert d[j] == pytest.approx(fd, rel=1e-7)
    assert incompressible_lever(np.array([-0.6, 0.1, 0.0]), 0.8, d) == 0.8 and np.all(d == 0.0)


@pytest.mark.parametrize("state", ["elastic", "plastic"])
def test_section_tangent_with_the_lever_following_the_membrane_strain(state):
    """With h = t / J(em) the section's tangent carries dS/dh (x) dh/dem (unsymmetric): equal to
    central differences of the resultants, the lever moving with em, at a stretch of 1.35
    (elastic and plastic); the term is not negligible there (9e-4 and 3e-3 of D's largest entry,
    which lies in the membrane block; the term lies in the moment rows)."""
    zeta, wz = through_thickness_rule(5)

    def response(x, ep_n, p_n):
        S, D, ep, p, d = np.zeros(6), np.zeros((6, 6)), np.zeros((5, 3)), np.zeros(5), np.zeros(3)
        h = incompressible_lever(x[:3], 1.0, d)
        st, _ = section_response(x[:3].copy(), x[3:].copy(), 1.0, h, zeta, wz, ep_n, p_n, STEEL, True, False, S, D,
                                 ep, p, None, d)
        return S, D, st, ep, p

    x0 = np.array([0.3, -0.05, 0.1, 0.05, -0.02, 0.03])
    _, _, st, ep_n, p_n = response(x0, np.zeros((5, 3)), np.zeros(5))
    assert st == 5
    x = x0 + np.array([0.05, 0.01, -0.02, 0.01, 0.0, 0.01]) if state == "plastic" else 0.997 * x0
    S, D, st, _, _ = response(x, ep_n, p_n)
    assert st == (5 if state == "plastic" else 0)
    fixed = section(x[:3], x[3:], True, ep_n, p_n, lever=incompressible_lever(x[:3], 1.0, np.zeros(3)))[1]
    assert np.abs(D - fixed).max() > 5e-4 * np.abs(D).max()  # the lever's term matters here
    assert_section_tangent(lambda y: response(y, ep_n, p_n)[0], x, D)


def test_small_strains_reproduce_the_small_strain_model():
    """At strain e the finite-strain section differs from the small-strain one by O(e): the
    difference, relative to the resultants, falls tenfold with e (elastic and plastic)."""
    direction = np.array([1.0, -0.4, 0.6, 0.3, 0.2, -0.5])
    ratios = []
    for e in (1e-2, 1e-3):
        x = e * direction
        S1, D1, _, _, _ = section(x[:3], x[3:], True, lever=1.0)
        S0, D0, _, _, _ = section(x[:3], x[3:], False, lever=1.0)
        ratios.append(np.abs(S1 - S0).max() / np.abs(S0).max())
        assert ratios[-1] < 3 * e
    assert 5 < ratios[0] / ratios[1] < 20


@pytest.mark.parametrize("material", ["swift", "power"])
def test_uniaxial_strip_to_a_stretch_of_1_5(material):
    """Homogeneous uniaxial tension: the nominal stress is tau / lambda with the flow curve in
    true stress and logarithmic plastic strain, to solver tolerance; within 0.5 % of the
    rigid-plastic sigma(ln lambda)/lambda; the thickness strain is -ln(lambda)/2 plus the elastic
    part (von Mises)."""
    mat = strip.mild_steel() if material == "swift" else strip.power_law()
    _, rows = strip.strip(mat, 1.5, steps=5)
    assert [round(r["stretch"], 12) for r in rows] == [1.1, 1.2, 1.3, 1.4, 1.5]
    for r in rows:
        lam = r["stretch"]
        exact = strip.uniaxial_kirchhoff(mat, lam) / lam
        assert r["nominal_stress"] == pytest.approx(exact, rel=1e-8)
        packed = mat.pack()
        rigid_plastic = (strip.flow_stress(np.log(lam), packed)[0] if material == "swift"
                         else strip.uniaxial_kirchhoff(mat, lam)) / lam
        assert abs(r["nominal_stress"] / rigid_plastic - 1) < 5e-3
        elastic = -mat.nu * exact * lam / mat.E
        assert r["thickness_strain"] == pytest.approx(-0.5 * (np.log(lam) - exact * lam / mat.E) + elastic, rel=1e-8)


@pytest.mark.parametrize("material", ["swift", "power"])
def test_force_peaks_at_considere(material):
    """The free strip (only its end pulled): the force is largest at the increment closest to
    Considere's true strain (Swift n - eps0, power law 1/N), within one step. (Whether the perfect
    strip then necks depends on round-off; the study's finer strip does, docs/material.md.)"""
    mat = strip.mild_steel() if material == "swift" else strip.power_law()
    _, rows = strip.strip(mat, 1.4, homogeneous=False, steps=40, n=2)
    e = np.log([r["stretch"] for r in rows])
    force = np.array([r["nominal_stress"] for r in rows])
    i = int(np.argmax(force))
    assert 0 < i < len(rows) - 1
    assert abs(e[i] - strip.considere_strain(mat)) <= e[i + 1] - e[i]


@pytest.mark.parametrize("r", [0.5, 1.5, 3.0])
@pytest.mark.parametrize("m", [2.0, 8.0])
def test_lankford_ratio_of_logarithmic_strains(r, m):
    """ln(w/w0) / ln(t/t0) = r within 1 % at a stretch of 1.5 (the total strains, elastic parts
    included)."""
    _, rows = strip.strip(strip.mild_steel(r, m), 1.5, steps=3)
    last = rows[-1]
    assert last["width_strain"] / last["thickness_strain"] == pytest.approx(r, rel=1e-2)


def test_equibiaxial_stretch():
    """Equibiaxial stretch to a thickness strain of -0.5: tau follows Hill 1979's equibiaxial
    yield stress to solver tolerance, and within 0.5 % of its rigid-plastic value at the true
    strain (r 1.5, m 8)."""
    mat = strip.mild_steel(1.5, 8.0)
    lam = np.exp(0.25)
    tau, e33 = strip.equibiaxial(mat, lam)
    assert e33 == pytest.approx(-0.5, abs=5e-3)
    assert tau == pytest.approx(strip.equibiaxial_kirchhoff(mat, lam), rel=1e-8)
    assert tau == pytest.approx(strip.equibiaxial_kirchhoff(mat, lam, elastic=False), rel=5e-3)


def test_plastic_incompressibility_at_a_stretch_of_2():
    """ln(lambda1 lambda2 lambda3), from the deformed strip and its thickness, equals the elastic
    volume change (1 - 2 nu) tau / E: the plastic part changes no volume (to 1e-10)."""
    mat = strip.mild_steel(1.5, 2.0)
    p, rows = strip.strip(mat, 2.0, steps=10)
    last = rows[-1]
    lnJ = np.log(2.0) + last["width_strain"] + last["thickness_strain"]
    tau = 2.0 * last["nominal_stress"]
    assert abs(lnJ - (1 - 2 * mat.nu) * tau / mat.E) < 1e-10
    assert p.model.p_n.min() > 0.6  # far into the plastic range


def test_rigid_rotation_of_a_yielded_sheet(turned_states):
    """A strip stretched by 1.3 (yielded) and then turned rigidly by 100 degrees about an
    inclined axis: resultants, plastic strains, equivalent plastic strain and thickness stretch
    are unchanged to 1e-10."""
    p, _ = strip.strip(strip.mild_steel(1.5, 6.0), 1.3, steps=3)
    model = p.model
    states = turned_states(p)
    assert model.p.min() > 0.1
    for a, b in zip(*states):
        assert np.abs(a - b).max() <= 1e-10 * max(np.abs(a).max(), 1.0)
