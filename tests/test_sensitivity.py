"""Sensitivities from one run (shellform.nonlinear.sensitivity): direct differentiation through
the increments against closed forms and against finite differences of whole runs
(docs/sensitivity.md)."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import csv
from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from shellform.errors import InputError
from shellform.nonlinear.problem import SheetProblem
from shellform.nonlinear.sensitivity import Sensitivity
from shellform.studies import strip
from shellform.assembly.sheet_element import BS
from shellform.studies.sensitivity import (drawn_cup, material_parameters, plate, pulled_strip, rim_node,
                                           swift_derivatives, value_of)

STEEL = strip.mild_steel()


def test_the_homogeneous_strip_against_the_closed_form():
    """The nominal stress tau / lambda at a stretch of 1.5, after ten plastic increments whose
    history sensitivities carry each one's plastic strain on: d/dK, d/dn, d/dE to 1e-6 of the
    implicit derivative of tau = sigma_f(ln lambda - tau / E)."""
    p, s = pulled_strip(STEEL, True, ("K", "n", "E"))
    tau, exact = swift_derivatives(STEEL, 1.5)
    area = strip.WIDTH * strip.T0
    assert p.reaction("right", "u") / area == pytest.approx(tau / 1.5, rel=1e-8)
    for name, d in exact.items():
        got = p.reaction("right", "u", residual=s.residual(name)) / area
        assert got == pytest.approx(d / 1.5, rel=1e-6), name
    assert s.switches == [0] * 10  # every layer plastic throughout, the path smooth
    assert max(s.free_residual) < 1e-5


def test_the_free_strip_against_finite_differences_of_two_runs():
    """The strip's end pulled: the force and the width's contraction (v at the free corner), for
    K, n and nu, against central differences of two runs at p(1 +- 1e-4) (their error about
    1e-8 of the value); where a derivative is near zero (the force's in nu), against the force's
    own scale F / p."""
    p, s = pulled_strip(STEEL, False, ("K", "n", "nu"))
    F = p.reaction("right", "u")
    for name in ("K", "n", "nu"):
        value = getattr(STEEL, name)
        h = 1e-4 * value
        plus, _ = pulled_strip(replace(STEEL, **{name: value + h}), False)
        minus, _ = pulled_strip(replace(STEEL, **{name: value - h}), False)
        fd_force = (plus.reaction("right", "u") - minus.reaction("right", "u")) / (2 * h)
        fd_v = (plus.value("v", strip.LENGTH, strip.WIDTH) - minus.value("v", strip.LENGTH, strip.WIDTH)) / (2 * h)
        force = p.reaction("right", "u", residual=s.residual(name))
        v = value_of(p, s, name, "v", strip.LENGTH, strip.WIDTH)
        assert abs(force - fd_force) <= 1e-6 * max(abs(fd_force), abs(F / value)), name
        assert v == pytest.approx(fd_v, rel=1e-6), name


def centre_sensitivity(p, s, name):
    return value_of(p, s, name, "w", 0.0, 0.0)


def test_the_plate_in_large_deflection_is_homogeneous_in_E_and_the_pressure():
    """An elastic sheet's stresses scale with E, so w(E, P) = W(P / E) and
    E dw/dE + P dw/dP = 0 exactly: both sensitivities from one run, to 1e-6 of w's own scale;
    the deflection is large (w about 3 t, dw/dP far from w / P)."""
    E, P = 70e3, 5.0
    p, s = plate(E, P, ("bending", "membrane", "geometric_nonlinearity"), sensitivities=True)
    w = p.value("w", 0.0, 0.0)
    dE, dP = centre_sensitivity(p, s, "E"), centre_sensitivity(p, s, "pressure")
    assert abs(w) > 1.0  # large deflection
    assert abs(dP * P / w - 1) > 0.3  # far from linear
    assert abs(E * dE + P * dP) <= 1e-6 * abs(w)


def test_the_linear_plate_deflects_as_one_over_E():
    """Without geometric nonlinearity w = c P / E: dw/dE = -w / E and dw/dP = w / P, to 1e-6."""
    E, P = 70e3, 1e-4
    p, s = plate(E, P, ("bending",), sensitivities=True)
    w = p.value("w", 0.0, 0.0)
    assert centre_sensitivity(p, s, "E") == pytest.approx(-w / E, rel=1e-6)
    assert centre_sensitivity(p, s, "pressure") == pytest.approx(w / P, rel=1e-6)


def test_the_sensitivities_do_not_change_the_run():
    """The run with sensitivities takes the same increments to the same state, bit for bit."""
    p, _ = pulled_strip(STEEL, False, ("K",))
    q, _ = pulled_strip(STEEL, False)
    assert np.array_equal(p.driver.q.x.array, q.driver.q.x.array)
    assert np.array_equal(p.driver.residual_full, q.driver.residual_full)
    assert [h.iterations for h in p.driver.history] == [h.iterations for h in q.driver.history]


class _PartsState:
    """A record that keeps every part's iterate state (Part.iterate_state) at each converged
    increment; with `before`, another such record, it lists the increments where the parts'
    state differs from what `before` saw."""

    def __init__(self, before=None):
        self.before, self.states, self.changed = before, [], []

    def converged(self, driver, lam):
        self.states.append([part.iterate_state() for part in driver.parts])
        if self.before is not None and not _same(self.before.states[-1], self.states[-1]):
            self.changed.append(len(self.states))

    def checkpoint(self):
        return {}

    def restore(self, state):
        pass


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_the_sensitivities_leave_the_parts_as_the_last_iterate_left_them():
    """The sensitivities linearize the converged state as Newton's iterates see it, which moves
    the contact set's net forces and friction's normal forces to the converged q; they put every
    part back (Driver.linearized), so that the run goes on as without them: the round cup ironed
    at a gap, with friction (n 6, 1.5 mm), every part's state the same before and after the
    sensitivities at every increment (without the putting back, all 15 increments differ)."""
    from shellform.contact.problem import DrawingProblem
    from shellform.nonlinear.sensitivity import scene_parameters

    s, _ = drawn_cup({"tools.holder": "gap", "tools.holder_gap": 1.0}, friction=True, ironing=True, stroke=1.5,
                     scene_only=True)
    p = DrawingProblem.from_scene(s, verbose=False)
    before = _PartsState()
    after = _PartsState(before)
    p.driver.records += [before, Sensitivity(p.driver, scene_parameters(
        s.changed({"output.sensitivities": ["tools.friction"]}))), after]
    p.driver.run(1.0)
    assert len(after.states) == 15 and after.changed == []


@pytest.mark.slow  # two runs, about 2.5 min
def test_a_run_with_sensitivities_is_the_run_without():
    """A 1.19 mm sheet drawn 25 mm into the round cup's 1.2 mm clearance (n 6), which the die's
    shoulder and the punch iron: with d/dK the run takes the same 253 increments to the same
    state, bit for bit (with the parts left at the converged state it took 250: a later step
    decision went the other way)."""
    changes = {"tools.holder": "gap", "tools.holder_gap": 1.3, "material.thickness": 1.19}
    p, _ = drawn_cup(changes, sensitivities=("material.K",), friction=True, ironing=True, stroke=25.0)
    q, _ = drawn_cup(changes, friction=True, ironing=True, stroke=25.0)
    assert [h.iterations for h in p.driver.history] == [h.iterations for h in q.driver.history]
    assert np.array_equal(p.driver.q.x.array, q.driver.q.x.array)


def test_the_frictionless_cup_against_finite_differences_of_two_runs():
    """Rigid punch and die (the round cup without friction, holder force and ironing), n 6, 3 mm:
    the punch force and the rim's draw-in, d/dK from one run against central differences of two
    runs at K (1 +- 1e-5), to 1e-6 (measured 2e-10 and 4e-9: docs/sensitivity.md). The nodes on
    the tools carry the known jump h_i' of their half thickness; without it the draw-in misses
    by 0.5 %."""
    p, s = drawn_cup(sensitivities=("material.K",))
    assert p.driver.count_in_contact()["tool0"] > 0 and p.driver.count_in_contact()["tool1"] > 0
    K = float(p.scene.material.K)
    h = 1e-5 * K
    plus, minus = drawn_cup({"material.K": K + h})[0], drawn_cup({"material.K": K - h})[0]
    i = rim_node(p)
    force = (plus.punch_force() - minus.punch_force()) / (2 * h)
    draw = -(plus.driver.positions()[i, 0] - minus.driver.positions()[i, 0]) / (2 * h)
    assert p.punch_force(residual=s.residual("material.K")) == pytest.approx(force, rel=1e-6)
    assert -s.carrier("material.K").reshape(-1, BS)[i, 0] == pytest.approx(draw, rel=1e-6)
    assert max(s.free_residual) < 1e-5  # the frames' turn on the curved tools included (2e-7 measured)
    assert not s.corrected and sum(s.corrections) == 0  # every part's tangent exact: nothing corrected


@pytest.mark.slow  # five runs, about 13 s
def test_the_cup_with_friction_against_finite_differences_of_two_runs():
    """The round cup with its Coulomb friction (0.07), no holder force (n 6, 3 mm): d/dmu
    (tools.friction) and d/dK of the punch force and the rim's draw-in against central
    differences at p (1 +- 1e-5): to 1e-4 (measured 4e-6 and 7e-6 in mu, 2e-7 in K:
    docs/sensitivity.md). Friction carries its history's derivative (the committed forces) and
    adds the normal forces' and its coefficient's to the pseudo-load, the stick and slip states
    held."""
    p, s = drawn_cup(sensitivities=("material.K", "tools.friction"), friction=True)
    assert p.driver.friction.slipping.any()
    i = rim_node(p)
    for key, value in (("tools.friction", float(p.scene.tools.friction)), ("material.K", float(p.scene.material.K))):
        h = 1e-5 * value
        plus, minus = (drawn_cup({key: value + sign * h}, friction=True)[0] for sign in (1, -1))
        force = (plus.punch_force() - minus.punch_force()) / (2 * h)
        draw = -(plus.driver.positions()[i, 0] - minus.driver.positions()[i, 0]) / (2 * h)
        assert p.punch_force(residual=s.residual(key)) == pytest.approx(force, rel=1e-4), key
        assert -s.carrier(key).reshape(-1, BS)[i, 0] == pytest.approx(draw, rel=1e-4), key
    assert max(s.free_residual) < 1e-3


def _cup_against_differences(key, rel, changes=None, at=None, **cup):
    """d/dp of the punch force and the rim's draw-in of the round cup with friction (n 6, 3 mm;
    `cup`: drawn_cup's holder and ironing; with `changes` to its scene) against central
    differences of two runs at p (1 +- 1e-5), whose scenes are at(p) (default: `changes` with the
    key at p): (the problem, its Sensitivity)."""
    p, s = drawn_cup(changes, sensitivities=(key,), friction=True, **cup)
    i = rim_node(p)
    value = float(s.parameters[0].value)
    h = 1e-5 * value
    at = at or (lambda v: {**(changes or {}), key: v})
    plus, minus = (drawn_cup(at(value + sign * h), friction=True, **cup)[0] for sign in (1, -1))
    force = (plus.punch_force() - minus.punch_force()) / (2 * h)
    draw = -(plus.driver.positions()[i, 0] - minus.driver.positions()[i, 0]) / (2 * h)
    assert p.punch_force(residual=s.residual(key)) == pytest.approx(force, rel=rel)
    assert -s.carrier(key).reshape(-1, BS)[i, 0] == pytest.approx(draw, rel=rel)
    return p, s


def _holder_cup_against_differences(key, rel, changes=None, closed=True, at=None):
    """_cup_against_differences with the round cup's holder (10 kN), closed at the end (or
    open, with `closed` False): the Sensitivity."""
    p, s = _cup_against_differences(key, rel, changes, at, holder=True)
    if closed:
        assert p.driver.holder.closed and p.driver.holder.pinched.sum() > 10
    else:
        assert p.driver.holder.is_open and p.driver.holder.on_face()[1] > 0
    return s


def test_the_cup_with_a_holder_against_finite_differences_of_two_runs():
    """d/dF (tools.blank_holder_force): F enters only through the holder's split, which friction
    presses with on the pinched nodes; to 1e-3 (measured 3e-6 in the force, 1.3e-4 in the
    draw-in). The friction's tangent holds the split's spread (F's share per node) and its band
    fixed, so the solve is corrected against the total derivative: the free rows' total after
    the corrections is below the threshold, 1e-4 of the loads' (5e-5 measured; 2e-3
    uncorrected)."""
    s = _holder_cup_against_differences("tools.blank_holder_force", 1e-3)
    assert s.corrected and sum(s.corrections) > 0 and max(s.free_residual) < 1e-4


@pytest.mark.parametrize("key", ["tools.blank_holder_force", pytest.param("material.K", marks=pytest.mark.slow),
                                 pytest.param("tools.friction", marks=pytest.mark.slow)])
def test_an_open_holders_lift_is_differentiated(key):
    """A light holder (300 N) opens in the first millimetres and rides on 5 nodes, its lift an
    unknown of its own, solved with the derivative as with Newton's step
    (Part.border_derivative), its conforming face's known rows -h_i' (not the contact set's
    +h_i'): d/dF, d/dK and d/dmu against two runs, to 1e-3 (measured 2.5e-5 / 3.3e-5 in F,
    9e-8 / 2.9e-4 in K, 2.4e-6 / 3.6e-5 in mu; without the lift's derivative d/dF reads 0 and
    d/dmu misses by 0.8 % / 8 %; with +h_i' d/dK's draw-in misses by 3.6e-3)."""
    _holder_cup_against_differences(key, 1e-3, {"tools.blank_holder_force": 300.0}, closed=False)


@pytest.mark.slow  # three runs each, about 25 s
@pytest.mark.parametrize("key", ["material.K", "tools.friction"])
def test_the_cup_with_a_holder_in_k_and_mu(key):
    """d/dK and d/dmu with the holder: its edge load moves with K (its strip solved again), the
    coefficient with mu; to 1e-3 (measured 4e-7 / 7e-4 in K, 7e-5 / 1.3e-4 in mu)."""
    _holder_cup_against_differences(key, 1e-3)


@pytest.mark.parametrize("key, rel", [("tools.friction", 1e-4), pytest.param("material.K", 1e-3, marks=pytest.mark.slow),
                                      pytest.param("material.E", 2e-2, marks=pytest.mark.slow)])
def test_the_cup_ironed_at_a_gap_against_finite_differences_of_two_runs(key, rel):
    """The round cup's flange held at a gap of the sheet's thickness (1.0 mm), which irons it
    from the first increments: d/dmu, d/dK and d/dE of the punch force and the rim's draw-in
    against two runs (measured 9.7e-6 / 1.1e-5 in mu, 4e-7 / 1e-4 in K, 2.3e-6 / 1e-2 in E, whose
    draw-in derivative is 6e-9 mm/MPa). The faces' penalty takes the material's modulus, and the
    nodes the clearance bounds have the known row c_i'/2 = 0 between parallel faces, not h_i':
    with h_i' (and the clearance held in the differences) the draw-in misses by 2.1e-4 in mu and
    1e-3 in K; with the scene's modulus held the force misses by 5 % in E."""
    p, _ = _cup_against_differences(key, rel, {"tools.holder": "gap", "tools.holder_gap": 1.0}, ironing=True)
    pressed = [part.report()["ironed_cells"] for part in p.driver.parts if "ironed_cells" in part.report()]
    assert pressed and pressed[0] > 10


