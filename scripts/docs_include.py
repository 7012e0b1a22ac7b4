"""The studies' tables in the docs: included from docs/results/, never copied by hand.

A page includes a table that a study wrote (docs/results/<study>/<study>.md) in a block

    <!-- include: results/numisheet_cost/numisheet_cost.md -->

    | the table, exactly as the file holds it |

    <!-- end include -->

and a block may take one section of the file, the lines under a heading up to the next heading
of its level or above: `results/cup_convergence/cup_convergence.md#aluminium` (the heading's
text). The path is relative to the page. The block's body must equal the file's text (or the
section's), blank lines at either end aside.

    python scripts/docs_include.py --check    # exit 1 naming each block that differs (make docs)
    python scripts/docs_include.py --write    # rewrite each block's body from its file

A study that reruns rewrites its file; `--write` then brings the pages up to it, and `--check`
(make docs, tests/test_docs.py) fails until it has: a page cannot show a table its study does
not hold.
"""

import argparse
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"

BEGIN = re.compile(r"^<!-- include: (?P<target>\S+) -->\s*$")
END = re.compile(r"^<!-- end include -->\s*$")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


class IncludeError(ValueError):
    """A block that cannot be checked: no end, a missing file or section."""


def _strip(lines: list[str]) -> list[str]:
    """The lines without blank ones at either end."""
    start, end = 0, len(lines)
    while start < end and not lines[start].strip():
        start += 1
    while end > start and not lines[end - 1].strip():
        end -= 1
    return lines[start:end]


def section(text: str, heading: str) -> str:
    """The lines under the heading whose text is `heading`, up to the next one of its level or above."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = HEADING.match(line)
        if m and m.group(2) == heading:
            level = len(m.group(1))
            body = []
            for rest in lines[i + 1:]:
                n = HEADING.match(rest)
                if n and len(n.group(1)) <= level:
                    break
                body.append(rest)
            return "\n".join(_strip(body))
    raise IncludeError(f"no heading {heading!r}")


def source(page: Path, target: str) -> str:
    """What a block that includes `target` (a path relative to the page, maybe with #section) must hold."""
    path, _, heading = target.partition("#")
    file = page.parent / path
    if not file.is_file():
        raise IncludeError(f"{target}: no file {file}")
    text = file.read_text(encoding="utf-8")
    return section(text, heading) if heading else "\n".join(_strip(text.splitlines()))


def blocks(page: Path):
    """Each include block of a page: (target, line of its opening comment, its body's lines as a slice)."""
    lines = page.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        m = BEGIN.match(lines[i])
        if m:
            end = next((j for j in range(i + 1, len(lines)) if BEGIN.match(lines[j]) or END.match(lines[j])), None)
            if end is None or not END.match(lines[end]):
                raise IncludeError(f"{page.name}:{i + 1}: the include of {m.group('target')} has no end")
            yield m.group("target"), i + 1, slice(i + 1, end)
            i = end
        i += 1


def check(docs: Path = DOCS) -> list[str]:
    """One line per block whose body is not its file's text (or that cannot be read); [] if all agree."""
    problems = []
    for page in sorted(docs.glob("*.md")):
        try:
            lines = page.read_text(encoding="utf-8").splitlines()
            for target, line, body in blocks(page):
                try:
                    want = source(page, target)
                except IncludeError as e:
                    problems.append(f"{page.name}:{line}: {e}")
                    continue
                if "\n".join(_strip(lines[body])) != want:
                    problems.append(f"{page.name}:{line}: the table differs from {target} "
                                    "(python scripts/docs_include.py --write)")
        except IncludeError as e:
            problems.append(str(e))
    return problems


def write(docs: Path = DOCS) -> list[Path]:
    """Rewrite every block's body from its file; the pages changed."""
    changed = []
    for page in sorted(docs.glob("*.md")):
        text = page.read_text(encoding="utf-8")
        lines = text.splitlines()
        for target, _, body in reversed(list(blocks(page))):
            lines[body] = ["", *source(page, target).splitlines(), ""]
        new = "\n".join(lines) + ("\n" if text.endswith("\n") else "")
        if new != text:
            page.write_text(new, encoding="utf-8")
            changed.append(page)
    return changed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--check", action="store_true", help="fail if a page's included table differs from its file")
    what.add_argument("--write", action="store_true", help="rewrite the included tables from their files")
    parser.add_argument("--docs", type=Path, default=DOCS, help="the docs folder (default: the clone's docs/)")
    args = parser.parse_args(argv)
    if args.write:
        for page in write(args.docs):
            print(f"docs_include: rewrote {page}")
        return 0
    problems = check(args.docs)
    for p in problems:
        print(f"docs_include: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
