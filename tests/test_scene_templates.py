"""The tool-scene templates of docs/scenes.md ("Templates: a square cup and a round cup") are
scenes: each TOML block loads, is a tool scene, and gives the steps of the demo it follows."""

import re
import tomllib
from pathlib import Path

import pytest

from shellform import scene

ROOT = Path(__file__).resolve().parents[1]


def templates() -> list[str]:
    text = (ROOT / "docs" / "scenes.md").read_text()
    section = text.split("### Templates: a square cup and a round cup", 1)[1].split("\n### ", 1)[0]
    return re.findall(r"```toml\n(.*?)```", section, re.S)


def test_docs_hold_two_templates():
    assert len(templates()) == 2


@pytest.mark.parametrize("i, demo", [(0, "square_cup.toml"), (1, "round_cup.toml")])
def test_a_template_is_the_scene_of_its_demo(i, demo):
    """The template loads, and its geometry, tools, material's curve and steps are its demo's."""
    s = scene.from_dict(tomllib.loads(templates()[i]))
    d = scene.load(ROOT / "demos" / demo)
    assert s.tools is not None and s.tools.shape == d.tools.shape
    for section in ("geometry", "tools"):
        assert getattr(s, section) == getattr(d, section), section
    for key in ("E", "nu", "thickness", "hardening", "K", "eps0", "n"):
        assert getattr(s.material, key) == getattr(d.material, key), key
    for key in ("initial_step_mm", "max_step_mm", "min_step_mm", "max_iterations", "rtol", "report"):
        assert getattr(s.process, key) == getattr(d.process, key), key
