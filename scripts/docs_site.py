"""The MkDocs hook of the docs site (mkdocs.yml: hooks): the pages that are not files in docs/.

- the home page, index.md: README.md, its links into docs/ made relative to docs/ and its links
  to other files of the clone written as their paths (the site holds only docs/);
- a page per literate demo, demos/<name>.md: demos/<name>.py (jupytext's light format) as its
  text and its code, not run (the demos print their sample runs in their text), as DOLFINx
  renders its demos;
- a page per module of the API reference, api/<module>.md: mkdocstrings' `::: <module>`, for
  every api/ entry of mkdocs.yml's nav (the nav is the one list of the reference's modules; a
  package's page shows its modules too);
- and before the build, the include check of scripts/docs_include.py and the cites check of
  scripts/docs_numbers.py: a page whose included table differs from its study's file, or whose
  prose cites a number its file does not hold, is a warning, which `mkdocs build --strict`
  (make docs) turns into a failure.

Every page is generated in memory (mkdocs' File.generated): nothing is written into docs/.
"""

import importlib.util
import logging
import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
log = logging.getLogger("mkdocs.hooks.docs_site")


def _script(name: str):
    """A module of scripts/ (not a package) loaded from its file."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


docs_include = _script("docs_include")
docs_numbers = _script("docs_numbers")

LINK = re.compile(r"(!?)\[([^\]]*)\]\((?!https?://|#)([^)\s]+)\)")


def home(readme: str) -> str:
    """README.md as the site's home page: docs/x -> x; a link to a file outside docs/ becomes its path."""
    def relink(m):
        bang, text, target = m.groups()
        if target.startswith("docs/"):
            return f"{bang}[{text}]({target.removeprefix('docs/')})"
        return f"`{target}`" if text == target else f"{text} (`{target}`)"
    return LINK.sub(relink, readme)


def demo(path: Path) -> str:
    """A literate demo as Markdown: its text cells as they are, each run of code cells as one block."""
    import jupytext  # the docs extra (and the test extra) install it

    notebook = jupytext.read(path)
    parts, code = [], []
    for cell in notebook.cells:
        if cell.cell_type == "code":
            code.append(cell.source)
            continue
        if code:
            parts.append("```python\n" + "\n\n".join(code) + "\n```")
            code = []
        parts.append(cell.source)
    if code:
        parts.append("```python\n" + "\n\n".join(code) + "\n```")
    source = f"demos/{path.name}"
    return "\n\n".join(parts) + f"\n\n*This page is `{source}`; run it with `python {source}`.*\n"


def api(module: str) -> str:
    """The reference page of one module; a package's page takes its modules too."""
    package = (ROOT / Path(*module.split("."))).is_dir()
    options = "\n    options:\n      show_submodules: true" if package else ""
    return f"# {module}\n\n::: {module}{options}\n"


def nav_entries(nav):
    """The file names of a nav (mkdocs.yml), depth first."""
    for item in nav or ():
        if isinstance(item, str):
            yield item
        elif isinstance(item, dict):
            for value in item.values():
                yield from ([value] if isinstance(value, str) else nav_entries(value))
        elif isinstance(item, list):
            yield from nav_entries(item)


def on_pre_build(config):
    for problem in docs_include.check(Path(config["docs_dir"])):
        log.warning(f"docs_include: {problem}")
    for problem in docs_numbers.check(Path(config["docs_dir"])):
        log.warning(f"docs_numbers: {problem}")


def on_files(files, config):
    files.append(File.generated(config, "index.md", content=home((ROOT / "README.md").read_text(encoding="utf-8"))))
    for path in sorted((ROOT / "demos").glob("demo_*.py")):
        files.append(File.generated(config, f"demos/{path.stem}.md", content=demo(path)))
    for entry in nav_entries(config["nav"]):
        if entry.startswith("api/") and entry.endswith(".md"):
            files.append(File.generated(config, entry, content=api(entry.removeprefix("api/").removesuffix(".md"))))
    return files
