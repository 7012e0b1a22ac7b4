"""Scene.changed: a changed scene is read and checked as a scene file is, and the studies derive
their scenes through it."""

from pathlib import Path

import pytest

from shellform import scene
from shellform.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
CUP = ROOT / "demos" / "square_cup.toml"


@pytest.mark.parametrize("changes, field", [
    ({"material.thickness": -1.0}, "material.thickness"),
    ({"mesh.n": 2.5}, "mesh.n"),  # an integer
    ({"mesh.cells": 4}, "mesh.cells"),  # no such key
    ({"tools.friction": 0.0}, "tools.friction"),  # the effect 'friction' needs friction > 0
    ({"tools.friction": -0.1}, "tools.friction"),
    ({"effects": ["bending", "membrane", "geometric_nonlinearity", "contact", "friction"]}, "material.hardening"),
    ({"process.max_step_mm": -1.0}, "process.max_step_mm"),
    ({"process.max_step": 0.1}, "process.max_step"),  # a tool scene steps in mm
    ({"bogus": 1}, "bogus"),
])
def test_a_bad_change_names_its_field(changes, field):
    s = scene.load(CUP)
    with pytest.raises(InputError) as err:
        s.changed(changes)
    assert err.value.field == field
    assert s == scene.load(CUP)  # left as it was


def test_changes_hold_together_and_leave_the_scene_alone():
    s = scene.load(CUP)
    mu0 = s.changed({"tools.friction": 0.0, "effects": [e for e in s.effects if e != "friction"], "mesh.n": 6})
    assert (mu0.tools.friction, "friction" in mu0.effects, mu0.mesh.n) == (0.0, False, 6)
    assert (s.tools.friction, s.mesh.n) == (0.1, 16)
    assert s.changed({}) == s and s.changed({}) is not s


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "demos").glob("*.toml")))
def test_a_scene_reads_back_as_itself(name):
    s = scene.load(ROOT / "demos" / name)
    assert scene.from_dict(scene.to_dict(s)) == s


def test_the_study_scenes_are_checked_scenes():
    """cup_hard's variants are checked as scene files are: a bad one is refused naming its field,
    and every scene of its cases, of cup-paper's friction runs and of cup-strain reads back as
    itself (a valid scene)."""
    from shellform.studies import cup_hard, cup_paper, cup_strain

    with pytest.raises(InputError) as err:
        cup_hard.variant(6, tools__friction=-0.1)
    assert err.value.field == "tools.friction"
    with pytest.raises(InputError) as err:
        cup_hard.variant(6, material__thickness=5.0)  # thicker than the clearance
    assert err.value.field == "tools.die_half_width"
    scenes = [*cup_hard.cases(6).values(), *cup_paper.friction_runs().values(), *(s for _, s in cup_strain.runs(6))]
    for s in scenes:
        assert scene.from_dict(scene.to_dict(s)) == s
    mu0 = cup_paper.friction_runs()["mu 0"]
    assert mu0.tools.friction == 0.0 and "friction" not in mu0.effects
