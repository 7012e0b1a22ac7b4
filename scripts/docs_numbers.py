"""The numbers the pages' prose cites from the studies' files: marked, and checked against them.

A page that quotes a number a study wrote (docs/results/**: a CSV, a Markdown table, a JSON
summary) says where it comes from in an HTML comment after the sentence, which neither GitHub
nor the site shows:

    n = 16 (512 cells, 69 s) is within 5 % <!-- cites: 512 = results/numisheet_cost/numisheet_cost.csv case="n 16" cells; 69 = case="n 16" cpu_s -->

The comment stands after text on its line and on one line: alone on a line, Python-Markdown
would end the paragraph or list there; in a table row it stands inside a cell. Each cite is `SHOWN = FILE [KEY=VALUE ...] FIELD [*K|/K]`,
cites separated by `;`, the words split as a shell does (quote a value with spaces); a cite
without FILE reads the previous cite's file in the same comment:

- SHOWN is the number as the text before the comment writes it: `69`, `-0.335`, `2,450`,
  `1.4e-6`; it must stand there (since the paragraph's start or the previous such comment), so a
  number edited in the prose and not in its cite fails too;
- FILE is relative to the page, like an include (scripts/docs_include.py);
- in a CSV, or a Markdown table (the tables of a .md file, or of one section of it:
  `file.md#heading`), the KEY=VALUE pairs pick the one row whose cells equal them (as text, or
  as numbers: `n=24` is the row with 24.0) and FIELD is a column's header; a file of one row
  needs no pair;
- in a JSON file FIELD is a path: `min_thickness_strain`, `wall_time_s.total`,
  `where_initial_xy_mm[0]`, `draw_in_mm[stroke_mm=15].DX` (the one list entry whose key equals
  the value);
- `*100` or `/1000` scales the file's value first (a fraction shown in per cent, N shown in kN).

The check: the file's value, rounded to the digits SHOWN has (the last one, to within half a
unit), is SHOWN. A SHOWN without a sign is compared with the value's magnitude: the prose
carries the sign in words ("3.5 % low"); a signed SHOWN must match in sign too.

    python scripts/docs_numbers.py        # exit 1 naming page, line, cite, file and value per miss

make docs runs it, the site's hook (scripts/docs_site.py) warns of each miss so that
`mkdocs build --strict` fails, and tests/test_docs.py asserts there is none. Numbers the prose
derives (a ratio of two runs, "two thirds") are not cited: cite the numbers they come from.
"""

import argparse
import csv
import json
import math
import re
import shlex
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docs_include import IncludeError, section  # noqa: E402  (a sibling script, not a package)

DOCS = Path(__file__).resolve().parents[1] / "docs"

CITE = re.compile(r"\s*(?P<shown>[^\s=]+)\s*=\s*(?P<ref>.*)$", re.S)
FILE = re.compile(r"\.(csv|md|json)(#.*)?$")
OPEN = re.compile(r"<!--\s*cites:")
COMMENT = re.compile(r"<!--\s*cites:(?P<body>[^\n]*?)-->")
NUMBER = re.compile(r"^(?P<sign>[+-]?)(?P<int>\d{1,3}(?:,\d{3})+|\d+)(?:\.(?P<frac>\d+))?(?:[eE](?P<exp>[+-]?\d+))?$")
PARAGRAPH = re.compile(r"\n[ \t]*\n")
JSON_STEP = re.compile(r"\.?(?P<key>[^.\[\]]+)|\[(?P<index>-?\d+)\]|\[(?P<pick>[^=\]]+)=(?P<value>[^\]]*)\]")


class CiteError(ValueError):
    """A cite that cannot be checked: bad syntax, a missing file, column, row or key."""


