"""scripts/tangent_modes.py: the softest modes of a run's tangent at its checkpoint (the fine
cups' soft modes, docs/performance.md). A short cup: its tangent on the free rows is positive
definite at a converged state, its softest mode is the stretched bottom's drum mode (out of the
plane, one sign over many nodes), and System.free_tangent leaves out exactly the known rows."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from shellform import scene
from shellform.contact import run as contact_run

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location("tangent_modes", ROOT / "scripts" / "tangent_modes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.timeout(180)
def test_the_softest_modes_of_a_short_cup(tmp_path):
    s = scene.load(ROOT / "demos" / "numisheet93_aluminium.toml").changed({
        "mesh.n": 8, "tools.stroke": 3.0, "output.png": False, "output.vtx": False, "output.vtu": False,
        "output.fld": False, "process.springback": False})
    contact_run.run(s, tmp_path)
    rows = _script().modes(s, tmp_path, 4)
    values = [r["eigenvalue"] for r in rows]
    assert values == sorted(values) and values[0] > 0.0
    soft = rows[0]
    assert soft["stroke_mm"] == pytest.approx(3.0)
    assert soft["dominant_unknown"] == 2 and soft["nodes_for_90_percent"] >= 4
    assert all(q["value"] > 0 for q in soft["largest"][:4])
    assert np.hypot(*soft["largest"][0]["initial_xy"]) < 20.0  # under the punch's flat face
