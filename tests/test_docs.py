"""The docs' numbers come from the runs: every results table a page shows is included from the
file its study wrote (scripts/docs_include.py), that file is what the study's own `markdown`
makes of its CSV, every number the prose cites from a study's file is that file's
(scripts/docs_numbers.py), and the site (mkdocs.yml, make docs) builds without a warning."""

import csv
import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from shellform.studies import (cup_convergence, cup_hard, cup_mesh, cup_paper, cup_strain, esaform_cup, levy, nakajima,
                               numisheet, numisheet_cost, outlines, plastic, plate, rollup, shell, strip)

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "docs" / "results"


def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


docs_include = _script("docs_include")
docs_numbers = _script("docs_numbers")


def test_the_pages_tables_are_their_studies_files():
    assert docs_include.check() == []
    included = {t.partition("#")[0] for p in (ROOT / "docs").glob("*.md") for t, _, _ in docs_include.blocks(p)}
    assert included == {f"results/{s}.md" for s in (
        "cup_convergence/cup_convergence", "cup_hard/hard_cases", "cup_mesh/cup_mesh", "cup_paper/cup_paper",
        "cup_strain/cup_strain", "esaform_cup/esaform_cup", "esaform_gap_holder/esaform_cup", "esaform_lever/esaform_cup",
        "esaform_hypotheses/esaform_hypotheses", "esaform_poly6/esaform_cup", "esaform_poly6/peers",
        "yld2000_fit/residuals", "yld2000_fit/poly6_residuals",
        "binder_wrap/binder_wrap", "curved_binder/channel", "curved_binder/cup", "levy/levy",
        "nakajima/nakajima", "numisheet93/numisheet",
        "numisheet_cost/numisheet_cost", "outlines/outlines", "plastic/plastic", "plate/plate_convergence",
        "rollup/rollup", "sensitivity/sensitivity", "sensitivity_cup/sensitivity_cup", "shell/shell_convergence",
        "strip/strip")}


def test_a_table_that_differs_from_its_file_fails_the_check(tmp_path):
    docs = tmp_path / "docs"
    for study, table in (("nakajima", "nakajima.md"), ("binder_wrap", "binder_wrap.md"),
                         ("curved_binder", "channel.md"), ("curved_binder", "cup.md")):  # the tables tools.md includes
        (docs / "results" / study).mkdir(parents=True, exist_ok=True)
        shutil.copy(RESULTS / study / table, docs / "results" / study)
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


def test_the_numbers_the_pages_cite_are_their_files():
    """Every `<!-- cites: ... -->` of docs/*.md holds: the pages whose prose quotes the studies cite them."""
    assert docs_numbers.check() == []
    cited = {p.name: sum(1 for _, c, _ in docs_numbers.cites(p) if c) for p in (ROOT / "docs").glob("*.md")}
    for page in ("cost.md", "cup-convergence.md", "cup.md"):
        assert cited[page] >= 5, (page, cited[page])


def _cited_page(tmp_path: Path) -> Path:
    """A docs folder with a CSV, a JSON summary and a Markdown table, and a page citing all three."""
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "t.csv").write_text("case,n,force,share\nal,16,48.0721,0.0456711\nal,24,47.6325,nan\n")
    (tmp_path / "results" / "s.json").write_text('{"draw_in_mm": [{"stroke_mm": 15.0, "DX": 5.0945}], "balance": 1.4043e-06}')
    (tmp_path / "results" / "t.md").write_text("## a\n\n| run | DX | note |\n|---|---|---|\n| n 16 | 5.122 | 1.2 % |\n")
    page = tmp_path / "p.md"
    page.write_text("# P\n\nThe force is 48.1 kN on n = 16 <!-- cites: 48.1 = results/t.csv case=al n=16 force -->\n"
                    "and 47.6 on 24, DX 5.09 mm, 4.6 % <!-- cites: 47.6 = results/t.csv n=24 force; 4.6 = n=16 share *100; "
                    "5.09 = results/s.json draw_in_mm[stroke_mm=15].DX -->\n\n"
                    "- balance 1.4e-6, DX -5.122 <!-- cites: 1.4e-6 = results/s.json balance; 5.122 = results/t.md#a run=\"n 16\" DX -->\n")
    return page


def test_a_cited_number_its_file_does_not_hold_fails_naming_it(tmp_path):
    page = _cited_page(tmp_path)
    assert docs_numbers.check(tmp_path) == []
    page.write_text(page.read_text() + "\nAn example: `5 <!-- cites: 5 = results/none.csv x -->` (code, not a cite).\n")
    assert docs_numbers.check(tmp_path) == []
    text = page.read_text()
    page.write_text(text.replace("48.1", "48.2"))  # the text and its cite, both wrong
    assert docs_numbers.check(tmp_path) == ["p.md:3: 48.2 = results/t.csv case=al n=16 force: the file holds 48.0721, not 48.2"]
    assert docs_numbers.main(["--docs", str(tmp_path)]) == 1
    page.write_text(text.replace("48.1 kN", "48.2 kN"))  # the text edited, its cite not
    assert docs_numbers.check(tmp_path) == ["p.md:3: 48.1 = results/t.csv case=al n=16 force: the text before the comment does not show 48.1"]
    for shown, ok in (("48.07", True), ("48", True), ("48.072", True), ("48.08", False), ("-48.1", False), ("+48.1", True)):
        page.write_text(text.replace("48.1", shown))  # to the digits shown; a sign must match
        assert (docs_numbers.check(tmp_path) == []) is ok, shown
    page.write_text(text.replace("DX 5.09 mm", "DX 5.1 mm").replace("5.09 = ", "5.1 = "))
    assert docs_numbers.check(tmp_path) == []
    page.write_text(text.replace("DX 5.09 mm", "DX 5.2 mm").replace("5.09 = ", "5.2 = "))
    assert docs_numbers.check(tmp_path) == ["p.md:4: 5.2 = results/s.json draw_in_mm[stroke_mm=15].DX: the file holds 5.0945, not 5.2"]