def shown(text: str) -> tuple[float, float, bool]:
    """A number as a page writes it: (value, half a unit of its last digit, whether it is signed)."""
    m = NUMBER.match(text.replace("\u2212", "-"))
    if not m:
        raise CiteError(f"{text!r} is not a number")
    value = float(text.replace("\u2212", "-").replace(",", ""))
    exp = int(m.group("exp") or 0) - len(m.group("frac") or "")
    return value, 0.5 * 10.0 ** exp, bool(m.group("sign"))


def _number(cell, where: str) -> float:
    """A file's cell as a number ("1,152", "1.2 %" as a Markdown table writes them)."""
    if isinstance(cell, bool) or cell is None:
        raise CiteError(f"{where} is {cell!r}, not a number")
    try:
        number = float(cell) if isinstance(cell, (int, float)) else float(str(cell).replace(",", "").removesuffix("%"))
    except ValueError:
        raise CiteError(f"{where} is {cell!r}, not a number") from None
    if not math.isfinite(number):
        raise CiteError(f"{where} is {cell!r}, not a number")
    return number


def _equal(cell: str, want: str) -> bool:
    if cell.strip() == want:
        return True
    try:
        return float(cell.replace(",", "")) == float(want)
    except ValueError:
        return False


def _md_rows(text: str) -> list[dict]:
    """The rows of every pipe table of a Markdown text, each as {header: cell}."""
    rows, header = [], None
    for line in text.splitlines():
        if not line.startswith("|"):
            header = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if header is None:
            header = cells
        elif not all(set(c) <= set("-: ") for c in cells):
            rows.append(dict(zip(header, cells)))
    return rows


def _row(rows: list[dict], picks: list[str], field: str, name: str) -> dict:
    """The one row whose cells equal the KEY=VALUE picks (and that has the column `field`)."""
    want = [p.split("=", 1) for p in picks]
    for key in [k for k, _ in want] + [field]:
        if not any(key in r for r in rows):
            raise CiteError(f"{name}: no column {key!r}")
    found = [r for r in rows if all(key in r and r[key] is not None and _equal(str(r[key]), v) for key, v in want)]
    if len(found) != 1:
        raise CiteError(f"{name}: {len(found)} rows with {' '.join(picks) or 'no pick'}, not one")
    return found[0]


def _json_value(data, path: str, name: str):
    """The value at a JSON path: key, key.key, key[0], key[pick=value]."""
    pos, value = 0, data
    while pos < len(path):
        m = JSON_STEP.match(path, pos)
        if not m or m.end() == pos:
            raise CiteError(f"{name}: cannot read the path {path!r}")
        pos = m.end()
        try:
            if m.group("key") is not None:
                value = value[m.group("key")]
            elif m.group("index") is not None:
                value = value[int(m.group("index"))]
            else:
                found = [v for v in value if isinstance(v, dict) and _equal(str(v.get(m.group("pick"))), m.group("value"))]
                if len(found) != 1:
                    raise CiteError(f"{name}: {len(found)} entries of {path!r} with {m.group('pick')}={m.group('value')}")
                value = found[0]
        except (KeyError, IndexError, TypeError):
            raise CiteError(f"{name}: no {path!r}") from None
    return value


