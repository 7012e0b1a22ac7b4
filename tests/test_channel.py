"""The channel over a curved binder (shellform/tools/channel.py, demos/channel_binder.toml): the
swept profiles' gap, normal and shape operator against finite differences of the signed
distance, the flat channel's section against the square tools' straight side, the holder's
path that stops at its gap (travel.py), the scene's checks, and the blank closed onto the
binder by the holder in the scene (the binder wrap)."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.errors import InputError
from shellform.tools import channel
from shellform.tools.analytic import Die, Punch
from shellform.tools.travel import Capped, Linear, path

DEMO = Path(__file__).resolve().parents[1] / "demos" / "channel_binder.toml"
T = 0.78


def _spec(radius):
    return SimpleNamespace(punch_half_width=25.0, punch_profile_radius=5.0, die_half_width=26.5,
                           die_profile_radius=5.0, punch_gap=0.5, binder_radius=radius, binder_rise=6.0,
                           stroke=18.5)


def _tools(radius):
    tools = channel.tools(_spec(radius), T)
    tools["holder"] = tools["holder"].at_gap(0.8, T)
    return tools


@pytest.mark.parametrize("radius", [150.0, 0.0])
@pytest.mark.parametrize("name", ["punch", "die", "holder"])
def test_the_swept_profiles_gap_normal_and_shape_are_the_signed_distance_and_its_derivatives(radius, name):
    tool = _tools(radius)[name]
    rng = np.random.default_rng(7)
    x = np.column_stack([rng.uniform(-45, 45, 400), rng.uniform(-40, 40, 400), rng.uniform(-15, 8, 400)])
    dz = -3.0
    g, n = tool.gap(x, 0.0, dz)
    H = tool.shape(x, 0.0, dz)
    near = np.isfinite(g) & (g > -4.0)  # outside the profiles' cores (radius 5), where the distance is exact
    assert near.sum() > 100
    h = 1e-5
    checked = 0
    for k in range(3):  # n = grad g, H = dn/dx, column by column, away from the profiles' kinks
        e = np.zeros(3)
        e[k] = h
        gp, n_p = tool.gap(x + e, 0.0, dz)
        gm, n_m = tool.gap(x - e, 0.0, dz)
        smooth = near & np.isfinite(gp) & np.isfinite(gm)
        smooth[smooth] &= np.linalg.norm(n_p - n_m, axis=1)[smooth] < 1e-3
        checked += smooth.sum()
        assert np.allclose((gp[smooth] - gm[smooth]) / (2 * h), n[smooth, k], atol=1e-7)
        assert np.allclose((n_p[smooth] - n_m[smooth]) / (2 * h), H[smooth, :, k], atol=1e-7)
    assert checked > 250
    assert np.allclose(np.linalg.norm(n[near], axis=1), 1.0)
    assert np.allclose(np.einsum("nij,nj->ni", H[near], n[near]), 0.0, atol=1e-14)
    assert np.allclose(H, H.transpose(0, 2, 1), atol=1e-15)


def test_the_curved_binders_faces_are_cylinders_of_the_binders_radius():
    """The die's binder face is the cylinder of radius binder_radius about the x axis through
    z = -(binder_radius + t/2), its curvature 1/rho across the channel's length; the holder at
    its gap is the concentric inside face, gap - t/2 over the mid-surface's radius."""
    tools = _tools(150.0)
    rm = 150.0 + T / 2
    y = np.linspace(0.0, 40.0, 9)
    on_flange = np.column_stack([np.full(9, 40.0), y, np.sqrt(rm**2 - y**2) - rm])  # the wrapped mid-surface
    g, n = tools["die"].gap(on_flange, T / 2)
    assert np.allclose(g, 0.0, atol=1e-12)
    assert np.allclose(n, np.column_stack([np.zeros(9), y, np.sqrt(rm**2 - y**2)]) / rm)
    assert np.allclose(tools["holder"].gap(on_flange, T / 2, -6.0)[0], 0.8 - T, atol=1e-12)
    H = tools["die"].shape(on_flange)
    along = np.column_stack([np.zeros(9), n[:, 2], -n[:, 1]])  # the tangent along the channel's length
    assert np.allclose(np.einsum("ni,nij,nj->n", along, H, along), 1.0 / rm)
    assert np.allclose(H[:, 0, :], 0.0)  # straight across the flange


def test_the_flat_channels_section_is_the_square_tools_straight_side():
    """A flat binder's channel, seen near y = 0, is the square cup's punch and die along a
    straight side of their plans (analytic.py): the same gap and normal (the punch raised by
    binder_rise)."""
    tools = _tools(0.0)
    punch = Punch(25.0, 10.0, 5.0, T / 2 + 0.5 + 6.0)
    die = Die(26.5, 10.0, 5.0, -T / 2)
    rng = np.random.default_rng(3)
    # beyond x = 10 the straight side is the square plans' nearest (their corners begin at |y| > 15)
    x = np.column_stack([rng.uniform(10, 45, 200), rng.uniform(-4, 4, 200), rng.uniform(-12, 6, 200)])
    for mine, square in ((tools["punch"], punch), (tools["die"], die)):
        g, n = mine.gap(x, 0.3, -2.0)
        gs, ns = square.gap(x, 0.3, -2.0)
        outside = gs > -4.7  # outside the cores
        assert np.allclose(g[outside], gs[outside], atol=1e-12)
        assert np.allclose(n[outside], ns[outside], atol=1e-12)


