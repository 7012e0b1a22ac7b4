"""Hill 1979 plane-stress plasticity against closed forms (shellform.material)."""

import math

import numpy as np
import pytest

from shellform.errors import InputError
from shellform.material import (
    Hill79Material, elastic_section, equivalent_stress, flow_stress, point, return_map,
    section_response, thickness_strain, through_thickness_rule, yield_derivatives,
)
from shellform.material import A_, B_, C_, COS_, E_, LAW_, NU_, PAR_
from shellform.material.plane_stress import return_core as _return_core

E, NU, SY = 200e3, 0.3, 250.0
EY = SY / E
MS = [1.5, 2.0, 2.5, 8.0]
RS = [0.5, 1.0, 1.5, 3.0]
GRID = [(m, r) for m in MS for r in RS]


def power(m, r, n=5.0):
    return Hill79Material(E, NU, r, m, "power", yield_stress=SY, n=n).pack()


def perfect(m, r, nu=NU):
    return Hill79Material(E, nu, r, m, "swift", K=SY, eps0=1.0, n=0.0).pack()


def swift(m, r):
    return Hill79Material(E, NU, r, m, "swift", K=500.0, eps0=0.02, n=0.25).pack()


def compliance(nu=NU):
    return np.array([[1.0, -nu, 0.0], [-nu, 1.0, 0.0], [0.0, 0.0, 2.0 * (1.0 + nu)]]) / E


def rmap(e, mat, ep_n=np.zeros(3), p_n=0.0):
    s, D, ep = np.zeros(3), np.zeros((3, 3)), np.zeros(3)
    p, status = return_map(np.asarray(e, float), np.asarray(ep_n, float), p_n, mat, s, D, ep)
    return s, D, ep, p, status


# ---- yield function --------------------------------------------------------------------------

@pytest.mark.parametrize("m, r", GRID)
def test_uniaxial_yield_equals_sigma_bar(m, r):
    """Uniaxial stress in any in-plane direction yields at s1 = sigma_bar (planar isotropy)."""
    assert point.stress_ratio_yield(power(m, r), 0.0) == pytest.approx(SY, rel=1e-10)
    for th in np.linspace(0.0, math.pi, 7):
        c, s = math.cos(th), math.sin(th)
        s_uni = SY * np.array([c * c, s * s, c * s])
        assert equivalent_stress(s_uni, r, m) == pytest.approx(SY, rel=1e-13)
    path = point.uniaxial(perfect(m, r), 20 * EY, 10)  # strain-driven, perfectly plastic
    np.testing.assert_allclose(path.stress[-1], [SY, 0.0, 0.0], atol=1e-10 * SY)


@pytest.mark.parametrize("m, r", GRID)
def test_equibiaxial_yield(m, r):
    sb = SY * (2.0 * (1.0 + r)) ** (1.0 / m) / 2.0
    assert point.stress_ratio_yield(power(m, r), 1.0) == pytest.approx(sb, rel=1e-10)


@pytest.mark.parametrize("r, m, table", [
    (1.0, 1.5, 1.260), (1.0, 2.0, 1.000), (1.0, 2.5, 0.871),
    (1.5, 1.5, 1.462), (1.5, 2.0, 1.118), (1.5, 2.5, 0.952),
])
def test_equibiaxial_table(r, m, table):
    assert point.stress_ratio_yield(power(m, r), 1.0) / SY == pytest.approx(table, abs=5e-4)


@pytest.mark.parametrize("m, r", GRID)
def test_plane_strain_stress_ratio(m, r):
    """eps2 = 0 in plastic flow: s2/s1 = (t - 1)/(t + 1), t = (1 + 2r)^(1/(m-1))."""
    t = (1.0 + 2.0 * r) ** (1.0 / (m - 1.0))
    assert point.plane_strain_yield(power(m, r)) == pytest.approx((t - 1.0) / (t + 1.0), abs=1e-10)


@pytest.mark.parametrize("m, r", GRID)
def test_lankford_coefficient(m, r):
    """r = d ep22 / d ep33 in uniaxial tension (power law and Swift hardening)."""
    assert point.lankford(power(m, r), 40 * EY, 8) == pytest.approx(r, rel=1e-6)
    assert point.lankford(swift(m, r), 0.1, 8) == pytest.approx(r, rel=1e-6)