def value(page: Path, cite: str) -> tuple[str, float]:
    """What one cite `SHOWN = FILE [KEY=VALUE ...] FIELD [*K|/K]` shows, and its file's value (scaled)."""
    m = CITE.match(cite)
    text, ref = (m.group("shown"), m.group("ref")) if m else (cite, "")
    try:
        words = shlex.split(ref)
    except ValueError as e:
        raise CiteError(f"{cite.strip()!r}: {e}") from None
    if len(words) < 2:
        raise CiteError(f"{cite.strip()!r}: not SHOWN = FILE [KEY=VALUE ...] FIELD")
    scale = 1.0
    if words[-1][0] in "*/":
        op = words.pop()
        k = _number(op[1:], f"the scale {op!r}")
        scale = k if op[0] == "*" else 1.0 / k
    target, *picks, field = words
    path, _, heading = target.partition("#")
    file = page.parent / path
    if not file.is_file():
        raise CiteError(f"no file {target}")
    if file.suffix == ".json":
        if picks:
            raise CiteError(f"{target}: a JSON file takes a path, not KEY=VALUE picks")
        got = _json_value(json.loads(file.read_text(encoding="utf-8")), field, target)
    else:
        if file.suffix == ".csv":
            with open(file, newline="", encoding="utf-8") as f:
                rows = [{k: (v if v != "" else None) for k, v in r.items()} for r in csv.DictReader(f)]
        elif file.suffix == ".md":
            source = file.read_text(encoding="utf-8")
            if heading:
                try:
                    source = section(source, heading)
                except IncludeError as e:
                    raise CiteError(f"{target}: {e}") from None
            rows = _md_rows(source)
        else:
            raise CiteError(f"{target}: not a CSV, Markdown or JSON file")
        got = _row(rows, picks, field, target)[field]
    return text.strip(), _number(got, f"{target} {' '.join(picks + [field])}") * scale


def cites(page: Path):
    """Each cite of a page: (line, the cite's text, the page's text it must stand in), or, for a
    comment the site would not render inline, (line, None, what is wrong)."""
    text = page.read_text(encoding="utf-8")
    start = 0
    for m in OPEN.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        if text[text.rfind("\n", 0, m.start()) + 1:m.start()].count("`") % 2:
            continue  # in a code span: an example, not a cite
        end = COMMENT.match(text, m.start())
        if not end:
            yield line, None, "a cites comment ends on its own line (-->)"
            continue
        line_start = text.rfind("\n", 0, m.start()) + 1
        lead = text[line_start:m.start()]
        if not lead.strip(" \t-*>|"):
            yield line, None, "a cites comment follows the text on its line (alone, it ends the paragraph or list)"
        elif lead.lstrip().startswith("|") and lead.rstrip().endswith("|"):
            yield line, None, "a cites comment in a table row stands inside a cell (after the last |, it is dropped)"
        para = max((p.end() for p in PARAGRAPH.finditer(text, 0, m.start())), default=0)
        before = COMMENT.sub(" ", text[max(start, para):m.start()])
        file = None
        for cite in end.group("body").split(";"):
            m = CITE.match(cite)
            if m and m.group("ref").split() and FILE.search(m.group("ref").split()[0]):
                file = m.group("ref").split()[0]
            elif m and file:
                cite = f"{m.group('shown')} = {file} {m.group('ref')}"
            if cite.strip():
                yield line, " ".join(cite.split()), before
        start = end.end()


def check(docs: Path = DOCS) -> list[str]:
    """One line per cite whose file does not hold its number (or that cannot be read); [] if all do."""
    problems = []
    for page in sorted(docs.glob("*.md")):
        for line, cite, before in cites(page):
            if cite is None:
                problems.append(f"{page.name}:{line}: {before}")
                continue
            where = f"{page.name}:{line}: {cite}"
            try:
                text, got = value(page, cite)
                number, half, signed = shown(text)
            except CiteError as e:
                problems.append(f"{where}: {e}")
                continue
            if not re.search(rf"(?<![\w.,]){re.escape(text)}(?!\d|[.,]\d|[eE][+-]?\d)", before):
                problems.append(f"{where}: the text before the comment does not show {text}")
            elif abs(number - (got if signed else abs(got))) > half * (1 + 1e-9):
                problems.append(f"{where}: the file holds {got:.6g}, not {text}")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--docs", type=Path, default=DOCS, help="the docs folder (default: the clone's docs/)")
    args = parser.parse_args(argv)
    problems = check(args.docs)
    for p in problems:
        print(f"docs_numbers: {p}", file=sys.stderr)
    count = sum(1 for page in sorted(args.docs.glob("*.md")) for _, cite, _ in cites(page) if cite)
    print(f"docs_numbers: {count} cited numbers checked, {len(problems)} not their files'")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