def test_a_cite_that_cannot_be_read_is_a_clear_error(tmp_path):
    page = _cited_page(tmp_path)
    text = page.read_text()
    for old, new, message in (
            ("results/t.csv case=al n=16 force", "results/u.csv case=al n=16 force", "no file results/u.csv"),
            ("n=16 force -->", "n=16 forse -->", "results/t.csv: no column 'forse'"),
            ("case=al n=16 force", "case=al force", "results/t.csv: 2 rows with case=al, not one"),
            ("n=24 force", "n=24 share", "results/t.csv n=24 share is 'nan', not a number"),
            ("draw_in_mm[stroke_mm=15].DX", "draw_in_mm[stroke_mm=40].DX", "0 entries of 'draw_in_mm[stroke_mm=40].DX'"),
            ("s.json balance", "s.json balanse", "results/s.json: no 'balanse'"),
            ("t.md#a run", "t.md#b run", "results/t.md#b: no heading 'b'"),
            ("run=\"n 16\" DX", "run=\"n 16\" note", None),
            ("48.1 = results", "48.1 results", "not SHOWN = FILE [KEY=VALUE ...] FIELD")):
        page.write_text(text.replace(old, new))
        problems = docs_numbers.check(tmp_path)
        if message is None:  # "1.2 %" is a number: the cite is wrong, not unreadable
            assert len(problems) == 1 and "the file holds 1.2, not 5.122" in problems[0]
        else:
            assert len(problems) == 1 and message in problems[0], (message, problems)
    page.write_text(text.replace(" <!-- cites: 48.1", "\n<!-- cites: 48.1"))  # alone on its line: ends the paragraph
    assert docs_numbers.check(tmp_path) == ["p.md:4: a cites comment follows the text on its line (alone, it ends the paragraph or list)"]
    page.write_text(text + "\n| a | b |\n|---|---|\n| 1 | 48.1 | <!-- cites: 48.1 = results/t.csv n=16 force -->\n")
    assert docs_numbers.check(tmp_path) == ["p.md:10: a cites comment in a table row stands inside a cell "
                                            "(after the last |, it is dropped)"]
    page.write_text(text + "\n| a | b |\n|---|---|\n| 1 | 48.1 <!-- cites: 48.1 = results/t.csv n=16 force --> |\n")
    assert docs_numbers.check(tmp_path) == []
    page.write_text(text.replace("n=16 force -->", "n=16 force\n-->"))
    assert docs_numbers.check(tmp_path) == ["p.md:3: a cites comment ends on its own line (-->)"]


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
    """Each table docs/results/<study>/<study>.md is the study's `markdown` of its CSV files (and
    cup-paper's of the thickness lines and force_stroke.csv of the runs it draws on): the numbers
    a page includes are the runs' (to the CSV's six digits, which every table rounds)."""
    made = {
        "nakajima": nakajima.markdown(_rows(RESULTS / "nakajima" / "nakajima.csv")),
        "cup_convergence": cup_convergence.markdown(
            [{**r, "holder_opens_mm": r.get("holder_opens_mm")}
             for r in _rows(RESULTS / "cup_convergence" / "cup_convergence.csv", drop_empty=True)],
            _rows(RESULTS / "cup_convergence" / "cup_convergence_estimates.csv")),
        "esaform_cup": esaform_cup.markdown(_rows(RESULTS / "esaform_cup" / "esaform_cup.csv"),
                                            _rows(RESULTS / "esaform_cup" / "esaform_cup_estimates.csv")),
        "esaform_hypotheses": esaform_cup.markdown(_rows(RESULTS / "esaform_hypotheses" / "esaform_hypotheses.csv"), []),
        "numisheet_cost": numisheet_cost.markdown(
            _rows(RESULTS / "numisheet_cost" / "numisheet_cost.csv", drop_empty=True),
            {r["answer"]: (r["value"], r["uncertainty"], r["source"])
             for r in _rows(RESULTS / "numisheet_cost" / "numisheet_cost_reference.csv")},
            _rows(RESULTS / "numisheet_cost" / "numisheet_cost_picks.csv")),
        "cup_paper": cup_paper.markdown(_rows(RESULTS / "cup_paper" / "cup_paper.csv"), RESULTS / "cup_mesh",
                                        RESULTS / "cup_hard"),
    }
    for study, text in made.items():
        assert text == (RESULTS / study / f"{study}.md").read_text(), study
    for study, table in ((plate, "plate/plate_convergence"), (shell, "shell/shell_convergence"),
                         (outlines, "outlines/outlines"), (levy, "levy/levy"), (rollup, "rollup/rollup"),
                         (plastic, "plastic/plastic"), (numisheet, "numisheet93/numisheet"),
                         (cup_mesh, "cup_mesh/cup_mesh"), (cup_hard, "cup_hard/hard_cases"),
                         (cup_strain, "cup_strain/cup_strain"), (strip, "strip/strip")):  # one CSV each
        assert study.markdown(_rows(RESULTS / f"{table}.csv")) == (RESULTS / f"{table}.md").read_text(), table


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