@pytest.mark.parametrize("m", [1.5, 2.0, 2.5, 8.0])
def test_gradient_and_hessian(m):
    """a and Hess against central differences; Euler: s.a = sigma_bar, Hess s = 0; no NaN at
    u = 0 (pure shear) or rho = 0 (equibiaxial)."""
    r = 1.7
    rng = np.random.default_rng(3)
    a, H = np.zeros(3), np.zeros((3, 3))
    for s in rng.normal(size=(5, 3)) * SY:
        sb = yield_derivatives(s, r, m, a, H)
        assert sb == pytest.approx(equivalent_stress(s, r, m), rel=1e-14)
        assert s @ a == pytest.approx(sb, rel=1e-12)
        np.testing.assert_allclose(H @ s, 0.0, atol=1e-12 * np.abs(H).max() * SY)
        h = 1e-6 * SY
        a_fd, H_fd = np.zeros(3), np.zeros((3, 3))
        for j in range(3):
            dp, dm = s.copy(), s.copy()
            dp[j] += h
            dm[j] -= h
            a_fd[j] = (equivalent_stress(dp, r, m) - equivalent_stress(dm, r, m)) / (2 * h)
            ap, am = np.zeros(3), np.zeros(3)
            yield_derivatives(dp, r, m, ap, np.zeros((3, 3)))
            yield_derivatives(dm, r, m, am, np.zeros((3, 3)))
            H_fd[:, j] = (ap - am) / (2 * h)
        np.testing.assert_allclose(a, a_fd, atol=1e-8)
        np.testing.assert_allclose(H, H_fd, atol=1e-6 * np.abs(H).max())
    for s in ([0.0, 0.0, SY], [SY, -SY, 0.3 * SY], [SY, SY, 0.0], [-SY, -SY, 0.0], [0.0, 0.0, 0.0]):
        sb = yield_derivatives(np.array(s), r, m, a, H)
        assert np.isfinite(sb) and np.isfinite(a).all() and np.isfinite(H).all()


# ---- return map ------------------------------------------------------------------------------

DIRECTIONS = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, -0.3, 0.8],
              [0.2, 0.5, -1.5], [-1.0, 0.4, 0.6], [0.0, 0.0, 1.0]]


@pytest.mark.parametrize("m", [2.0, 8.0])
@pytest.mark.parametrize("law", [perfect, swift, power])
def test_consistent_tangent_is_derivative(m, law):
    """D_out equals the central difference of return_map's stress (plastic, with shear)."""
    mat = law(m, 3.0)
    ey = flow_stress(0.0, mat)[0] / E
    ep_n, p_n = np.array([0.003, -0.001, 0.002]), 0.004
    h = 1e-5 * ey
    for d in DIRECTIONS:
        e = ep_n + 3 * ey * np.array(d) / np.linalg.norm(d)
        _, D, _, _, status = rmap(e, mat, ep_n, p_n)
        assert status == 1
        D_fd = np.zeros((3, 3))
        for j in range(3):
            de = np.zeros(3)
            de[j] = h
            sp, sm = rmap(e + de, mat, ep_n, p_n)[0], rmap(e - de, mat, ep_n, p_n)[0]
            D_fd[:, j] = (sp - sm) / (2 * h)
        assert np.abs(D - D_fd).max() <= 1e-6 * np.abs(D).max()
        np.testing.assert_allclose(D, D.T, atol=1e-12 * E)


def check_closest_point(e, mat, ep_n, p_n, s, ep, p):
    """C^-1 s + dlambda a(s) = e - ep_n and sigma_bar(s) = sigma_f(p)."""
    a = np.zeros(3)
    sb = yield_derivatives(s, mat[PAR_], mat[PAR_ + 1], a, np.zeros((3, 3)))
    assert sb == pytest.approx(flow_stress(p, mat)[0], rel=1e-11)
    np.testing.assert_allclose(compliance() @ s + (p - p_n) * a, e - ep_n,
                               atol=1e-11 * np.linalg.norm(e - ep_n))
    np.testing.assert_allclose(ep, e - compliance() @ s, atol=1e-15)


@pytest.mark.parametrize("r", RS)
@pytest.mark.parametrize("law", [perfect, swift])
def test_newton_converges_sharp_yield_surface_large_increment(r, law):
    """m = 8 and a strain increment of 50 yield strains in one step, from virgin and from
    pre-strained states."""
    mat = law(8.0, r)
    ey = flow_stress(0.0, mat)[0] / E
    for ep_n, p_n in ((np.zeros(3), 0.0), (np.array([0.01, -0.004, 0.006]), 0.012)):
        for d in DIRECTIONS:
            e = ep_n + 50 * ey * np.array(d) / np.linalg.norm(d)
            s, _, ep, p, status = rmap(e, mat, ep_n, p_n)
            assert status == 1
            check_closest_point(e, mat, ep_n, p_n, s, ep, p)


