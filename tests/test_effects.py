"""The effects registry (shellform/effects.py): every need is enforced naming `effects`, the
solver route, the keys an effect gives a meaning, the linear element's order, and docs/scenes.md
as its rendering."""

import importlib
from pathlib import Path

import pytest

from shellform import effects, scene
from shellform.errors import InputError

ROOT = Path(__file__).resolve().parents[1]


def closure(name) -> list[str]:
    """name and every effect it needs, transitively, in the registry's order."""
    out, todo = set(), [name]
    while todo:
        e = todo.pop()
        if e not in out:
            out.add(e)
            todo += effects.EFFECTS[e].needs
    return list(effects.canonical(out))


def test_each_need_is_enforced_naming_effects():
    """With all its needs on an effect passes the effects check; without any one of them the
    scene is refused naming `effects`, and the message names the missing effect."""
    checked = 0
    for name, e in effects.EFFECTS.items():
        full = closure(name)
        if "bending" not in full and "membrane" not in full:
            full = ["bending"] + full
        effects.check(full)
        for need in e.needs:
            without = [x for x in full if x != need]
            with pytest.raises(InputError) as err:
                scene.from_dict({"effects": without})
            assert err.value.field == "effects"
            assert repr(need) in str(err.value), (name, need, str(err.value))
            checked += 1
    assert checked >= 12


@pytest.mark.parametrize("bad", [["bending", "sticking"], ["bending", "bending"], ["shallow_curvature"], []])
def test_unknown_twice_or_nothing_assembled_names_effects(bad):
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": bad})
    assert err.value.field == "effects"


def test_the_route_is_the_first_solver_that_knows_every_effect():
    linear = scene.from_dict({"effects": ["bending", "membrane", "cubic_membrane"]})
    sheet = scene.from_dict({"effects": ["bending", "membrane", "assumed_membrane"]})
    assert (linear.route, linear.nonlinear) == (effects.LINEAR, False)
    assert (sheet.route, sheet.nonlinear) == (effects.SHEET, True)
    assert scene.load(ROOT / "demos" / "square_cup.toml").route == effects.TOOLS
    with pytest.raises(InputError) as err:  # the nonlinear sheet's in-plane field is cubic already
        scene.from_dict({"effects": ["bending", "membrane", "cubic_membrane", "geometric_nonlinearity"]})
    assert err.value.field == "effects" and "'cubic_membrane'" in str(err.value)


def test_keys_of_an_effect_that_is_off_keep_their_defaults():
    """Every dotted key of the registry's `keys`, set away from its default without its effect,
    is refused naming that key; with the effect (and its needs) on, the same value is taken."""
    values = {"surface.R1": 2.0, "surface.R2": 3.0, "surface.z0": "0.1*x*y", "material.hardening": "power",
              "material.yield_stress": 1e-3, "material.n": 5.0, "material.K": 1.0, "material.eps0": 0.01,
              "material.r": 1.5, "material.m": 8.0, "material.yield_function": "hill48",
              "material.rolling_direction": 30.0, "material.r0": 1.8, "material.r45": 1.5, "material.r90": 2.3,
              "material.sigma0": 1.0, "material.sigma45": 1.0, "material.sigma90": 1.0, "material.sigma_b": 1.0, "material.r_b": 0.7, "material.a": 8.0,
              "material.alpha": [1.0] * 8, "material.fit_angles": [0.0, 45.0, 90.0], "material.fit_r": [0.5] * 3,
              "material.fit_sigma": [1.0] * 3, "material.coefficients": [1.0] * 16,
              "material.Q": 100.0, "material.beta": 10.0, "material.swift_weight": 0.5, "material.flow_curve": "c.csv",
              "material.extrapolation": "swift", "material.forming_limit_curve": "flc.csv",
              "tools.friction": 0.1, "tools.punch_friction": 0.02, "tools.die_friction": 0.1,
              "tools.holder_friction": 0.15,
              "tools.drawbead": [{"points": [[45.0, 0.0], [45.0, 50.0]], "restraint": 10.0}]}
    base = {"effects": ["bending", "membrane", "geometric_nonlinearity", "contact"],
            "geometry": {"lx": 100.0, "ly": 100.0, "region": "quarter"}, "material": {"thickness": 0.8},
            "supports": {"left": "symmetry", "bottom": "symmetry"}, "tools": {"stroke": 10.0}}
    seen = set()
    for e in effects.EFFECTS.values():
        for key in (k for k in e.keys if "." in k):
            table, _, name = key.partition(".")
            data = {**base, table: {**base.get(table, {}), name: values[key]}}
            with pytest.raises(InputError) as err:
                scene.from_dict(data)
            assert err.value.field == key and repr(e.name) in str(err.value)
            seen.add(key)
    assert seen == set(values)
    curved = scene.from_dict({"effects": ["bending", "membrane", "shallow_curvature"], "surface": {"R1": 2.0}})
    assert curved.surface.R1 == 2.0


def test_the_linear_element_follows_the_registry():
    """The element's fields and the functional's terms come in the registry's order, and only
    for the effects that are on."""
    from shellform.assembly.hybrid_element import GROUPS, HybridElement
    from shellform.forms import functional

    assert GROUPS == tuple(n for n, e in effects.EFFECTS.items() if e.kind == "form term")
    element = HybridElement(("cubic_membrane", "bending", "membrane"))
    assert element.effects == effects.canonical(("bending", "membrane", "cubic_membrane"))
    assert element.groups == GROUPS
    assert HybridElement(("bending",)).carrier_components == ("w", "w_x", "w_y")
    assert effects.form_terms(("bending",)) == [functional.bending_terms]
    assert effects.form_terms(("shallow_curvature", "bending", "membrane")) == [functional.membrane_terms,
                                                                                 functional.bending_terms]


def test_docs_list_every_effect_as_the_registry_does():
    """docs/scenes.md holds the registry's table as `python -m shellform.effects` renders it, so
    that every effect is listed with what it switches on and needs."""
    text = (ROOT / "docs" / "scenes.md").read_text()
    for name in effects.EFFECTS:
        assert f"| `{name}` |" in text, name
    assert effects.markdown_table() in text


def test_every_part_exists():
    for e in effects.EFFECTS.values():
        assert e.kind in effects.KINDS and e.routes and set(e.routes) <= set(effects.ROUTES)
        assert set(e.needs) <= set(effects.EFFECTS)
        try:
            importlib.import_module(e.part)
        except ModuleNotFoundError:
            module, _, attribute = e.part.rpartition(".")
            assert hasattr(importlib.import_module(module), attribute), e.part
