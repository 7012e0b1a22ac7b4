"""The analytic tools of the square cup: signed distances against a sampled surface, normals
against finite differences, symmetry to the bit, the faces, walls and offsets exactly, and the
shape operator (the Hessian of the signed distance) against central differences and closed forms."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from shellform.tools.analytic import BlankHolder, Die, Punch, rounded_square_hessian, rounded_square_sdf
from shellform.tools.square import square_cup_tools
from shellform.tools.holder_edge import RoundedSquareEdge
from shellform.scene import ToolsSpec

H = 0.04  # sampling spacing of the brute-force surfaces (mm)
PUNCH = Punch(half_width=10.0, corner_radius=4.0, profile_radius=2.0, z_face=0.3)
DIE = Die(half_width=12.0, corner_radius=5.0, profile_radius=3.0, z_top=-0.4)
HOLDER = BlankHolder(RoundedSquareEdge(half_width=15.0, corner_radius=8.0), z_face=0.4)
RNG = np.random.default_rng(7)


# -- brute force: the tool surfaces sampled parametrically in the quadrant x, y >= 0 ----------
def quadrant_outline(a, rc, h, reach):
    """Points and outward normals of the boundary of the rounded square (a, rc), x, y >= 0, its
    corner arc sampled finely enough for a surface up to reach outside it."""
    b = a - rc
    t = np.linspace(0.0, b, int(b / h) + 2)
    phi = np.linspace(0.0, np.pi / 2, int(np.pi / 2 * (rc + reach) / h) + 2)
    c = np.vstack([np.c_[np.full_like(t, a), t], np.c_[t, np.full_like(t, a)],
                   b + rc * np.c_[np.cos(phi), np.sin(phi)]])
    n = np.vstack([np.tile([1.0, 0.0], (len(t), 1)), np.tile([0.0, 1.0], (len(t), 1)),
                   np.c_[np.cos(phi), np.sin(phi)]])
    return c, n


def inside_rounded_square(x, y, a, rc):
    """Independent of rounded_square_sdf: the union of two rectangles and four discs."""
    x, y, b = np.abs(x), np.abs(y), a - rc
    return ((x <= a) & (y <= b)) | ((x <= b) & (y <= a)) | ((x - b) ** 2 + (y - b) ** 2 <= rc * rc)


def swept(c, n, r, z0, sign, h):
    """The profile: c + r sin(phi) n (sign = +1 punch nose, -1 die shoulder), z0 - sign r cos(phi)."""
    phi = np.linspace(0.0, np.pi / 2, int(np.pi / 2 * r / h) + 2)
    xy = c[:, None, :] + sign * r * np.sin(phi)[None, :, None] * n[:, None, :]
    z = np.broadcast_to(z0 - sign * r * np.cos(phi), xy.shape[:2])
    return np.c_[xy.reshape(-1, 2), z.reshape(-1)]


def wall(c, z):
    return np.c_[np.repeat(c, len(z), axis=0), np.tile(z, len(c))]


def grid(lo, hi, h):
    g = np.linspace(lo, hi, int((hi - lo) / h) + 2)
    return [v.ravel() for v in np.meshgrid(g, g)]


def punch_surface(p, h=H, height=5.0):
    rp, a, rc = p.profile_radius, p.half_width - p.profile_radius, p.corner_radius - p.profile_radius
    c, n = quadrant_outline(a, rc, h, rp)
    x, y = grid(0.0, a, h)
    flat = inside_rounded_square(x, y, a, rc)
    zc = p.z_face + rp
    return np.vstack([np.c_[x[flat], y[flat], np.full(flat.sum(), p.z_face)],
                      swept(c, n, rp, zc, 1.0, h),
                      wall(c + rp * n, np.arange(zc, zc + height, h))])


def die_surface(d, h=H, size=22.0, depth=5.0):
    rd, a, rc = d.profile_radius, d.half_width + d.profile_radius, d.corner_radius + d.profile_radius
    c, n = quadrant_outline(a, rc, h, 0.0)
    x, y = grid(0.0, size, h)
    flat = ~inside_rounded_square(x, y, a, rc)
    zt = d.z_top - rd
    return np.vstack([np.c_[x[flat], y[flat], np.full(flat.sum(), d.z_top)],
                      swept(c, n, rd, zt, -1.0, h),
                      wall(c - rd * n, np.arange(zt - depth, zt, h))])


def near(lo, hi, m):
    return np.c_[RNG.uniform(lo[0], hi[0], m), RNG.uniform(lo[1], hi[1], m), RNG.uniform(lo[2], hi[2], m)]


# the quadrant x, y >= 0: a tool symmetric about x = 0 and y = 0 has a nearest point there too
CASES = {
    "punch": (PUNCH, punch_surface, ([0, 0, -2.5], [13, 13, 3.0])),
    "die": (DIE, die_surface, ([0, 0, -6.0], [19, 19, 2.0])),
}


@pytest.mark.parametrize("name", CASES)
def test_gap_is_the_distance_to_the_sampled_surface(name):
    tool, surface, box = CASES[name]
    r = tool.profile_radius
    x = near(*box, 6000)
    sd, _ = tool.gap(x)
    # outside, and inside shallower than the profile radius (there the signed distance is exact);
    # not nearer than 0.5 to the surface, where the sampling error is largest
    keep = (np.abs(sd) > 0.5) & (sd > -0.9 * r) & (sd < 3.0)
    x, sd = x[keep], sd[keep]
    assert len(x) > 1000
    brute, _ = cKDTree(surface(tool)).query(x)
    # brute >= the true distance (samples lie on the surface); the sampling overestimates a
    # distance d >= 0.5 by about delta^2 (1 + d/R) / (2 d) <= H^2, delta <= H / sqrt(2) the distance
    # to the nearest sample, R the surface's radius of curvature
    err = brute - np.abs(sd)
    assert err.min() > -1e-9
    assert err.max() < H**2


def finite_difference_gradient(tool, x, eps=1e-6):
    g = np.empty_like(x)
    for k in range(3):
        e = np.zeros(3)
        e[k] = eps
        g[:, k] = (tool.gap(x + e)[0] - tool.gap(x - e)[0]) / (2 * eps)
    return g


@pytest.mark.parametrize("name", CASES)
def test_normal_is_the_gradient_of_the_gap(name):
    tool, _, (lo, hi) = CASES[name]
    r = tool.profile_radius
    x = near(np.array(lo) - [hi[0], hi[1], 0], hi, 4000)  # all four quadrants
    sd, n = tool.gap(x, offset=0.3)
    sd += 0.3
    keep = (sd > -0.9 * r) & (np.abs(sd) > 1e-3)  # d_core > 0: smooth (the punch's core is convex)
    if tool is DIE:  # the medial axis of the opening lies at plan depth >= its corner radius
        s, _, _ = rounded_square_sdf(x[:, 0], x[:, 1], DIE.half_width + r, DIE.corner_radius + r)
        keep &= s > -(DIE.corner_radius + r - 0.1)
    assert keep.sum() > 1000
    np.testing.assert_allclose(n[keep], finite_difference_gradient(tool, x[keep]), atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=0, atol=1e-14)


TOOLS = {"punch": PUNCH, "die": DIE, "holder": HOLDER}


@pytest.mark.parametrize("name", TOOLS)
def test_symmetry_to_the_bit(name):
    tool = TOOLS[name]
    x = near([-20, -20, -6], [20, 20, 6], 5000)
    g, n = tool.gap(x)
    swap = x[:, [1, 0, 2]]
    gs, ns = tool.gap(swap)
    assert np.array_equal(g, gs)
    assert np.array_equal(n, ns[:, [1, 0, 2]])
    for k in (0, 1):  # mirrored about x = 0, y = 0
        m = x.copy()
        m[:, k] *= -1
        gm, nm = tool.gap(m)
        assert np.array_equal(g, gm)
        nm[:, k] *= -1
        assert np.array_equal(n, nm)
        x0 = x.copy()
        x0[:, k] = 0.0  # on the symmetry plane: exactly +0.0 across it
        g0, n0 = tool.gap(x0)
        assert np.all(n0[:, k] == 0.0) and not np.signbit(n0[:, k]).any()
        assert not np.isnan(g0).any() and not np.isnan(n0).any()


def test_rounded_square_sdf():
    a, rc = 5.0, 2.0
    x = np.array([0.0, 6.0, 3.0 + 3 * np.cos(0.3), 1.0, 0.0, -4.0, 0.0])
    y = np.array([0.0, 1.0, 3.0 + 3 * np.sin(0.3), 4.5, -2.0, 0.0, 7.0])
    s, sx, sy = rounded_square_sdf(x, y, a, rc)
    np.testing.assert_allclose(s, [-5.0, 1.0, 1.0, -0.5, -3.0, -1.0, 2.0], atol=1e-14)
    np.testing.assert_allclose(sx, [0.0, 1.0, np.cos(0.3), 0.0, 0.0, -1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(sy, [0.0, 0.0, np.sin(0.3), 1.0, -1.0, 0.0, 1.0], atol=1e-15)
    s0, _, _ = rounded_square_sdf(np.array([5.0, 5.0]), np.array([5.0, 0.0]), a, 0.0)  # sharp corner
    np.testing.assert_array_equal(s0, [0.0, 0.0])


def test_rounded_square_hessian():
    """tau tau^T / r on the corner arcs' sectors (r from the arc's centre), 0 on the sides and inside."""
    a, rc, th = 5.0, 2.0, 0.3
    x = np.array([3.0 + 3 * np.cos(th), -(3.0 + 0.5 * np.cos(th)), 6.0, 1.0, 0.0])
    y = np.array([3.0 + 3 * np.sin(th), 3.0 + 0.5 * np.sin(th), 1.0, 4.5, 0.0])
    H = rounded_square_hessian(x, y, a, rc)
    tau = np.array([[-np.sin(th), np.cos(th), 0.0], [-np.sin(th), -np.cos(th), 0.0]])
    np.testing.assert_allclose(H[0], np.outer(tau[0], tau[0]) / 3.0, atol=1e-15)
    np.testing.assert_allclose(H[1], np.outer(tau[1], tau[1]) / 0.5, atol=1e-14)  # inside the arc, x < 0
    np.testing.assert_array_equal(H[2:], np.zeros((3, 3, 3)))


def test_flat_faces_have_exact_normals():
    x = near([-6, -6, -1.5], [6, 6, 0.29], 500)  # under the punch's flat face (plan core 8 - 2)
    _, n = PUNCH.gap(x)
    assert np.array_equal(n, np.tile([0.0, 0.0, -1.0], (len(x), 1)))
    x = np.r_[near([15.5, -20, -0.3], [20, 20, 2], 300), near([-20, 15.5, -0.3], [20, 20, 2], 300)]
    _, n = DIE.gap(x)  # over the die's flat top, outside O (half-width 15)
    assert np.array_equal(n, np.tile([0.0, 0.0, 1.0], (len(x), 1)))
    g, n = HOLDER.gap(x)
    assert np.array_equal(n, np.tile([0.0, 0.0, -1.0], (len(x), 1)))
    np.testing.assert_array_equal(g, HOLDER.z_face - x[:, 2])


def test_sheet_on_the_faces_has_zero_gap():
    t = 0.8
    tools = square_cup_tools(ToolsSpec(), t)
    punch, die, holder = tools["punch"], tools["die"], tools["holder"]
    assert (punch.z_face, die.z_top, holder.z_face) == (0.4, -0.4, 0.4)
    assert (holder.edge.half_width, holder.edge.corner_radius) == (42.0, 17.0)
    x = np.c_[RNG.uniform(-25, 25, (200, 2)), np.zeros(200)]  # mid-surface under the punch face
    assert np.abs(punch.gap(x, t / 2)[0]).max() < 1e-14
    flange = np.c_[RNG.uniform(42.5, 60, 200), RNG.uniform(-60, 60, 200), np.zeros(200)]
    assert np.abs(die.gap(flange, np.full(200, t / 2))[0]).max() < 1e-14
    assert np.abs(holder.gap(flange, t / 2)[0]).max() < 1e-14
    # the punch's travel and the holder's displacement move them along z
    g, _ = punch.gap(x, t / 2, dz=-1.5)
    np.testing.assert_allclose(g, -1.5, atol=1e-14)
    assert np.allclose(holder.gap(flange, t / 2, dz=0.25)[0], 0.25, atol=1e-14)
    assert np.allclose(tools["punch"].gap(x + [0, 0, -2.0], 0.0, dz=-2.0)[0], punch.gap(x)[0], atol=1e-14)
    # a punch spec.punch_gap above the sheet
    spaced = square_cup_tools(ToolsSpec(punch_gap=0.7), t)["punch"]
    np.testing.assert_allclose(spaced.gap(x, t / 2)[0], 0.7, atol=1e-14)


@pytest.mark.parametrize("s", [0.1, 1.0, 2.9])
def test_walls_and_profiles(s):
    a, rd = DIE.half_width, DIE.profile_radius
    deep = DIE.z_top - rd - 4.0
    x = np.array([[a - s, 0, deep], [a + s, 0, deep], [0, -(a - s), deep], [-(a + s), 0, deep]])
    g, n = DIE.gap(x)
    np.testing.assert_allclose(g, [s, -s, s, -s], atol=1e-14)  # into the opening / into the die
    np.testing.assert_array_equal(n, [[-1, 0, 0], [-1, 0, 0], [0, 1, 0], [1, 0, 0]])
    # the die's shoulder: a torus of radius rd about the circle (a + rd, z_top - rd) of the section
    phi = 0.7
    p = np.array([[a + rd - (rd + s) * np.sin(phi), 0.0, DIE.z_top - rd + (rd + s) * np.cos(phi)]])
    g, n = DIE.gap(p)
    np.testing.assert_allclose(g, [s], atol=1e-13)
    np.testing.assert_allclose(n, [[-np.sin(phi), 0.0, np.cos(phi)]], atol=1e-14)
    # the punch's wall, nose and plan corner
    ap, rp, zf = PUNCH.half_width, PUNCH.profile_radius, PUNCH.z_face
    x = np.array([[ap + s, 0.0, zf + 5.0], [0.0, -ap - s, zf + rp], [0.0, 0.0, zf - s]])
    g, n = PUNCH.gap(x)
    np.testing.assert_allclose(g, [s, s, s], atol=1e-14)
    np.testing.assert_array_equal(n, [[1, 0, 0], [0, -1, 0], [0, 0, -1]])
    b = ap - PUNCH.corner_radius  # centre of the plan corner arc
    x = np.array([[b + (PUNCH.corner_radius + s) / np.sqrt(2), b + (PUNCH.corner_radius + s) / np.sqrt(2), zf + 3]])
    g, n = PUNCH.gap(x)
    np.testing.assert_allclose(g, [s], atol=1e-13)
    np.testing.assert_allclose(n, [[np.sqrt(0.5), np.sqrt(0.5), 0.0]], atol=1e-15)
    q = np.array([[0.0, ap - rp + (rp + s) * np.sin(phi), zf + rp - (rp + s) * np.cos(phi)]])
    g, n = PUNCH.gap(q)  # the nose: a torus of radius rp
    np.testing.assert_allclose(g, [s], atol=1e-13)
    np.testing.assert_allclose(n, [[0.0, np.sin(phi), -np.cos(phi)]], atol=1e-14)


def test_holder_covers_only_the_flange():
    x = np.array([[0.0, 0.0, 0.0], [14.9, 0.0, 0.0], [12.0, 12.0, 0.0], [15.0, 0.0, 0.0], [30, 30, 1.0]])
    g, n = HOLDER.gap(x, 0.4)
    assert np.isinf(g[:3]).all() and (g[:3] > 0).all()
    np.testing.assert_allclose(g[3:], [0.0, -1.0], atol=1e-15)


def test_no_nan_deep_inside_or_at_the_core():
    x = np.array([[0.0, 0.0, 50.0], [6.0, 6.0, 2.3], [8.0, 0.0, 2.3], [0.0, 0.0, -30.0], [30, 30, -30.0],
                  [15.0, 0.0, -3.4], [0.0, 0.0, 0.0]])
    for tool, face in ((PUNCH, [0, 0, -1]), (DIE, [0, 0, 1]), (HOLDER, [0, 0, -1])):
        g, n = tool.gap(x)
        assert not np.isnan(g).any() and np.isfinite(n).all()
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-15)
    g, n = PUNCH.gap(x[:2])  # inside the core: -rp and the face normal
    np.testing.assert_array_equal(g, [-2.0, -2.0])
    np.testing.assert_array_equal(n, [[0, 0, -1], [0, 0, -1]])
    _, n = DIE.gap(x[3:5])  # the opening's centre deep down (no plan gradient), inside the core
    np.testing.assert_array_equal(n, [[0, 0, 1], [0, 0, 1]])


# -- the shape operator H = dn/dx, the Hessian of the signed distance ------------------------
EPS, MARGIN = 1e-5, 0.05  # central differences' step; least distance of a point to a region's edge


def finite_difference_shape(tool, x, eps=EPS):
    """Central differences of gap's normals: column k is dn/dx_k."""
    H = np.empty((len(x), 3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = eps
        H[:, :, k] = (tool.gap(x + e)[1] - tool.gap(x - e)[1]) / (2 * eps)
    return H


def plan_parts(x, a, rc):
    """sdf of the rounded square (a, rc) and its q = |x| - (a - rc), |y| - (a - rc)."""
    s, _, _ = rounded_square_sdf(x[:, 0], x[:, 1], a, rc)
    return s, np.abs(x[:, 0]) - (a - rc), np.abs(x[:, 1]) - (a - rc)


def straight(qx, qy, m=MARGIN):
    """Beside a straight side of the plan, or inside the inner square, off its diagonals' kinks."""
    return ((qx > m) & (qy < -m)) | ((qy > m) & (qx < -m)) | ((qx < -m) & (qy < -m) & (np.abs(qx - qy) > m))


def punch_regions(x, m=MARGIN):
    rp = PUNCH.profile_radius
    s, qx, qy = plan_parts(x, PUNCH.half_width - rp, PUNCH.corner_radius - rp)
    h = PUNCH.z_face + rp - x[:, 2]
    corner = (qx > m) & (qy > m)
    far = np.hypot(np.maximum(s, 0), np.maximum(h, 0)) > 0.2  # the core distance: FD error ~ eps^2 / D^2
    return {"face": (s < -m) & (h > m), "nose straight": (s > m) & (h > m) & straight(qx, qy) & far,
            "nose corner": (s > m) & (h > m) & corner & far, "wall straight": (s > m) & (h < -m) & straight(qx, qy),
            "wall corner": (s > m) & (h < -m) & corner}


def die_regions(x, m=MARGIN):
    rd = DIE.profile_radius
    s, qx, qy = plan_parts(x, DIE.half_width + rd, DIE.corner_radius + rd)
    h = x[:, 2] - (DIE.z_top - rd)
    corner = (qx > m) & (qy > m) & (np.hypot(qx, qy) > 0.5)  # off the arcs' centres (the medial axis)
    side, inner = straight(qx, qy) & ((qx > m) | (qy > m)), straight(qx, qy) & (qx < -m) & (qy < -m)
    far = np.hypot(np.minimum(s, 0), np.maximum(h, 0)) > 0.2
    return {"top": s > m, "shoulder straight": (s < -m) & (h > m) & straight(qx, qy) & far,
            "shoulder corner": (s < -m) & (h > m) & corner & far, "wall straight": (s < -m) & (h < -m) & side,
            "wall corner": (s < -m) & (h < -m) & corner, "opening": (h < -m) & inner}  # deeper than a corner radius


REGIONS = [("punch", r) for r in punch_regions(np.zeros((1, 3)))] + [("die", r) for r in die_regions(np.zeros((1, 3)))]


@pytest.mark.parametrize("name,region", REGIONS)
def test_shape_is_the_derivative_of_the_normal(name, region):
    tool, _, (lo, hi) = CASES[name]
    x = near(np.array(lo) - [hi[0], hi[1], 0], hi, 40000)  # all four quadrants
    x = x[(punch_regions if tool is PUNCH else die_regions)(x)[region]][:400]
    assert len(x) >= 200
    H = tool.shape(x, offset=0.3)
    fd = finite_difference_shape(tool, x)
    if region in ("face", "top", "wall straight", "opening"):  # flat: the normal is constant, to the bit
        assert np.array_equal(fd, np.zeros_like(fd)) and np.array_equal(H, fd)
    else:  # to 1e-6 of each point's largest entry
        scale = np.abs(fd).max(axis=(1, 2), keepdims=True)
        assert scale.min() > 0.01
        assert (np.abs(H - fd) / scale).max() < 1e-6
    np.testing.assert_array_equal(H, H.transpose(0, 2, 1))
    _, n = tool.gap(x)
    assert np.abs(np.einsum("nij,nj->ni", H, n)).max() < 1e-14 * max(1.0, np.abs(H).max())


def principal(H, t):
    """t . H t for unit vectors t (one per point)."""
    return np.einsum("ni,nij,nj->n", t, H, t)


@pytest.mark.parametrize("delta", [0.1, 1.0, -0.5])  # outside, and into the tool (shallower than its radii)
def test_shape_closed_forms(delta):
    """On the tori and cylinders of the tools the principal curvatures of the distance's level
    surface at distance delta are known: across a profile of radius r, 1/(r + delta); along a
    plan arc of radius R about its centre, the normal's plan component over R (Meusnier)."""
    phi = np.array([0.2, 0.7, 1.3])
    ones, zeros = np.ones_like(phi), np.zeros_like(phi)
    # punch nose, straight part (the side y = -half_width): across 1/(rp + delta), along x 0
    ap, rp, zc = PUNCH.half_width, PUNCH.profile_radius, PUNCH.z_face + PUNCH.profile_radius
    x = np.c_[zeros + 1.0, -(ap - rp + (rp + delta) * np.sin(phi)), zc - (rp + delta) * np.cos(phi)]
    n, t = np.c_[zeros, -np.sin(phi), -np.cos(phi)], np.c_[zeros, -np.cos(phi), np.sin(phi)]
    H = PUNCH.shape(x)
    np.testing.assert_allclose(PUNCH.gap(x)[1], n, atol=1e-15)
    np.testing.assert_allclose(H, t[:, :, None] * t[:, None, :] / (rp + delta), atol=1e-14)
    # punch nose at the plan corner (towards theta): the plan arc of the core has radius rc - rp,
    # the point lies R = rc - rp + (rp + delta) sin(phi) from its centre
    theta, b, rc = 0.4, ap - PUNCH.corner_radius, PUNCH.corner_radius - rp
    R = rc + (rp + delta) * np.sin(phi)
    x = np.c_[b + R * np.cos(theta), b + R * np.sin(theta), zc - (rp + delta) * np.cos(phi)]
    n = np.c_[np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), -np.cos(phi)]
    t = np.c_[np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)]
    tau = np.c_[-np.sin(theta) * ones, np.cos(theta) * ones, zeros]
    H = PUNCH.shape(x)
    np.testing.assert_allclose(PUNCH.gap(x)[1], n, atol=1e-15)
    np.testing.assert_allclose(principal(H, t), 1 / (rp + delta), rtol=1e-14)
    np.testing.assert_allclose(principal(H, tau), np.sin(phi) / R, rtol=1e-14)
    np.testing.assert_allclose(H, t[:, :, None] * t[:, None, :] / (rp + delta)
                               + (np.sin(phi) / R)[:, None, None] * tau[:, :, None] * tau[:, None, :], atol=1e-14)
    # punch wall at the plan corner: 1 / (delta + corner_radius), straight wall 0
    x = np.array([[b + (PUNCH.corner_radius + delta) * np.cos(theta), b + (PUNCH.corner_radius + delta) * np.sin(theta),
                   zc + 2.0], [ap + delta, 1.0, zc + 2.0]])
    H = PUNCH.shape(x)
    np.testing.assert_allclose(H[0], np.outer(tau[0], tau[0]) / (PUNCH.corner_radius + delta), atol=1e-14)
    np.testing.assert_array_equal(H[1], np.zeros((3, 3)))
    # die shoulder, straight part (x = half_width + rd): across +1/(rd + delta) (the section is
    # convex, as the nose's), along y 0
    A, rd, zt = DIE.half_width + DIE.profile_radius, DIE.profile_radius, DIE.z_top - DIE.profile_radius
    x = np.c_[A - (rd + delta) * np.sin(phi), zeros + 1.0, zt + (rd + delta) * np.cos(phi)]
    n, t = np.c_[-np.sin(phi), zeros, np.cos(phi)], np.c_[np.cos(phi), zeros, np.sin(phi)]
    H = DIE.shape(x)
    np.testing.assert_allclose(DIE.gap(x)[1], n, atol=1e-15)
    np.testing.assert_allclose(H, t[:, :, None] * t[:, None, :] / (rd + delta), atol=1e-14)
    # die shoulder at the opening's plan corner: along it -sin(phi) / R, concave (the sign
    # opposite to the punch nose's), R = rc + rd - (rd + delta) sin(phi) from the arc's centre
    B, RC = A - (DIE.corner_radius + rd), DIE.corner_radius + rd
    R = RC - (rd + delta) * np.sin(phi)
    x = np.c_[B + R * np.cos(theta), B + R * np.sin(theta), zt + (rd + delta) * np.cos(phi)]
    n = np.c_[-np.sin(phi) * np.cos(theta), -np.sin(phi) * np.sin(theta), np.cos(phi)]
    t = np.c_[np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)]
    H = DIE.shape(x)
    np.testing.assert_allclose(DIE.gap(x)[1], n, atol=1e-15)
    np.testing.assert_allclose(principal(H, t), 1 / (rd + delta), rtol=1e-14)
    np.testing.assert_allclose(principal(H, tau), -np.sin(phi) / R, rtol=1e-14)
    assert (principal(H, tau) < 0).all()
    # die wall at the opening's corner: -1 / (corner_radius - delta), concave
    b = DIE.half_width - DIE.corner_radius
    x = np.array([[b + (DIE.corner_radius - delta) * np.cos(theta), b + (DIE.corner_radius - delta) * np.sin(theta),
                   zt - 2.0]])
    np.testing.assert_allclose(DIE.shape(x)[0], -np.outer(tau[0], tau[0]) / (DIE.corner_radius - delta), atol=1e-14)