@pytest.mark.parametrize("r", RS)
def test_newton_converges_equibiaxial_m15(r):
    """m = 1.5 (curvature singular at rho = 0): equibiaxial states return to s_b."""
    mat = perfect(1.5, r)
    sb = SY * (2.0 * (1.0 + r)) ** (1.0 / 1.5) / 2.0
    for mult in (1.5, 10.0, 50.0):
        for d in ([1.0, 1.0, 0.0], [-1.0, -1.0, 0.0]):
            e = mult * EY * np.array(d)
            s, _, ep, p, status = rmap(e, mat)
            assert status == 1
            np.testing.assert_allclose(s, np.sign(d[0]) * np.array([sb, sb, 0.0]), atol=1e-10 * SY)
            check_closest_point(e, mat, np.zeros(3), 0.0, s, ep, p)
        s, _, _, p, status = rmap(mult * EY * np.array([1.0, 1.0 + 1e-6, 1e-7]), mat)  # near it
        assert status == 1 and equivalent_stress(s, r, 1.5) == pytest.approx(SY, rel=1e-11)


@pytest.mark.parametrize("m", [1.5, 2.0, 8.0])
@pytest.mark.parametrize("law", [perfect, swift])
def test_warm_start_returns_the_cold_solution(m, law):
    """The return map started from the point's last solution (Newton's last iterate, the strain
    moved since by up to 30 %) or from a misleading one (falls back to the radial start) gives
    the cold start's stress, tangent and plastic strain to the local tolerance."""
    mat = law(m, 1.5)
    ey = flow_stress(0.0, mat)[0] / E
    ep_n, p_n = np.array([0.003, -0.001, 0.002]), 0.004
    rng = np.random.default_rng(1)
    for d in DIRECTIONS:
        e0 = ep_n + 3 * ey * np.array(d) / np.linalg.norm(d)
        last = _return_core(*e0, *ep_n, p_n, mat)
        assert last[-1] == 1
        for e in (e0 * (1 + 1e-6), e0 + 0.3 * 3 * ey * rng.standard_normal(3)):
            cold = np.array(_return_core(*e, *ep_n, p_n, mat))
            if cold[-1] != 1:
                continue
            for w0, w1, w2, p_w in (last[9:13], (*(ep_n + 0.1 * rng.standard_normal(3)), p_n + 0.5)):
                warm = np.array(_return_core(*e, *ep_n, p_n, mat, w0, w1, w2, p_w))
                assert warm[-1] == 1
                np.testing.assert_allclose(warm[:3], cold[:3], rtol=0, atol=1e-10 * np.abs(cold[:3]).max())
                np.testing.assert_allclose(warm[3:9], cold[3:9], rtol=0, atol=1e-8 * E)
                np.testing.assert_allclose(warm[9:13], cold[9:13], rtol=0, atol=1e-13)


@pytest.mark.parametrize("r", RS)
def test_hill48_closed_form_equals_the_general_one(r):
    """m = 2 takes a branch without powers: sigma_bar, gradient and Hessian match the general
    expressions at m = 2 (1 + 1e-12)."""
    rng = np.random.default_rng(2)
    for s in rng.standard_normal((20, 3)) * SY:
        a, H, a1, H1 = np.zeros(3), np.zeros((3, 3)), np.zeros(3), np.zeros((3, 3))
        sb = yield_derivatives(s, r, 2.0, a, H)
        sb1 = yield_derivatives(s, r, 2.0 * (1 + 1e-12), a1, H1)
        assert sb == pytest.approx(sb1, rel=1e-10)
        assert equivalent_stress(s, r, 2.0) == pytest.approx(sb, rel=1e-14)
        np.testing.assert_allclose(a, a1, rtol=0, atol=1e-10)
        np.testing.assert_allclose(H, H1, rtol=0, atol=1e-10 * np.abs(H).max())


