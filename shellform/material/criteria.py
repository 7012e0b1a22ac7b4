"""The registered yield functions and the dispatch the return mapping calls.

A yield function is one file in shellform/material/ holding

    NAME                      its name in a scene (material.yield_function)
    PLANAR_ISOTROPIC          True where the rolling direction changes nothing (the return
                              mapping then does not turn into its axes)
    parameters(values)        its parameters from the material's keys, validated (InputError
                              naming the field), as a list of at most NPAR floats (packed at PAR_)
    yield_function(s0, s1, s2, mat, order)   numba (inline="always"): sigma_bar(s) in the
                              rolling-direction axes, and for order > 0 its gradient (3)
                              and Hessian (6, upper triangle), as one 10-tuple

It is registered here: its module in CRITERIA (its id is its place there) and one line in
``yield_function`` below, in the same order; its scene keys go to YIELD_PARAMETERS in
shellform/scene/schema.py. numba compiles the dispatch into a switch on the packed
id; each criterion's yield_function is declared inline="always" (numba IR inlining) and so
inlined into its branch (docs/material.md: cost).
"""

from shellform.material import CRITERION_, hill48, hill79, yld2000
from shellform import _jit as jit

CRITERIA = {m.NAME: m for m in (hill79, hill48, yld2000)}  # name -> module; the id of each is its place here


@jit.njit(inline="always")
def yield_function(s0, s1, s2, mat, order):
    """sigma_bar(s) and (order > 0) its derivatives, of the packed material's criterion."""
    c = mat[CRITERION_]
    if c == 1.0:
        return hill48.yield_function(s0, s1, s2, mat, order)
    if c == 2.0:
        return yld2000.yield_function(s0, s1, s2, mat, order)
    return hill79.yield_function(s0, s1, s2, mat, order)
