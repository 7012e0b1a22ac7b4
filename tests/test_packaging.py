"""Packaging: forms/ installs as shellform.forms, and every package folder is in the wheel."""

import os
import subprocess
import sys
import tomllib
from pathlib import Path

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