@pytest.mark.parametrize("m", [1.5, 2.0, 8.0])
def test_dissipation_is_sigma_bar_dp(m):
    """Along a proportional path s . dep = sigma_bar dp (sigma_bar work conjugate to p)."""
    mat = swift(m, 1.5)
    ey = flow_stress(0.0, mat)[0] / E
    d = np.array([1.0, 0.35, -0.4])
    ep, p = np.zeros(3), 0.0
    plastic = 0
    for lam in np.linspace(0.0, 30 * ey, 31)[1:]:
        s, _, ep_new, p_new, status = rmap(lam * d, mat, ep, p)
        assert status in (0, 1)
        if status == 1:
            plastic += 1
            sb = equivalent_stress(s, 1.5, m)
            assert s @ (ep_new - ep) == pytest.approx(sb * (p_new - p), rel=1e-10)
        ep, p = ep_new, p_new
    assert plastic > 20


def test_elastic_law_never_yields():
    mat = Hill79Material(E, NU).pack()
    e = np.array([0.3, -0.1, 0.2])
    s, D, ep, p, status = rmap(e, mat)
    C = np.linalg.inv(compliance())
    assert status == 0 and p == 0.0 and not ep.any()
    np.testing.assert_allclose(s, C @ e, rtol=1e-14)
    np.testing.assert_allclose(D, C, rtol=1e-14, atol=1e-10)


# ---- hardening -------------------------------------------------------------------------------

@pytest.mark.parametrize("n", [1.05, 2.0, 5.0, 12.0])
def test_power_law(n):
    """The curve passes through (eps_y, sigma_y) and eps_bar = eps_y (s/sigma_y)^n for p > 0."""
    mat = power(2.0, 1.0, n)
    assert flow_stress(0.0, mat)[0] == SY
    for p in np.logspace(-6, 0, 13):
        s, slope = flow_stress(p, mat)
        assert s / E + p == pytest.approx(EY * (s / SY) ** n, rel=1e-13)
        h = 1e-6 * p
        fd = (flow_stress(p + h, mat)[0] - flow_stress(p - h, mat)[0]) / (2 * h)
        assert slope == pytest.approx(fd, rel=1e-6)
    path = point.uniaxial(mat, 30 * EY, 30)  # one step ends exactly at the yield strain
    assert path.stress[1, 0] == pytest.approx(SY, rel=1e-12) and path.p[1] == 0.0
    for e11, s11 in zip(path.strain[2:, 0], path.stress[2:, 0]):
        assert e11 == pytest.approx(EY * (s11 / SY) ** n, rel=1e-10)


def test_the_power_law_turns_elastic_as_n_falls_to_1_so_n_1_is_refused():
    """eps = eps_y (s / sigma_y)^n: as n falls to 1 the stress at a given plastic strain grows
    without bound (x ln x ~ P / (n - 1)), the elastic limit, not the perfectly plastic one; n = 1
    is refused naming material.n, with the Swift law's n = 0 as the way to perfect plasticity."""
    stress = [flow_stress(1e-3, power(2.0, 1.0, n))[0] for n in (2.0, 1.5, 1.2, 1.1, 1.05)]
    assert all(b > a for a, b in zip(stress, stress[1:])) and stress[-1] > 5 * SY
    with pytest.raises(InputError) as err:
        power(2.0, 1.0, 1.0)
    assert err.value.field == "material.n" and "swift" in str(err.value)


def test_swift_law():
    mat = Hill79Material(E, NU, 1.0, 2.0, "swift", K=500.0, eps0=0.02, n=0.25).pack()
    for p in (0.0, 0.01, 0.3):
        assert flow_stress(p, mat) == pytest.approx((500 * (0.02 + p) ** 0.25,
                                                     0.25 * 500 * (0.02 + p) ** -0.75), rel=1e-14)
    mat = perfect(2.0, 1.0)  # n = 0: perfect plasticity
    for p in (0.0, 0.01, 0.3):
        assert flow_stress(p, mat) == (SY, 0.0)
    path = point.uniaxial(mat, 0.05, 10)
    np.testing.assert_allclose(path.stress[2:, 0], SY, rtol=1e-12)


def test_thickness_strain_uniaxial():
    """e33 = -ep11/(1+r) - nu s11/E under uniaxial plastic tension (r-value relation plus the
    plane-stress elastic part)."""
    for m in (1.5, 2.0, 8.0):
        for r in RS:
            mat = swift(m, r)
            path = point.uniaxial(mat, 0.2, 10)
            e, ep, s = path.strain[-1], path.plastic_strain[-1], path.stress[-1]
            expected = -ep[0] / (1.0 + r) - NU * s[0] / E
            assert thickness_strain(e, ep, mat) == pytest.approx(expected, rel=1e-6, abs=1e-14)


# ---- section ---------------------------------------------------------------------------------