def _bead(restraint=30.0, uplift=5.0):
    """A drawbead on the round cup's flange: a quarter circle of radius 47 mm (7 points), 30 N/mm
    restraint, 5 N/mm uplift."""
    from shellform import demos, scene

    effects = [e for e in scene.load(demos.path("round_cup.toml")).effects if e != "ironing"] + ["drawbeads"]
    angles = np.linspace(0.0, np.pi / 2, 7)
    return {"effects": effects, "tools.drawbead": [{"points": [[47 * np.cos(a), 47 * np.sin(a)] for a in angles],
                                                    "restraint": restraint, "uplift": uplift}]}


@pytest.mark.parametrize("key", ["restraint", pytest.param("uplift", marks=pytest.mark.slow)])
def test_the_cup_in_a_drawbeads_own_forces(key):
    """tools.drawbead[0].restraint and .uplift as parameters: d/dp of the punch force and the
    rim's draw-in against two runs with that bead's force at p (1 +- 1e-5), to 1e-4 (measured
    3e-6 and 5e-6 in both)."""
    _holder_cup_against_differences(f"tools.drawbead[0].{key}", 1e-4, _bead(), at=lambda v: _bead(**{key: v}))


def test_the_cup_with_a_drawbead_in_mu():
    """With a drawbead across the flange (its 23 nodes slipping), d/dmu of the punch force and
    the rim's draw-in against two runs to 1e-4 (measured 2e-6 and 6e-6): the bead's forces move
    with the positions (its shares), its history and the committed positions, and its uplift
    enters the holder's split and friction's normal forces."""
    s = _holder_cup_against_differences("tools.friction", 1e-4, _bead())
    assert s.corrected and max(s.free_residual) < 1e-3


