"""The shell's reference surface z0(x, y), given as an expression in x and y.

The shallow-shell strains need only its curvature tensor,

    kappa0 = -grad grad z0                (the paraboloid z0 = -(x^2/R1 + y^2/R2)/2: diag(1/R1, 1/R2)),

and the Kirchhoff-Love sheet its slopes and Hessian: X0 = (x, y, z0), grad X0 = [I; grad z0]^T.
UFL differentiates the expression; nothing is approximated. The text is Python syntax with
the names below (``x**2``, ``sin(pi*x/L)``); anything else is refused, so a scene file cannot
run code.
"""

import ast
import math
from dataclasses import dataclass

import ufl

FUNCTIONS = ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln", "sqrt")
_MATH = {**{f: getattr(math, f) for f in FUNCTIONS if f != "ln"}, "ln": math.log, "pi": math.pi}
_UFL = {**{f: getattr(ufl, f) for f in FUNCTIONS}, "pi": ufl.pi}
_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load, ast.Constant,
          ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd)


@dataclass(frozen=True)
class ReferenceSurface:
    """z0(x, y) from its text; hashable, so compiled kernels are cached per surface."""

    source: str

    def problem(self) -> str | None:
        """Why the text is no valid expression of x and y (None: it is one)."""
        try:
            tree = ast.parse(self.source, mode="eval")
        except SyntaxError as err:
            return f"not an expression: {err.msg}"
        for node in ast.walk(tree):
            if not isinstance(node, _NODES):
                return (f"{type(node).__name__} is not allowed; use numbers, x, y, + - * / **, pi and "
                        f"{', '.join(FUNCTIONS)}")
            if isinstance(node, ast.Name) and node.id not in ("x", "y", *_MATH):
                return f"unknown name {node.id!r}; known: x, y, pi, {', '.join(FUNCTIONS)}"
            if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS):
                return "only the functions " + ", ".join(FUNCTIONS) + " may be called"
            if isinstance(node, ast.Constant) and not isinstance(node.value, int | float):
                return f"{node.value!r} is no number"
        return None

    def value(self, x: float, y: float) -> float:
        """z0 at a point, in floating point (for checks and plots)."""
        return float(self._eval(_MATH, x, y))

    def z0(self, x):
        """The UFL expression of z0 at the spatial coordinate x."""
        return self._eval(_UFL, x[0], x[1])

    def slopes(self, x):
        return ufl.grad(self.z0(x))

    def hessian(self, x):
        return ufl.grad(ufl.grad(self.z0(x)))

    def kappa0(self, x):
        return -self.hessian(x)

    def _eval(self, names, x, y):
        return eval(compile(self.source, "surface.z0", "eval"), {"__builtins__": {}}, {**names, "x": x, "y": y})
