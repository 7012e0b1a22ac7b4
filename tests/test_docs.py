"""The docs' numbers come from the runs: every results table a page shows is included from the
file its study wrote (scripts/docs_include.py), that file is what the study's own `markdown`
makes of its CSV, and the site (mkdocs.yml, make docs) builds without a warning."""

import csv
import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from shellform.studies import cup_convergence, esaform_cup, nakajima, numisheet_cost

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "docs" / "results"
spec = importlib.util.spec_from_file_location("docs_include", ROOT / "scripts" / "docs_include.py")
docs_include = importlib.util.module_from_spec(spec)
spec.loader.exec_module(docs_include)


def test_the_pages_tables_are_their_studies_files():
    assert docs_include.check() == []
    included = {t.partition("#")[0] for p in (ROOT / "docs").glob("*.md") for t, _, _ in docs_include.blocks(p)}
    assert included == {f"results/{s}/{s}.md" for s in ("cup_convergence", "esaform_cup", "nakajima", "numisheet_cost",
                                                        "sensitivity")}


def test_a_table_that_differs_from_its_file_fails_the_check(tmp_path):
    docs = tmp_path / "docs"
    (docs / "results" / "nakajima").mkdir(parents=True)
    shutil.copy(RESULTS / "nakajima" / "nakajima.md", docs / "results" / "nakajima")
    page = (ROOT / "docs" / "tools.md").read_text()
    assert "| 20 | 558 | 24.84 |" in page
    (docs / "tools.md").write_text(page.replace("| 20 | 558 | 24.84 |", "| 20 | 558 | 24.85 |"))
    assert docs_include.check(docs) == [f"tools.md:{_line(page, 'nakajima.md')}: the table differs from "
                                        "results/nakajima/nakajima.md (python scripts/docs_include.py --write)"]
    assert docs_include.main(["--check", "--docs", str(docs)]) == 1
    assert docs_include.write(docs) == [docs / "tools.md"]  # the study's file wins
    assert (docs / "tools.md").read_text() == page and docs_include.check(docs) == []


def test_a_section_include_a_missing_file_and_a_block_without_end(tmp_path):
    (tmp_path / "t.md").write_text("### a\n\n| x |\n|---|\n| 1 |\n\n### b\n\n| y |\n|---|\n| 2 |\n")
    (tmp_path / "p.md").write_text("# P\n\n<!-- include: t.md#b -->\n\n| y |\n|---|\n| 2 |\n\n<!-- end include -->\n"
                                   "<!-- include: t.md#a -->\n| x |\n|---|\n| 3 |\n<!-- end include -->\n")
    assert docs_include.check(tmp_path) == ["p.md:10: the table differs from t.md#a (python scripts/docs_include.py --write)"]
    docs_include.write(tmp_path)
    assert docs_include.check(tmp_path) == [] and "| 1 |" in (tmp_path / "p.md").read_text()
    (tmp_path / "p.md").write_text("<!-- include: u.md -->\n<!-- end include -->\n<!-- include: t.md#c -->\n"
                                   "<!-- end include -->\n")
    problems = docs_include.check(tmp_path)
    assert [p.split(": ")[0] for p in problems] == ["p.md:1", "p.md:3"]
    assert "no file" in problems[0] and "no heading 'c'" in problems[1]
    (tmp_path / "p.md").write_text("<!-- include: t.md -->\n| x |\n")
    assert docs_include.check(tmp_path) == ["p.md:1: the include of t.md has no end"]


def _line(text: str, target: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith("<!-- include:") and target in line)


def _value(s: str):
    """A CSV cell as write_csv wrote it: "" None, True/False, int, float, else the string."""
    if s == "":
        return None
    if s in ("True", "False"):
        return s == "True"
    for kind in (int, float):
        try:
            return kind(s)
        except ValueError:
            pass
    return s


def _rows(path: Path, drop_empty: bool = False) -> list[dict]:
    """A study's CSV as rows; drop_empty: without a row's empty cells (the columns of other rows)."""
    with open(path, newline="") as f:
        rows = [{k: _value(v) for k, v in r.items()} for r in csv.DictReader(f)]
    return [{k: v for k, v in r.items() if v is not None} for r in rows] if drop_empty else rows


def test_the_studies_tables_are_their_csvs():
    """Each table docs/results/<study>/<study>.md is the study's `markdown` of its CSV files: the
    numbers a page includes are the runs' (to the CSV's six digits, which every table rounds)."""
    made = {
        "nakajima": nakajima.markdown(_rows(RESULTS / "nakajima" / "nakajima.csv")),
        "cup_convergence": cup_convergence.markdown(
            [{**r, "holder_opens_mm": r.get("holder_opens_mm")}
             for r in _rows(RESULTS / "cup_convergence" / "cup_convergence.csv", drop_empty=True)],
            _rows(RESULTS / "cup_convergence" / "cup_convergence_estimates.csv")),
        "esaform_cup": esaform_cup.markdown(_rows(RESULTS / "esaform_cup" / "esaform_cup.csv"), []),
        "numisheet_cost": numisheet_cost.markdown(
            _rows(RESULTS / "numisheet_cost" / "numisheet_cost.csv", drop_empty=True),
            {r["answer"]: (r["value"], r["uncertainty"], r["source"])
             for r in _rows(RESULTS / "numisheet_cost" / "numisheet_cost_reference.csv")},
            _rows(RESULTS / "numisheet_cost" / "numisheet_cost_picks.csv")),
    }
    assert not (RESULTS / "esaform_cup" / "esaform_cup_estimates.csv").exists()  # else markdown takes them
    for study, text in made.items():
        assert text == (RESULTS / study / f"{study}.md").read_text(), study


def _nav_files(nav) -> list[str]:
    out = []
    for item in nav:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out += [value] if isinstance(value, str) else _nav_files(value)
    return out


def test_the_nav_holds_every_page_and_demo():
    """mkdocs.yml's nav: every page of docs/, every literate demo, once (the site build fails on a
    page left out; this says so where the docs toolchain is not installed)."""
    nav = _nav_files(yaml.safe_load((ROOT / "mkdocs.yml").read_text())["nav"])
    assert len(nav) == len(set(nav))
    pages = {p.name for p in (ROOT / "docs").glob("*.md")}
    demos = {f"demos/{p.stem}.md" for p in (ROOT / "demos").glob("demo_*.py")}
    assert {n for n in nav if not n.startswith("api/")} == pages | demos | {"index.md"}
    for entry in (n for n in nav if n.startswith("api/")):
        module = entry.removeprefix("api/").removesuffix(".md").split(".")
        assert (ROOT.joinpath(*module).with_suffix(".py").is_file() or (ROOT.joinpath(*module) / "__init__.py").is_file()), entry


@pytest.mark.slow
def test_the_site_builds_without_a_warning(tmp_path):
    """make docs' build (about 15 s): skipped where the docs extra is not installed (make test)."""
    for name in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python", "jupytext"):
        pytest.importorskip(name, reason="the docs extra: pip install -e '.[docs]' (make docs)")
    site = tmp_path / "site"
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=ROOT,
                          capture_output=True, text=True, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert done.returncode == 0, done.stderr[-3000:]
    assert "WARNING" not in done.stderr
    for page in ("index.html", "cost/index.html", "demos/demo_square_cup/index.html", "api/shellform.run/index.html"):
        assert (site / page).is_file(), page
    assert "| 20 | 558" not in (site / "tools" / "index.html").read_text()  # the included table is rendered
    assert "<td>24.84</td>" in (site / "tools" / "index.html").read_text()