@pytest.mark.slow  # three runs each, about 12 s
@pytest.mark.parametrize("key, rel", [("material.K", 1e-5), ("tools.blank_holder_force", 1e-4), ("material.E", 2e-3)])
def test_the_cup_with_a_drawbead_in_k_f_and_e(key, rel):
    """The drawbead's cup in K, the holder's force and E (whose stiffness k_i = E t l_i / h the
    bead's stick law takes): measured 3e-8 / 6e-7, 3e-6 / 5e-6 and 1e-5 / 4e-4 (E's draw-in: the
    holder's edge strip moves with E as well)."""
    _holder_cup_against_differences(key, rel, _bead())


def test_a_tool_scene_reports_its_answers_sensitivities(tmp_path):
    """The frictionless round cup as a scene with `[output] sensitivities` and the forming-limit
    view (n 6, reports at 1.5 and 3 mm): each report carries d/dp of DX, DY, DD, the punch force,
    the peak thinning and the smallest margin to the forming-limit curve, sensitivities.csv (by
    stroke_mm) is written; at 3 mm d/dr of all six against central differences of two runs at
    r (1 +- 1e-5), to 1e-6 (measured 2e-9 to 2e-8; the margin's 5e-7, to 1e-5), and the margin's
    d/dn, which moves Keeler-Brazier's curve as well as the strains, to 1e-6 (measured 4e-11)."""
    import csv
    import json

    from shellform.contact.run import run
    from shellform.results import fld

    scene_, _ = drawn_cup(scene_only=True)
    s = scene_.changed({"output.sensitivities": ["material.K", "material.r", "material.n"], "process.report": [0.5],
                        "output.png": False, "output.vtx": False, "output.fld": True})
    run(s, tmp_path / "one")
    summary = json.loads((tmp_path / "one" / "summary.json").read_text())
    last = summary["reports"][-1]
    assert [r["stroke_mm"] for r in summary["reports"]] == pytest.approx([1.5, 3.0])
    r0 = float(s.material.r)
    h = 1e-5 * r0
    ends = [drawn_cup({"material.r": r0 + sign * h})[0] for sign in (1, -1)]
    from shellform.results import cup

    def margin(e, key, value):
        f = e.cell_fields()
        return float(fld.margins(f["major_strain"], f["minor_strain"], fld.curve_of(s, key, value)).min())

    states = [{**cup.draw_in(e), "punch_force_kN": e.punch_force() / 1e3,
               "min_thickness_strain": cup.peak_thinning(e)["min_thickness_strain"],
               "min_margin": margin(e, "material.r", r0 + sign * h)} for e, sign in zip(ends, (1, -1))]
    for answer in ("DX", "DY", "DD", "punch_force_kN", "min_thickness_strain", "min_margin"):
        fd = (states[0][answer] - states[1][answer]) / (2 * h)
        rel = 1e-5 if answer == "min_margin" else 1e-6
        assert last["sensitivities"]["material.r"][answer] == pytest.approx(fd, rel=rel), answer
    n0 = float(s.material.n)
    hn = 1e-5 * n0
    fd = (margin(drawn_cup({"material.n": n0 + hn})[0], "material.n", n0 + hn)
          - margin(drawn_cup({"material.n": n0 - hn})[0], "material.n", n0 - hn)) / (2 * hn)
    assert last["sensitivities"]["material.n"]["min_margin"] == pytest.approx(fd, rel=1e-6)
    rows = list(csv.DictReader(open(tmp_path / "one" / "sensitivities.csv")))
    assert rows[0]["stroke_mm"] and {r["answer"] for r in rows} == {"DX", "DY", "DD", "punch_force_kN",
                                                                   "min_thickness_strain", "min_margin"}
    assert summary["sensitivity_checks"]["largest_free_residual"] < 1e-3


