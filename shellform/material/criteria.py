"""The registry of yield functions and the dispatch the return mapping calls.

A yield function is one module of shellform/material/ that declares everything about itself:

    NAME                      its name in a scene (material.yield_function)
    PARAMETERS                its [material] keys in a scene (shellform.scene.schema.YIELD_PARAMETERS
                              is read from here; every key is a field of schema.Material)
    PLANAR_ISOTROPIC          True where the rolling direction changes nothing (the return
                              mapping then does not turn into its axes)
    parameters(values)        its parameters from the material's keys, validated (InputError
                              naming the field), as a list of at most NPAR floats (packed at PAR_)
    yield_function(s0, s1, s2, mat, order)   numba (inline="always"): sigma_bar(s) in the
                              rolling-direction axes, and for order > 0 its gradient (3)
                              and Hessian (6, upper triangle), as one 10-tuple

and may declare

    check(values)             validates its keys before any computation (InputError naming the
                              field): scene checking calls it
    describe(values)          words for a run's log beyond its keys (a fit's errors), or ""

Registering it is one line: its module's name in REGISTRY. Its id (the packed
mat[CRITERION_]) is its place there; CRITERIA maps the NAMEs to the modules in that order.

The dispatch ``yield_function`` is generated from REGISTRY (``dispatch_source``): a chain of
``if c == i: return criterion_i.yield_function(...)`` for the ids 1, 2, ..., the first
registered (id 0, Hill 1979) the fall-through. numba compiles it into a switch on the packed
id; each criterion's yield_function is declared inline="always" (numba IR inlining) and so
inlined into its branch (docs/material.md: cost), and the dispatch is inline="always" too, so
the return mapping holds the switch itself, as it would hold a hand-written one. Its code is
compiled with this file's name: numba caches it with the package's other numba code (the
cache folder is keyed by the sources of shellform/material, this registry among them).
"""

import importlib

from shellform import _jit as jit
from shellform import registry
from shellform.material.layout import CRITERION_

REGISTRY = ("hill79", "hill48", "yld2000", "poly6")  # modules of shellform.material; the id of each is its place here

DECLARES = ("NAME", "PARAMETERS", "PLANAR_ISOTROPIC", "parameters", "yield_function")


MODULES = tuple(importlib.import_module(f"{__package__}.{name}") for name in REGISTRY)
CRITERIA = registry.checked(MODULES, DECLARES, "yield function")  # NAME -> module, in registry order


def dispatch_source(modules: tuple) -> str:
    """The Python source of the dispatch over `modules` (module i as the global criterion_i)."""
    lines = ["def yield_function(s0, s1, s2, mat, order):",
             '    """sigma_bar(s) and (order > 0) its derivatives, of the packed material\'s criterion."""',
             "    c = mat[CRITERION_]"]
    for i in range(1, len(modules)):
        lines += [f"    if c == {float(i)!r}:", f"        return criterion_{i}.yield_function(s0, s1, s2, mat, order)"]
    lines.append("    return criterion_0.yield_function(s0, s1, s2, mat, order)")
    return "\n".join(lines) + "\n"


def _dispatch(modules: tuple):
    """The dispatch over `modules`, compiled by numba (inline="always", cached)."""
    namespace = {"__name__": __name__, "CRITERION_": CRITERION_}
    namespace.update({f"criterion_{i}": m for i, m in enumerate(modules)})
    exec(compile(dispatch_source(modules), __file__, "exec"), namespace)
    return jit.njit(inline="always")(namespace["yield_function"])


yield_function = _dispatch(MODULES)