def section(em, k, t, nz, mat, ep_n=None, p_n=None):
    zeta, wz = through_thickness_rule(nz)
    ep_n = np.zeros((nz, 3)) if ep_n is None else ep_n
    p_n = np.zeros(nz) if p_n is None else p_n
    S, D, ep_new, p_new = np.zeros(6), np.zeros((6, 6)), np.zeros((nz, 3)), np.zeros(nz)
    nplastic, _ = section_response(np.asarray(em, float), np.asarray(k, float), t, t, zeta, wz,
                                   ep_n, p_n, mat, False, False, S, D, ep_new, p_new)
    return S, D, nplastic, ep_new, p_new


def test_through_thickness_rule():
    for nz in range(2, 8):
        zeta, wz = through_thickness_rule(nz)
        assert wz.sum() == pytest.approx(1.0, rel=1e-15) and np.all(np.abs(zeta) < 0.5)
        assert wz @ zeta**2 == pytest.approx(1.0 / 12.0, rel=1e-14)
    for bad in (1, 0, 2.5):
        with pytest.raises(InputError) as err:
            through_thickness_rule(bad)
        assert err.value.field == "process.thickness_points"


@pytest.mark.parametrize("nz", range(2, 8))
def test_elastic_section_equals_closed_form(nz):
    mat = Hill79Material(E, NU).pack()
    t = 1.3
    em, k = np.array([1e-3, -4e-4, 6e-4]), np.array([2e-3, 5e-4, -1e-3])
    S, D, nplastic, _, _ = section(em, k, t, nz, mat)
    S0, D0 = np.zeros(6), np.zeros((6, 6))
    elastic_section(em, k, t, mat, S0, D0)
    assert nplastic == 0
    np.testing.assert_allclose(S, S0, rtol=0, atol=1e-12 * np.abs(S0).max())
    np.testing.assert_allclose(D, D0, rtol=0, atol=1e-12 * np.abs(D0).max())
    np.testing.assert_allclose(D0[:3, :3], t * np.linalg.inv(compliance()), rtol=1e-14)
    np.testing.assert_allclose(D0[3:, 3:], t**3 / 12 * np.linalg.inv(compliance()), rtol=1e-14)


@pytest.mark.parametrize("nz", range(2, 8))
@pytest.mark.parametrize("m, r", [(2.0, 0.25), (2.0, 0.5), (8.0, 0.5)])
def test_fully_plastic_uniaxial_bending(nz, m, r):
    """Perfectly plastic section bent far beyond yield with k = kappa (1, -nu, 0), nu = r/(1+r):
    elastic and plastic strain rates are both along the uniaxial direction, every layer carries
    s = (+-sigma_y, 0, 0) and M11 = sigma_y t^2/4 * (4 sum w |zeta|), N = 0, M22 = M12 = 0."""
    nu = r / (1.0 + r)
    mat = perfect(m, r, nu)
    t = 0.8
    zeta, wz = through_thickness_rule(nz)
    kappa = 10 * EY / (t * np.abs(zeta[np.abs(zeta) > 1e-12]).min())
    S, _, nplastic, _, _ = section([0.0, 0.0, 0.0], kappa * np.array([1.0, -nu, 0.0]), t, nz, mat)
    assert nplastic == np.count_nonzero(np.abs(zeta) > 1e-12)
    M = SY * t**2 / 4 * (4 * np.sum(wz * np.abs(zeta)))
    assert S[3] == pytest.approx(M, rel=1e-8)
    np.testing.assert_allclose(S[[0, 1, 2]], 0.0, atol=1e-8 * SY * t)
    np.testing.assert_allclose(S[[4, 5]], 0.0, atol=1e-8 * M)