@pytest.mark.parametrize("changes, field", [
    ({"output.sensitivities": ["tools.blank_holder_force"]}, "output.sensitivities (tools.blank_holder_force)"),
    ({"tools.blank_holder_force": 1000.0, "tools.holder": "gap", "tools.holder_gap": 1.04,
      "output.sensitivities": ["tools.blank_holder_force"]}, "output.sensitivities (tools.blank_holder_force)"),
    ({"output.sensitivities": ["tools.friction"]}, "output.sensitivities (tools.friction)"),  # no friction
    ({"effects": "friction", "tools.friction": 0.1, "tools.punch_friction": 0.02,
      "output.sensitivities": ["tools.die_friction"]}, "output.sensitivities (tools.die_friction)"),  # unset
    ({"output.sensitivities": ["material.thickness"]}, "output.sensitivities (material.thickness)"),
    ({"output.sensitivities": ["tools.drawbead[0].restraint"]}, "output.sensitivities (tools.drawbead[0].restraint)"),
    ({"output.sensitivities": ["tools.drawbead[1].uplift"], "effects": "drawbeads",
      "tools.drawbead": [{"points": [[47.0, 0.0], [0.0, 47.0]], "restraint": 30.0}]},
     "output.sensitivities (tools.drawbead[1].uplift)"),
    ({"effects": "no finite_strain"}, "effects"),
])
def test_a_tool_scenes_bad_sensitivities_are_named(changes, field):
    scene_, _ = drawn_cup(scene_only=True)
    effects = list(scene_.effects)
    if changes.get("effects") in ("friction", "drawbeads"):
        effects.append(changes["effects"])
    elif changes.get("effects") == "no finite_strain":
        effects.remove("finite_strain")
    with pytest.raises(InputError) as err:
        scene_.changed({"output.sensitivities": ["material.K"], "effects": effects,
                        **{k: v for k, v in changes.items() if k != "effects"}})
    assert err.value.field == field


