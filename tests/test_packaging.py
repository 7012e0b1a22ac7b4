"""Packaging: forms/ installs as shellform.forms, demos/ as shellform.demos (the scenes as
package data), and every package folder is in the wheel."""

import ast
import os
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# a scene or a file a scene names, as the studies write its name (csv files are their outputs)
DEMO_FILE = re.compile(r"[\w/.-]*\w\.(toml|geo|msh|step|stp|stl|brep)")
# the scenes and files of the studies (issue 47 item 8); the studies' own list must hold them
STUDY_FILES = {"numisheet93_aluminium.toml", "numisheet93_steel.toml", "numisheet93_aluminium_graded.toml",
               "square_cup.toml", "esaform2021_cup.toml", "nakajima.toml", "meshes/nakajima/specimen.geo",
               "meshes/curved_beam.geo", "meshes/square_cup_graded.geo"}


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
    """Every package of shellform, forms/ and demos/, and each folder under demos/meshes (a data
    folder that setuptools would warn of as a package left out), and the demos' data globs."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "shellform").rglob("__init__.py")}
    meshes = {"shellform.demos." + ".".join(d.relative_to(ROOT / "demos").parts)
              for d in [ROOT / "demos" / "meshes", *(ROOT / "demos" / "meshes").rglob("*")] if d.is_dir()}
    assert found | {"shellform.forms", "shellform.demos"} | meshes == listed
    assert config["package-dir"] == {"shellform.forms": "forms", "shellform.demos": "demos"}
    assert config["package-data"] == {"shellform.demos": ["*.toml", "meshes/**/*"]}


def _study_files() -> set:
    """The demo files the studies name (string constants of shellform/studies), and the files
    those scenes name in turn (relative to demos/)."""
    names = {n.value for f in (ROOT / "shellform" / "studies").glob("*.py") for n in ast.walk(ast.parse(f.read_text()))
             if isinstance(n, ast.Constant) and isinstance(n.value, str) and DEMO_FILE.fullmatch(n.value)}
    return names | {f for n in names if n.endswith(".toml") for f in _named_files(ROOT / "demos" / n)}


def _named_files(scene_file: Path) -> list:
    """The files a scene names (geometry.file, material's curves, the tools' files), relative to it."""
    data = tomllib.loads(scene_file.read_text())
    section = lambda name: data.get(name) if isinstance(data.get(name), dict) else {}  # noqa: E731
    named = [section("geometry").get("file"),
             *(section("material").get(k) for k in ("flow_curve", "forming_limit_curve")),
             *(section("tools").get(k) for k in ("punch_file", "die_file"))]
    return [n for n in named if isinstance(n, str) and n]


def test_the_studies_find_their_scenes_through_shellform_demos():
    """shellform.demos.path finds every scene the studies draw and every file those name, beside
    itself (where a wheel ships them and an editable install maps demos/); every demo scene names
    only files under meshes/, which the package data ships."""
    from shellform import demos

    needed = _study_files()
    assert STUDY_FILES <= needed
    for name in needed:
        found = demos.path(name)
        assert found.is_file() and found.relative_to(demos.HERE).as_posix() == name
    for scene_file in sorted((ROOT / "demos").glob("*.toml")):
        for name in _named_files(scene_file):
            assert name.startswith("meshes/") and (ROOT / "demos" / name).is_file(), (scene_file.name, name)
    with pytest.raises(FileNotFoundError, match="no demo file 'nothing.toml'"):
        demos.path("nothing.toml")


def test_no_module_reaches_the_source_tree():
    """No module of the package (shellform/, forms/, demos/__init__.py) finds a file by walking up
    from itself (`parents[...]`, `.parent / "demos"`): that tree exists only in a clone. The demos'
    files come through shellform.demos.path, another study's results from beside --out."""
    sources = [*(ROOT / "shellform").rglob("*.py"), *(ROOT / "forms").rglob("*.py"), ROOT / "demos" / "__init__.py"]
    walks = re.compile(r"\.parents\s*\[|\.parent\s*/\s*[\"'](demos|forms|docs|shellform)\b|[\"']\.\./")
    found = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in sources
             for i, line in enumerate(p.read_text().splitlines(), 1) if walks.search(line)]
    assert found == []
    assert walks.search('ROOT = Path(__file__).resolve().parents[2]') and walks.search('root.parent / "forms"')


@pytest.mark.slow
def test_the_wheel_holds_the_scenes_and_a_study_runs_from_it(tmp_path):
    """The wheel built from the sources (pip, offline, no build isolation) holds the demos'
    scenes and the files they name; installed into a folder of its own, a study imported from it
    finds its scenes there, and `shellform study yld2000-fit` runs from it in a folder outside
    the clone."""
    setuptools = pytest.importorskip("setuptools")
    if int(setuptools.__version__.split(".")[0]) < 77:
        pytest.skip(f"setuptools {setuptools.__version__}: the build needs 77 (pyproject's build-system)")
    src = tmp_path / "src"  # a copy, so that the build leaves no build/ or egg-info in the clone
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        (src / name).parent.mkdir(exist_ok=True)
        shutil.copy(ROOT / name, src / name)
    for name in ("shellform", "forms", "demos"):
        shutil.copytree(ROOT / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-v",
                            str(src), "-w", str(tmp_path / "wheel")], capture_output=True, text=True)
    assert built.returncode == 0, built.stdout + built.stderr
    # -v shows setuptools' warnings: none of a data folder it could import as a package left out
    assert "is absent from the `packages` configuration" not in built.stdout + built.stderr
    (wheel,) = (tmp_path / "wheel").glob("shellform-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = {n.removeprefix("shellform/demos/") for n in names if n.startswith("shellform/demos/")}
    demos = ROOT / "demos"
    every = {p.relative_to(demos).as_posix() for p in [*demos.glob("*.toml"), *demos.glob("*.py"),
                                                       *(demos / "meshes").rglob("*")] if p.is_file()}
    assert _study_files() <= shipped and STUDY_FILES <= shipped
    assert every == shipped  # the scenes, the files they name, the literate demos and __init__.py
    assert "shellform/forms/functional.py" in names

    target = tmp_path / "site"
    installed = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-index", "-q",
                                "--target", str(target), str(wheel)], capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr
    away = tmp_path / "elsewhere"
    away.mkdir()
    code = ("import sys\nfrom shellform import demos, cli\nfrom shellform.studies import nakajima, locking, yld2000_fit\n"
            "print(demos.HERE, nakajima.SCENE, nakajima.SPECIMEN, locking.BEAM_GEO, yld2000_fit.SCENE)\n"
            "sys.exit(cli.main(['study', 'yld2000-fit', '--out', 'fit', '-q']))\n")
    env = {**os.environ, "PYTHONPATH": str(target)}
    out = subprocess.run([sys.executable, "-c", code], cwd=away, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    here, *paths = map(Path, out.stdout.split("\n")[0].split())
    assert here == (target / "shellform" / "demos").resolve()
    assert all(p.is_file() and p.is_relative_to(here) for p in paths)
    assert (away / "fit" / "residuals.csv").is_file()


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