@pytest.mark.parametrize("m", [2.0, 8.0])
def test_section_tangent_is_derivative(m):
    """The section tangent equals the central difference of the resultants (partly plastic)."""
    mat, t, nz = swift(m, 1.5), 1.1, 5
    ey = flow_stress(0.0, mat)[0] / E
    rng = np.random.default_rng(7)
    ep_n, p_n = rng.normal(size=(nz, 3)) * 1e-3, np.abs(rng.normal(size=nz)) * 2e-3
    x = np.array([0.8, 0.2, 0.3, 3.0 / t, -1.0 / t, 1.0 / t]) * ey
    x[:3] += ep_n.mean(axis=0)
    S, D, nplastic, _, _ = section(x[:3], x[3:], t, nz, mat, ep_n, p_n)
    assert nplastic > 0
    h = 1e-5 * ey
    D_fd = np.zeros((6, 6))
    for j in range(6):
        dx = np.zeros(6)
        dx[j] = h * (1 if j < 3 else 1 / t)
        Sp = section(x[:3] + dx[:3], x[3:] + dx[3:], t, nz, mat, ep_n, p_n)[0]
        Sm = section(x[:3] - dx[:3], x[3:] - dx[3:], t, nz, mat, ep_n, p_n)[0]
        D_fd[:, j] = (Sp - Sm) / (2 * dx[j])
    scale = np.diag([1, 1, 1, 1 / t, 1 / t, 1 / t])  # compare in units of the membrane block
    assert np.abs(scale @ (D - D_fd) @ scale).max() <= 1e-6 * np.abs(scale @ D @ scale).max()
    np.testing.assert_allclose(D, D.T, atol=1e-12 * np.abs(D).max())


# ---- input -----------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, field", [
    (dict(r=0.0), "material.r"),
    (dict(r=-1.0), "material.r"),
    (dict(m=0.9), "material.m"),
    (dict(E=-1.0), "material.E"),
    (dict(E="steel"), "material.E"),
    (dict(nu=0.5), "material.nu"),
    (dict(hardening="linear"), "material.hardening"),
    (dict(hardening="power", n=3.0), "material.yield_stress"),
    (dict(hardening="power", yield_stress=SY), "material.n"),
    (dict(hardening="power", yield_stress=SY, n=0.5), "material.n"),
    (dict(hardening="power", yield_stress=SY, n=1.0), "material.n"),
    (dict(hardening="swift", K=500.0, n=0.2), "material.eps0"),
    (dict(hardening="swift", K=500.0, eps0=0.0, n=0.2), "material.eps0"),
    (dict(hardening="swift", eps0=0.01, n=0.2), "material.K"),
    (dict(hardening="swift", K=500.0, eps0=0.01, n=-0.1), "material.n"),
])
def test_material_input_errors_name_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        Hill79Material(**{"E": E, "nu": NU, **kwargs}).pack()
    assert err.value.field == field
    assert str(err.value).startswith(field + ":")


def test_pack_layout():
    mat = Hill79Material(E, NU, 1.5, 6.0, "swift", K=500.0, eps0=0.01, n=0.2).pack()
    slots = [E_, NU_, PAR_, PAR_ + 1, LAW_, A_, B_, C_]
    np.testing.assert_array_equal(mat[slots], [E, NU, 1.5, 6.0, 2.0, 500.0, 0.01, 0.2])
    assert mat[COS_] == 1.0 and np.count_nonzero(np.delete(mat, slots + [COS_])) == 0  # rolling direction along x
    assert mat.dtype == np.float64
    np.testing.assert_array_equal(power(2.0, 1.0, 4.0)[[LAW_, A_, B_]], [1.0, SY, 4.0])


@pytest.mark.slow
def test_strain_guard_counts_and_skips_unphysical_points():
    """section_update leaves a point whose strain is not finite or past 1000 % untouched (its
    resultants those of zero strain, its layers' state as it was) and counts it."""
    from shellform.material.update import section_update

    mat = swift(2.0, 1.5)
    zeta, wz = through_thickness_rule(3)
    e = np.zeros((3, 1, 6))
    e[0, 0, 1] = np.nan
    e[1, 0, 5] = 20.0 / 0.8  # curvature 25 / mm at t = 0.8: 2000 % at the faces
    e[2, 0, 0] = 3 * SY / E  # a real, plastic point
    ep_n, p_n = np.zeros((3, 1, 3, 3)), np.zeros((3, 1, 3))
    ep, p = np.full_like(ep_n, 7.0), np.full_like(p_n, 7.0)
    S, D = np.full((3, 1, 6), np.nan), np.full((3, 1, 6, 6), np.nan)
    nplastic, nfail, nguard = section_update(e, np.zeros((3, 1, 3)), mat, 0.8, True, False, zeta, wz, ep_n, p_n, ep, p,
                                             np.ones((3, 1)), S, D)
    assert (nplastic, nfail, nguard) == (3, 0, 2)
    assert np.all(S[:2] == 0.0) and np.all(np.isfinite(D))
    assert np.all(ep[:2] == 7.0) and np.all(p[:2] == 7.0)
    # the plastic point, warm-started from a misleading state (7.0), flows at the flow stress
    assert np.all(p[2] > 0) and S[2, 0, 0] / 0.8 > flow_stress(0.0, mat)[0]