def test_the_holders_path_comes_down_with_the_ram_and_stops_at_its_gap():
    p = Capped(-18.5, -6.0)
    lam = np.array([0.0, 0.1, 6.0 / 18.5, 0.5, 1.0])
    assert [p.at(v) for v in lam] == pytest.approx([0.0, -1.85, -6.0, -6.0, -6.0])
    assert p.between(0.3, 0.5) == pytest.approx(-(6.0 - 0.3 * 18.5))
    assert p.between(0.5, 1.0) == 0.0
    line = path(-30.0)
    assert isinstance(line, Linear) and line.at(0.37) == 0.37 * -30.0
    assert line.between(0.2, 0.37) == (0.37 - 0.2) * -30.0
    with pytest.raises(ValueError):
        Capped(-18.5, 6.0)
    travel = channel.travel(_spec(150.0))
    assert travel["holder"] == Capped(-18.5, -6.0) and travel["punch"] == Linear(-18.5)


def _changed(**changes):
    return {f"tools.{k}" if "." not in k else k: v for k, v in changes.items()}


@pytest.mark.parametrize("changes, field", [
    ({"binder_rise": 5.0}, "tools.binder_rise"),  # the holder would cut the flat blank's ends
    ({"binder_radius": 30.0}, "tools.binder_radius"),  # the blank's half length is 40
    ({"binder_radius": -1.0}, "tools.binder_radius"),
    ({"stroke": 6.4}, "tools.stroke"),  # not beyond binder_rise + punch_gap
    ({"holder": "force", "holder_gap": 0.0, "blank_holder_force": 1000.0}, "tools.holder"),
    ({"die_half_width": 25.5}, "tools.die_half_width"),  # clearance 0.5 < t
    ({"punch_corner_radius": 5.0}, "tools.punch_corner_radius"),  # a square tool's key
    ({"geometry.lx": 60.0}, "geometry.lx"),  # short of the binder face (31.5)
])
def test_channel_scene_errors_name_the_field(changes, field):
    with pytest.raises(InputError) as err:
        scene.load(DEMO).changed(_changed(**changes))
    assert err.value.field == field


def test_a_short_blank_along_the_channel_is_a_channel_blank():
    """The blank must reach the binder across the channel only: a blank shorter along y than
    the die's opening is wide is a channel's blank."""
    s = scene.load(DEMO).changed({"geometry.ly": 40.0, "tools.binder_rise": 2.0})
    assert s.geometry.ly == 40.0


def test_the_holder_closes_the_blank_onto_the_curved_binder():
    """The ram brings the holder down by binder_rise (6 mm) onto the die's cylindrical binder
    face (R 150): the flange (|x| beyond the binder's edge, 31.5 mm) then lies on the cylinder,
    its mid-surface at the radius R + t/2 from the axis within the holder's clearance (0.8 - t
    = 0.02 mm) and the contact's tolerance (1 % of t), out to its ends 5.3 mm below the crown.
    The blank over the opening, pressed by no binder, follows the wrap within the punch's
    clearance (0.5 mm): its ends lag and touch the punch's face."""
    s = scene.load(DEMO).changed({"mesh.n": 8})
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(s.tools.binder_rise / s.tools.stroke)
    assert p.stroke == pytest.approx(6.0)
    X, x = d.model.mesh.geometry.x[: d.n_owned], d.positions()
    rm = 150.0 + T / 2
    off = np.hypot(x[:, 1], x[:, 2] + rm) - rm  # the mid-surface's distance from the wrapped radius
    flange = X[:, 0] > 31.5 + 2.0
    assert flange.sum() > 10
    assert np.all(off[flange] > -0.01 * T - 1e-9) and np.all(off[flange] < (0.8 - T) + 0.01 * T)
    assert np.all(x[flange & (X[:, 1] > 39.0), 2] < -5.0)  # the ends went down with the holder
    centre = np.abs(X[:, 0]) < 1e-9
    assert np.all(np.abs(off[centre]) < 0.5 + 0.01 * T)


def test_the_studys_channels_wrap_onto_the_binder_and_order_by_the_punchs_friction():
    """docs/results/curved_binder (shellform study curved-binder): on n 16 and 24 the flange
    closed onto the binder lies within the holder's clearance and the contact's tolerance of the
    wrapped radius; with the die and holder at 0.12, the punch's coefficient 0.02 < 0.12 < 0.3
    orders the draw-in and the peak punch force upward and the peak thinning's magnitude
    downward (docs/tools.md: the direction and the literature)."""
    import csv

    rows = list(csv.DictReader(open(Path(__file__).resolve().parents[1] / "docs" / "results" / "curved_binder"
                                    / "channel.csv")))
    curved = [r for r in rows if float(r["binder_radius_mm"]) > 0]
    assert len(curved) == 4
    for r in curved:
        assert 0 < float(r["wrap_flange_mm"]) <= (0.8 - T) + 0.01 * T
    by = {r["case"]: r for r in curved if r["n"] == "16"}
    order = [by[c] for c in ("lubricated punch", "one coefficient", "dry punch")]
    assert [float(r["mu_punch"]) for r in order] == [0.02, 0.12, 0.3]
    for key, sign in (("DX_mm", 1), ("force_peak_kN", 1), ("peak_thinning", 1)):
        values = [sign * float(r[key]) for r in order]
        assert values[0] < values[1] < values[2], key