@pytest.mark.parametrize("name", TOOLS)
def test_shape_ignores_the_offset_moves_with_the_tool_and_keeps_the_symmetry(name):
    tool = TOOLS[name]
    x = near([-20, -20, -6], [20, 20, 6], 5000)
    H = tool.shape(x)
    assert H.shape == (len(x), 3, 3)
    np.testing.assert_array_equal(tool.shape(x, offset=RNG.uniform(0, 0.5, len(x))), H)
    np.testing.assert_allclose(tool.shape(x + [0, 0, -1.5], 0.0, dz=-1.5), H, rtol=0, atol=1e-12)
    # mirrored about x = y, x = 0, y = 0: H -> S H S, to the bit
    swap = [1, 0, 2]
    assert np.array_equal(tool.shape(x[:, swap])[:, swap][:, :, swap], H)
    for k in (0, 1):
        S = np.ones(3)
        S[k] = -1.0
        Hm = tool.shape(x * S) * S[:, None] * S[None, :]
        assert np.array_equal(Hm + 0.0, H)
    assert np.isfinite(H).all()
    if tool is HOLDER:  # a flat face
        assert np.array_equal(H, np.zeros_like(H))


def test_shape_is_vectorised():
    """No loop over points: shape costs a few times gap, not a Python call per point."""
    import time

    x = near([-20, -20, -6], [20, 20, 6], 200_000)
    for tool in (PUNCH, DIE):
        cost = {}
        for f in (tool.gap, tool.shape):
            t = []
            for _ in range(3):
                t0 = time.perf_counter()
                f(x)
                t.append(time.perf_counter() - t0)
            cost[f.__name__] = min(t)
        assert cost["shape"] < 10 * cost["gap"] + 0.05, cost


def test_a_registry_refuses_a_module_that_misses_a_declaration_or_repeats_a_name():
    """shellform.registry.checked, which the yield functions and the kinds of tools share."""
    from types import SimpleNamespace

    from shellform import registry

    a, b = SimpleNamespace(__name__="a", NAME="a", f=1), SimpleNamespace(__name__="b", NAME="b", f=2)
    assert registry.checked((a, b), ("NAME", "f"), "part") == {"a": a, "b": b}
    with pytest.raises(TypeError, match="part c does not declare f"):
        registry.checked((a, SimpleNamespace(__name__="c", NAME="c")), ("NAME", "f"), "part")
    with pytest.raises(TypeError, match="a part's NAME is registered twice"):
        registry.checked((a, SimpleNamespace(__name__="a2", NAME="a", f=3)), ("NAME", "f"), "part")