def test_a_driver_with_parts_is_refused():
    from shellform.nonlinear.parts import Part

    p = SheetProblem.on_rectangle(MPI.COMM_WORLD, 2.0, 2.0, 1, STEEL, 1.0, strip.effects(True),
                                  supports={"left": "clamped"}, parts=[lambda model: Part()])
    with pytest.raises(InputError, match="output.sensitivities"):
        Sensitivity(p.driver, material_parameters(STEEL, ("K",)))


def test_a_scene_reports_its_sensitivities_and_their_uncertainty(tmp_path):
    """`[output] sensitivities` and `scatter` on a sheet scene: every report carries d/dp of its
    answers (the cantilever's largest w against central differences of two runs, to 1e-6),
    sensitivities.csv and tornado.png are written, and summary.json gives each answer's first-order
    standard deviation sqrt(sum (da/dp s_p)^2) with the parameters' shares summing to 1."""
    import json

    from shellform.run import run
    from shellform.studies.sensitivity import CANTILEVER, cantilever_scene

    scatter = [0.05, 50.0, 1e-5, 0.001]
    s = cantilever_scene(True).changed({"output.scatter": scatter, "output.png": True, "process.report": [0.5]})
    summary = run(s, tmp_path / "one")
    data = json.loads((tmp_path / "one" / "summary.json").read_text(),
                      parse_constant=lambda c: pytest.fail(f"summary.json holds {c}"))
    assert [r["load_factor"] for r in data["reports"]] == pytest.approx([0.5, 1.0], abs=1e-12)
    last = data["reports"][-1]["sensitivities"]
    assert list(last) == list(CANTILEVER)
    key, value = "material.K", CANTILEVER["material.K"]
    h = 1e-4 * value
    plain = cantilever_scene(False)
    ends = [run(plain.changed({key: value + d}), tmp_path / f"fd{i}")["reports"][-1]["extremes"]["w"]["value"]
            for i, d in enumerate((h, -h))]
    assert last[key]["extreme_w"] == pytest.approx((ends[0] - ends[1]) / (2 * h), rel=1e-6)
    w = data["uncertainty"]["extreme_w"]
    sd = np.sqrt(sum((last[k]["extreme_w"] * sd_k) ** 2 for k, sd_k in zip(CANTILEVER, scatter)))
    assert w["sd"] == pytest.approx(sd, rel=1e-12)
    assert sum(w["shares"].values()) == pytest.approx(1.0, rel=1e-12)
    rows = (tmp_path / "one" / "sensitivities.csv").read_text().splitlines()
    assert rows[0].split(",")[:3] == ["load_factor", "answer", "parameter"]
    assert len(rows) == 1 + 2 * 4 * len(last[key])  # two reports, four parameters, every answer
    assert (tmp_path / "one" / "tornado.png").stat().st_size > 10_000
    assert summary["reports"][-1]["sensitivities"] == last


