"""A field over the blank's plan given as text: an expression in x and y.

The text is Python syntax with the names below (``x**2``, ``sin(pi*x/L)``); anything else is
refused, so a scene file cannot run code. It is checked in bounded time and memory: at most
MAX_LENGTH characters and MAX_DEPTH nested operations, one argument per function, and its value
is computed in floating point (numbers as floats), so that ``9**9**9`` overflows at once instead
of growing an integer. UFL takes the same text as an expression of the spatial coordinate, so
the forms differentiate and integrate it exactly as written. Fields: the reference surface z0
(reference_surface.py) and the pressure's distribution (loads.py).
"""

import ast
import math
from dataclasses import dataclass

import ufl

FUNCTIONS = ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln", "sqrt")
_MATH = {**{f: getattr(math, f) for f in FUNCTIONS if f != "ln"}, "ln": math.log, "pi": math.pi}
_UFL = {**{f: getattr(ufl, f) for f in FUNCTIONS}, "pi": ufl.pi}
MAX_LENGTH = 1000  # characters of an expression
MAX_DEPTH = 100  # operations nested in one another (a sum of n terms nests n deep)
_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load, ast.Constant,
          ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd)


@dataclass(frozen=True)
class PlanField:
    """f(x, y) from its text; hashable, so compiled kernels are cached per field."""

    source: str
    FIELD = "field"  # the scene's name for it, in messages

    def problem(self) -> str | None:
        """Why the text is no valid expression of x and y (None: it is one)."""
        if len(self.source) > MAX_LENGTH:
            return f"longer than {MAX_LENGTH} characters ({len(self.source)})"
        try:
            tree = ast.parse(self.source, mode="eval")
        except SyntaxError as err:
            return f"not an expression: {err.msg}"
        except (MemoryError, RecursionError, ValueError):
            return f"nested too deeply (at most {MAX_DEPTH} levels)"
        if _depth(tree) > MAX_DEPTH:
            return f"nested too deeply (at most {MAX_DEPTH} levels)"
        for node in ast.walk(tree):
            if not isinstance(node, _NODES):
                return (f"{type(node).__name__} is not allowed; use numbers, x, y, + - * / **, pi and "
                        f"{', '.join(FUNCTIONS)}")
            if isinstance(node, ast.Name) and node.id not in ("x", "y", *_MATH):
                return f"unknown name {node.id!r}; known: x, y, pi, {', '.join(FUNCTIONS)}"
            if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS):
                return "only the functions " + ", ".join(FUNCTIONS) + " may be called"
            if isinstance(node, ast.Call) and (len(node.args) != 1 or node.keywords):
                return f"{node.func.id} takes one argument, got {len(node.args) + len(node.keywords)}"
            if isinstance(node, ast.Constant) and (isinstance(node.value, bool) or
                                                   not isinstance(node.value, int | float)):
                return f"{node.value!r} is no number"
        return None

    def quoted(self, most: int = 60) -> str:
        """The text as messages quote it: in full up to `most` characters, else its start and
        its length (an error message stays one line)."""
        if len(self.source) <= most:
            return repr(self.source)
        return f"{self.source[:most]!r}... ({len(self.source):,} characters)"

    def value(self, x, y):
        """The field at a point in floating point, every number of the text taken as a float, so
        that no power grows an unbounded integer (for checks and plots)."""
        tree = _Floats().visit(ast.parse(self.source, mode="eval"))
        code = compile(ast.fix_missing_locations(tree), self.FIELD, "eval")
        return float(eval(code, {"__builtins__": {}}, {**_MATH, "x": x, "y": y}))

    def nonfinite_point(self, mesh) -> tuple[str, tuple[float, float]] | None:
        """Where on the mesh the field is not finite: (what is not, as a message says it: "it is",
        (x, y)); None where it is finite everywhere (first_nonfinite; collective)."""
        bad = first_nonfinite(mesh, [self.ufl(ufl.SpatialCoordinate(mesh))])
        return None if bad is None else ("it is", bad[1])

    def ufl(self, x):
        """The UFL expression of the field at the spatial coordinate x."""
        return eval(compile(self.source, self.FIELD, "eval"), {"__builtins__": {}}, {**_UFL, "x": x[0], "y": x[1]})


def first_nonfinite(mesh, values) -> tuple[int, tuple[float, float]] | None:
    """The first point of the mesh where one of `values` (UFL scalars of the spatial coordinate)
    is not finite: (the index of the first such value there, (x, y)), or None. Evaluated at each
    cell's vertices and at the points of its degree-4 Gauss rule (the nonlinear sheet's
    quadrature); collective over the mesh's ranks."""
    import basix
    import dolfinx.fem
    import numpy as np

    x = ufl.SpatialCoordinate(mesh)
    n = len(values)
    rule, _ = basix.make_quadrature(basix.CellType.triangle, 4)
    points = np.vstack([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], rule])
    cells = np.arange(mesh.topology.index_map(2).size_local, dtype=np.int32)
    expr = dolfinx.fem.Expression(ufl.as_vector([*values, x[0], x[1]]), points, comm=mesh.comm)
    v = expr.eval(mesh, cells).reshape(-1, n + 2)
    bad = np.flatnonzero(~np.isfinite(v[:, :n]).all(axis=1))
    mine = None
    if bad.size:
        row = v[bad[0]]
        mine = (int(np.flatnonzero(~np.isfinite(row[:n]))[0]), (float(row[n]), float(row[n + 1])))
    return next((b for b in mesh.comm.allgather(mine) if b is not None), None)


def _depth(tree) -> int:
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


class _Floats(ast.NodeTransformer):
    def visit_Constant(self, node):
        return ast.Constant(float(node.value)) if isinstance(node.value, int) else node
