"""Packaging: forms/ installs as shellform.forms, and every package folder is in the wheel."""

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_forms_install_as_shellform_forms(tmp_path):
    """From an unrelated folder that holds a forms/ package of its own, shellform.forms is still
    the project's forms/ and the user's forms is the user's."""
    (tmp_path / "forms").mkdir()
    (tmp_path / "forms" / "__init__.py").write_text("MINE = True\n")
    out = subprocess.run([sys.executable, "-c", "import forms, shellform.forms.functional as f; "
                          "print(forms.MINE, f.__file__)"], cwd=tmp_path, capture_output=True, text=True, check=True)
    mine, path = out.stdout.split()
    assert mine == "True"
    assert Path(path) == ROOT / "forms" / "functional.py"


def test_every_package_folder_is_listed():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "shellform").rglob("__init__.py")}
    assert found | {"shellform.forms"} == listed
    assert config["package-dir"] == {"shellform.forms": "forms"}


def test_one_blas_thread_unless_the_user_sets_it():
    """Importing shellform sets OPENBLAS_NUM_THREADS=1 before the DOLFINx runtime loads (MUMPS's
    spinning BLAS workers took a third of the element loop's cores), and leaves a value the
    user set alone."""
    code = "import os, shellform; print(os.environ['OPENBLAS_NUM_THREADS'])"
    for given, expected in ((None, "1"), ("2", "2")):
        env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
        if given is not None:
            env["OPENBLAS_NUM_THREADS"] = given
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        assert out.stdout.strip() == expected


def test_the_fast_lane_the_slow_lane_and_a_timeout():
    """`make test` runs all but the tests marked slow, `make test-slow` those, CI (.ci/run) both
    in turn; every test fails after pyproject's timeout instead of hanging."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert 0 < config["timeout"] <= 900
    assert any(m.startswith("slow:") for m in config["markers"])
    lanes = {}
    for target in ("test", "test-slow"):
        out = subprocess.run(["make", "-n", target], cwd=ROOT, capture_output=True, text=True, check=True).stdout
        lanes[target] = [line for line in out.splitlines() if "-m pytest" in line]
    assert len(lanes["test"]) == 1 and '-m "not slow"' in lanes["test"][0]
    assert len(lanes["test-slow"]) == 1 and "-m slow" in lanes["test-slow"][0]
    steps = [line for line in (ROOT / ".ci" / "run").read_text().splitlines() if line.startswith("make")]
    assert steps == ["make test", "make test-slow"]


def test_dolfinx_of_another_version_is_refused_with_what_to_do():
    """shellform checks the installed DOLFINx's version on import, from its distribution's
    metadata (the wheel's here), and refuses another minor version naming both and the fix."""
    from shellform import _env

    assert _env.dolfinx_version().startswith("0.11")
    _env.check_dolfinx("0.11.0.post0")
    _env.check_dolfinx(None)  # a DOLFINx without known metadata (built from source): not refused
    with pytest.raises(ImportError, match=r"needs DOLFINx 0\.11\.x, and DOLFINx 0\.10\.0 is installed: install"):
        _env.check_dolfinx("0.10.0")
    with pytest.raises(ImportError, match="0.110"):
        _env.check_dolfinx("0.110")


def test_the_build_asks_for_a_setuptools_that_knows_license_expressions():
    """license = "MIT" (PEP 639) needs setuptools 77 (68 and 76 fail with --no-build-isolation)."""
    build = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
    assert build == ["setuptools>=77"]


def test_without_dolfinx_one_line_says_what_to_install():
    """In a Python that cannot import DOLFINx's stack (hidden here by a finder that refuses it),
    importing shellform prints one line naming what is missing and how to install it, and exits
    with status 1 without a traceback."""
    hide = ("import sys\n"
            "class Hide:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] in ('dolfinx', 'mpi4py', 'petsc4py', 'dolfinx_solver'):\n"
            "            raise ModuleNotFoundError(name)\n"
            "sys.meta_path.insert(0, Hide())\n"
            "import shellform.run\n")
    out = subprocess.run([sys.executable, "-c", hide], capture_output=True, text=True)
    assert out.returncode == 1 and out.stdout == ""
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in out.stderr
    assert lines[0].startswith("shellform: no mpi4py, petsc4py, dolfinx in this Python")
    assert "dolfinx-solver-real" in lines[0] and "make venv" in lines[0]


def test_the_metadata_names_the_licence_and_citation_the_paper():
    """pyproject's metadata (licence file, authors, classifiers) and CITATION.cff: the software
    at the package's version, with the paper whose method it implements among its references."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert meta["license"] == "MIT" and meta["license-files"] == ["LICENSE"] and (ROOT / "LICENSE").exists()
    assert meta["authors"] and any(c.startswith("Topic :: Scientific/Engineering") for c in meta["classifiers"])
    cff = (ROOT / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in cff and f"version: {meta['version']}\n" in cff and "type: software" in cff
    assert "family-names: Jiang" in cff and "given-names: Heyang" in cff