@pytest.mark.parametrize("changes, field", [
    ({"output.sensitivities": ["material.Q"]}, "output.sensitivities (material.Q)"),  # not used by Swift
    ({"output.sensitivities": ["tools.friction"]}, "output.sensitivities (tools.friction)"),
    ({"output.sensitivities": ["material.K", "material.K"]}, "output.sensitivities"),
    ({"output.sensitivities": ["material.K"], "output.scatter": [0.1, 0.2]}, "output.scatter"),
    ({"output.sensitivities": ["material.K"], "output.scatter": [-0.1]}, "output.scatter[0]"),
    ({"output.sensitivities": [], "output.scatter": [0.1]}, "output.scatter"),
])
def test_bad_sensitivities_are_named(changes, field):
    from shellform.studies.sensitivity import cantilever_scene

    with pytest.raises(InputError) as err:
        cantilever_scene(False).changed(changes)
    assert err.value.field == field


def test_the_sensitivities_go_through_a_checkpoint(tmp_path):
    """A checkpoint holds dq/dp and the material state's d/dp; a driver that resumes from it
    continues with them (the history sensitivities a path-dependent derivative needs)."""
    from shellform.nonlinear import checkpoint

    p, s = pulled_strip(STEEL, False, ("K", "n"))
    p.driver.checkpoint_dir = tmp_path
    p.driver.save_checkpoint()
    q, _ = pulled_strip(STEEL, False)  # a driver at the same mesh, then given sensitivities and the checkpoint
    r = Sensitivity(q.driver, s.parameters)
    q.driver.records.append(r)
    q.driver.resume(checkpoint.read(tmp_path))
    for name in ("K", "n"):
        owned = q.driver.n_owned * 9
        assert np.array_equal(r.carrier(name)[:owned], s.carrier(name)[:owned])
        for key, values in s.state(name).items():
            assert np.array_equal(r.state(name)[key], values), key


