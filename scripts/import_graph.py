"""The module import graph of shellform, read from the sources (ast), and what docs/design.md
says of it.

    python scripts/import_graph.py [ROOT]    # the report: lines per folder, the largest modules
                                             # and classes, upward arrows, circles

A module is a file of shellform/ (and of forms/, installed as shellform.forms, and
demos/__init__.py, installed as shellform.demos). An arrow a -> b is an import of b in a, at
the top of a or inside one of its functions: ``import shellform.x.y`` and ``from shellform.x.y
import name`` point to shellform.x.y, ``from shellform.x import y`` to the module shellform.x.y
where y is one, else to the package shellform.x (its __init__). The parents a module's import
runs implicitly (shellform, shellform.x) are not arrows.

The layers are docs/design.md's fenced block that begins with the line ``layers (top to
bottom)``: one layer per line, its modules or packages by name separated by spaces (a package
stands for all its modules, a module named in a higher line is taken out of its package's
layer). A module may import its own layer and those below; an arrow to a higher layer is
upward. tests/test_import_graph.py asserts no circle and no upward arrow.
"""

import ast
import re
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def modules(root: Path = ROOT) -> dict[str, Path]:
    """Dotted name -> file of every module of shellform and shellform.forms, and shellform.demos
    (demos/__init__.py, the scenes' accessor; the literate demos beside it are scripts)."""
    found = {}
    for base, prefix in ((root / "shellform", "shellform"), (root / "forms", "shellform.forms")):
        for path in sorted(base.rglob("*.py")):
            parts = list(path.relative_to(base).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join([prefix, *parts])] = path
    if (root / "demos" / "__init__.py").is_file():
        found["shellform.demos"] = root / "demos" / "__init__.py"
    return found


def _imports(tree: ast.Module, name: str, is_package: bool, known: set) -> list[tuple[str, bool]]:
    """(target, inside a function) of every shellform import in the module's tree."""
    out = []

    def visit(node, inside):
        for child in ast.iter_child_nodes(node):
            nested = inside or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                out.extend((a.name, nested) for a in child.names if a.name.startswith("shellform"))
            elif isinstance(child, ast.ImportFrom):
                base = child.module or ""
                if child.level:  # relative: from the module's package
                    package = name.split(".") if is_package else name.split(".")[:-1]
                    base = ".".join(package[: len(package) - child.level + 1] + ([base] if base else []))
                if base.startswith("shellform"):
                    for a in child.names:
                        sub = f"{base}.{a.name}"
                        out.append((sub if sub in known else base, nested))
            visit(child, nested)

    visit(tree, False)
    return out


def graph(root: Path = ROOT) -> dict[str, list[tuple[str, bool]]]:
    """Module -> its arrows (target module, inside a function), targets among shellform's modules."""
    mods = modules(root)
    known = set(mods)
    arrows = {}
    for name, path in mods.items():
        tree = ast.parse(path.read_text(), str(path))
        targets = [(t, f) for t, f in _imports(tree, name, path.name == "__init__.py", known) if t != name]
        arrows[name] = [(t if t in known else _owner(t, known), f) for t, f in targets]
        arrows[name] = [(t, f) for t, f in arrows[name] if t is not None and t != name]
    return arrows


def _owner(target: str, known: set):
    """The longest known module that `target` lies in (an import of a name inside a module)."""
    parts = target.split(".")
    while parts:
        if ".".join(parts) in known:
            return ".".join(parts)
        parts.pop()
    return None


def circles(arrows: dict) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def connect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w, _ in arrows.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(arrows):
        if v not in index:
            connect(v)
    return sorted(out)


def layers(design: Path = ROOT / "docs" / "design.md") -> list[list[str]]:
    """docs/design.md's layers, top first: each a list of module or package names."""
    text = design.read_text()
    m = re.search(r"```\nlayers \(top to bottom\)[^\n]*\n(.*?)```", text, re.S)
    if m is None:
        raise ValueError(f"{design} has no fenced block 'layers (top to bottom)'")
    rows = []
    for line in m.group(1).splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            rows.append([f"shellform.{n}" if n != "shellform" else n for n in line.split()])
    return rows


def layer_of(mods, rows) -> dict[str, int]:
    """Module -> its layer's row (0 the top), by the most specific name that covers it; a module
    no row covers is missing from the result."""
    best = {}
    for m in mods:
        for i, row in enumerate(rows):
            for n in row:
                if m == n or m.startswith(n + "."):
                    if m not in best or len(n) > best[m][1]:
                        best[m] = (i, len(n))
    return {m: i for m, (i, _) in best.items()}


def upward(arrows: dict, level: dict) -> list[tuple[str, str]]:
    """Arrows into a higher layer (a smaller row)."""
    return sorted((a, b) for a, targets in arrows.items() for b, _ in targets
                  if a in level and b in level and level[b] < level[a])


def classes(path: Path) -> list[tuple[str, int]]:
    """(class name, lines) of the classes of a module."""
    tree = ast.parse(path.read_text())
    return [(n.name, n.end_lineno - n.lineno + 1) for n in ast.walk(tree) if isinstance(n, ast.ClassDef)]


def report(root: Path = ROOT) -> str:
    mods = modules(root)
    arrows = graph(root)
    lines = {m: len(p.read_text().splitlines()) for m, p in mods.items()}
    folders = defaultdict(lambda: [0, 0])
    for m, p in mods.items():
        rel = p.relative_to(root).parent.as_posix()
        folders[rel][0] += lines[m]
        folders[rel][1] += 1
    out = [f"{sum(lines.values())} lines in {len(mods)} modules", "", "lines per folder:"]
    out += [f"  {f:<22} {n:>6} ({k} modules)" for f, (n, k) in sorted(folders.items())]
    out += ["", "largest modules:"]
    out += [f"  {lines[m]:>5}  {m}" for m in sorted(lines, key=lines.get, reverse=True)[:8]]
    cls = sorted(((n, c, m) for m, p in mods.items() for c, n in classes(p)), reverse=True)[:6]
    out += ["", "largest classes:"] + [f"  {n:>5}  {m}.{c}" for n, c, m in cls]
    inside = sum(f for targets in arrows.values() for _, f in targets)
    out += ["", f"imports inside functions: {inside}"]
    try:
        level = layer_of(mods, layers(root / "docs" / "design.md"))
        up = upward(arrows, level)
        out += [f"upward arrows: {len(up)}"] + [f"  {a} -> {b}" for a, b in up]
        missing = sorted(set(mods) - set(level))
        if missing:
            out += [f"modules in no layer: {', '.join(missing)}"]
    except ValueError as err:
        out += [f"upward arrows: ({err})"]
    cyc = circles(arrows)
    out += [f"circles: {len(cyc)}"] + [f"  {' <-> '.join(c)}" for c in cyc]
    return "\n".join(out)


if __name__ == "__main__":
    print(report(Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else ROOT))
