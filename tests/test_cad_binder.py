"""A binder face from a file (shellform/tools/cad.py, HolderFace): the flat holder given as a
CAD plate draws the same cup as the flat analytic holder, both held at a gap; and the checks of
a holder's face placed at the start."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import importlib.util
from pathlib import Path

import pytest

from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.errors import InputError
from shellform.results import cup

ROOT = Path(__file__).resolve().parents[1]
CAD_SCENE = ROOT / "demos" / "numisheet93_aluminium_cad.toml"


def _holder_plate(folder: Path) -> Path:
    """The analytic holder's plate as a STEP file (scripts/cup_tools_step.py, holder): face at
    z = 0, the opening of the scene's holder edge (half-width 45, corner radius 20)."""
    spec = importlib.util.spec_from_file_location("cup_tools_step", ROOT / "scripts" / "cup_tools_step.py")
    steps = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(steps)
    path = folder / "holder.step"
    steps.write_step(steps.holder, path, 45.0, 20.0)
    return path


def _scene(**changes):
    base = scene.load(CAD_SCENE)
    return base.changed({"mesh.n": 8, "tools.stroke": 3.0, "tools.holder": "gap", "tools.holder_gap": 0.85,
                         "tools.blank_holder_force": 0.0, "effects": list(base.effects) + ["ironing"],
                         "process.report": [], **changes})


def _drawn(s):
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(1.0)
    d = cup.draw_in(p)
    return {"DX": d["DX"], "DD": d["DD"], "force": p.punch_force(), "holder": p.holder_force(),
            "thinning": cup.peak_thinning(p)["min_thickness_strain"],
            "iterations": sum(h.iterations for h in p.driver.history), "increments": len(p.driver.history)}


@pytest.mark.filterwarnings("error::shellform.tools.cad.ToolSymmetryWarning")  # the plate is symmetric
def test_a_flat_binder_from_a_cad_file_draws_the_analytic_holders_cup(tmp_path):
    """The aluminium cup's CAD tools (n 8, 3 mm), the holder 0.85 mm over the die's top: its
    face the flat analytic one, or a CAD plate with the same opening placed on the sheet
    (holder_translation t/2) and raised by the gap. The plate's face is a plane whose distance
    is the analytic face's, and no node comes near its opening's rim: the draw-in, the forces,
    the thinning and the steps agree to 1e-9 (bit for bit on one machine)."""
    plate = _holder_plate(tmp_path)
    analytic = _drawn(_scene())
    from_file = _drawn(_scene(**{"tools.holder_file": str(plate), "tools.holder_translation": [0.0, 0.0, 0.405]}))
    for key in ("DX", "DD", "force", "holder", "thinning"):
        assert from_file[key] == pytest.approx(analytic[key], rel=1e-9, abs=0.0), key
    assert (from_file["iterations"], from_file["increments"]) == (analytic["iterations"], analytic["increments"])
    assert analytic["holder"] > 0 and analytic["DX"] > 0.1


@pytest.mark.parametrize("changes, field", [
    ({"tools.holder_translation": [0.0, 0.0, 0.0]}, "tools.holder_translation"),  # through the sheet
    ({"tools.holder_translation": [0.0, 0.0, 1.0]}, "tools.holder_translation"),  # not resting on it
    ({"tools.holder_translation": [0.0, 0.0, 0.405], "tools.holder_normals": "inward"}, "tools.holder_normals"),
    ({"tools.holder": "force", "tools.holder_gap": 0.0, "tools.blank_holder_force": 19600.0,
      "effects": None}, "tools.holder_file"),  # a file's face is held at a gap
])
def test_a_holders_face_from_a_file_is_checked(tmp_path, changes, field):
    plate = _holder_plate(tmp_path)
    if changes.get("effects", 0) is None:
        changes = {**changes, "effects": list(scene.load(CAD_SCENE).effects)}
    with pytest.raises(InputError) as err:
        s = _scene(**{"tools.holder_file": str(plate), **changes})
        DrawingProblem.from_scene(s, verbose=False)
    assert err.value.field == field


CURVED = ROOT / "demos" / "square_cup_curved_binder.toml"


@pytest.mark.filterwarnings("error::shellform.tools.cad.ToolSymmetryWarning")  # the binder is symmetric
def test_the_holder_closes_the_blank_onto_a_cylindrical_binder_from_cad_files():
    """demos/square_cup_curved_binder.toml (die and holder faces: cylinders of R 500 and
    500 + t about the x axis, from STEP files) on n 6, the ram at binder_rise (6 mm): the
    holder has stopped 0.8 mm over the die, and the flange beyond the die's opening lies on the
    cylinder: its mid-surface within the holder's clearance (0.02 mm) and the contact's
    tolerance of the radius R + t/2, its ends 5.6 mm below the crown."""
    import numpy as np

    s = scene.load(CURVED).changed({"mesh.n": 6})
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(s.tools.binder_rise / s.tools.stroke)
    t, rm = s.material.thickness, 500.0 + s.material.thickness / 2
    X, x = d.model.mesh.geometry.x[: d.n_owned], d.positions()
    off = np.hypot(x[:, 1], x[:, 2] + rm) - rm
    flange = (np.abs(X[:, 0]) > 50.0) | (np.abs(X[:, 1]) > 50.0)
    assert flange.sum() > 10
    assert np.all(off[flange] > -0.01 * t - 1e-9) and np.all(off[flange] < (0.8 - t) + 0.01 * t)
    assert np.all(x[flange & (X[:, 1] > 74.0), 2] < -5.5)
    assert d.paths[2].at(d.lam) == -6.0 and d.paths[2].at(1.0) == -6.0  # the holder stopped


@pytest.mark.parametrize("changes, field", [
    ({"tools.binder_rise": 3.0}, "tools.binder_rise"),  # the face would cut the flat blank's ends
    ({"tools.holder_file": ""}, "tools.binder_rise"),  # a rise without a face from a file
    ({"tools.stroke": 5.0}, "tools.stroke"),  # not beyond the rise
])
def test_a_curved_binders_rise_is_checked(changes, field):
    with pytest.raises(InputError) as err:
        DrawingProblem.from_scene(scene.load(CURVED).changed({"mesh.n": 4, **changes}), verbose=False)
    assert err.value.field == field