def test_a_curved_clamped_rim_keeps_the_homogeneity(tmp_path):
    """demos/clamped_disc_large_deflection.toml, its rim held in its vertices' own frames
    (edge_frames.py): the sensitivities pass through those frames, and E dw/dE + P dw/dP = 0 at
    the centre to 1e-6 of w (w about 0.97 t, membrane-stiffened)."""
    from shellform import demos
    from shellform.run import run
    from shellform.scene import load

    s = load(demos.path("clamped_disc_large_deflection.toml")).changed(
        {"output.sensitivities": ["material.E", "loads.pressure"], "output.vtx": False, "output.vtu": False,
         "output.png": False})
    report = run(s, tmp_path / "disc")["reports"][-1]
    d = report["sensitivities"]
    E, P = s.material.E, s.loads.pressure
    assert abs(report["w"]) > 0.5 * s.material.thickness
    assert abs(E * d["material.E"]["w"] + P * d["loads.pressure"]["w"]) <= 1e-6 * abs(report["w"])


def test_an_increment_ending_at_the_yield_point_is_flagged():
    """A perfectly plastic strip (yield stress K) stretched homogeneously in one increment to
    exactly its yield strain ln(lambda) = K / E: at K + eps it is elastic (d tau / dK = 0), at
    K - eps it flows (d tau / dK = 1). The central difference lies between the one-sided
    derivatives, and the increment's layers are counted as switching."""
    from shellform.material import Hill79Material
    from shellform.nonlinear.driver import Controls

    mat = Hill79Material(E=1000.0, nu=0.3, hardening="swift", K=10.0, eps0=1.0, n=0.0)
    a = np.exp(mat.K / mat.E) - 1.0
    held = {("all", "u"): lambda x, y: a * x, ("all", "u_x"): a, ("all", "u_y"): 0.0}
    p = SheetProblem.on_rectangle(MPI.COMM_WORLD, 2 * strip.LENGTH, 2 * strip.WIDTH, 1, mat, strip.T0,
                                  strip.effects(True), region="quarter",
                                  supports={"left": "symmetry", "bottom": "symmetry"}, prescribed=held,
                                  controls=Controls(initial_step=1.0, max_step=1.0, rtol=1e-12))
    s = Sensitivity(p.driver, material_parameters(mat, ("K",)))
    p.driver.records.append(s)
    p.driver.run(1.0)
    tau = (1 + a) / (strip.WIDTH * strip.T0)
    assert p.reaction("right", "u") * tau == pytest.approx(mat.K, rel=1e-9)
    assert 0.3 < p.reaction("right", "u", residual=s.residual("K")) * tau < 0.7
    assert s.switches[0] > 0


def _springback_against_differences(tmp_path, names, holder):
    """The round cup (drawn_cup, n 6, 3 mm) drawn and sprung back as a scene with `names` in
    `[output] sensitivities`: per parameter and springback answer (the flange edge's move in z
    and in the distance from the centre, transverse and diagonal) the one-run derivative and
    central differences of two runs at p (1 +- 1e-5)."""
    from shellform.contact.run import run

    scene_, _ = drawn_cup(scene_only=True, friction=holder, holder=holder)
    base = scene_.changed({"process.springback": True, "output.png": False, "output.vtx": False,
                           "output.fld": False})
    one = run(base.changed({"output.sensitivities": names}), tmp_path / "one")["springback"]["sensitivities"]
    rows = list(csv.DictReader(open(tmp_path / "one" / "springback_sensitivities.csv")))
    assert len(rows) == 6 * len(names) and {r["parameter"] for r in rows} == set(names)
    assert float(next(r for r in rows if r["answer"] == "flange_edge_dz_mm.transverse")["derivative"]) == \
        pytest.approx(one[names[0]]["flange_edge_dz_mm"]["transverse"], rel=1e-5)  # the CSV's six digits
    out = []
    for name in names:
        section, _, key = name.partition(".")
        value = float(getattr(getattr(base, section), key))
        h = 1e-5 * value
        ends = [run(base.changed({name: value + sign * h}), tmp_path / f"{key}{sign}")["springback"] for sign in (1, -1)]
        for answer in ("flange_edge_dz_mm", "flange_edge_dr_mm"):
            fd = {line: (ends[0][answer][line] - ends[1][answer][line]) / (2 * h) for line in ("transverse", "diagonal")}
            out += [(name, answer, line, one[name][answer][line], fd[line], max(map(abs, fd.values()))) for line in fd]
    return out


def test_springback_carries_the_sensitivities(tmp_path):
    """The frictionless round cup's springback (the tools' forces released, contact/springback.py)
    carries the drawing's q', h' on, its released forces moving with the drawn state's dR/dp
    (Sensitivity.released): the flange edge's moves in K and r against central differences of two
    whole runs, to 1e-5 (measured 3e-8 to 3e-7: docs/sensitivity.md)."""
    for name, answer, line, one, fd, _ in _springback_against_differences(tmp_path, ["material.K", "material.r"],
                                                                          holder=False):
        assert one == pytest.approx(fd, rel=1e-5), (name, answer, line)


@pytest.mark.slow  # five runs with springback, about 30 s
def test_springback_with_the_holder_and_friction_carries_the_sensitivities(tmp_path):
    """With the holder (10 kN) and friction (0.07): d/dr and d/dmu of the flange edge's moves
    against differences of two runs, each within 1 % of the answer's largest derivative over the
    two lines (measured up to 0.2 %: the drawing's own derivatives miss by up to 1e-4 here, and a
    move is the difference of two states; docs/sensitivity.md)."""
    rows = _springback_against_differences(tmp_path, ["material.r", "tools.friction"], holder=True)
    for name, answer, line, one, fd, scale in rows:
        assert abs(one - fd) <= 1e-2 * scale, (name, answer, line, one, fd)
