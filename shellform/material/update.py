"""The constitutive update of every section point of the sheet, in one numba loop.

For each cell c and quadrature point g, from the section strains e = (E, K) (6), either the
closed-form elastic section (no layers) or the layered elastic-plastic section from the
committed state (ep_n, p_n) to the trial state (ep, p). Returns the resultants S (6), the
section tangents D (6 x 6) and the counts of plastic layers, of layers whose return mapping
failed, and of points past the strain guard: a strain that is not finite or beyond 1000 % is
not updated (no material takes it; the iterate has left the physical range) and the driver
cuts back, naming which of the two stopped it.

finite: the layers work in logarithmic strains (shellform.material.hencky); their lever arm is
the thickness of a sheet that keeps its volume, t / J with J the mid-surface's area stretch
(section.incompressible_lever: a function of the iterate's membrane strain, its term in D), and
the layers' thickness stretch lambda3 = exp(sum_i w_i e33_i) (a uniform stretch across the
section), the thickness the results and the contact read, is written to `stretch`.
``taper`` (cells, points, 3): a curvature the section carries without a moment, subtracted from
K before the section sees it (SheetModel.follow_taper: a thickness that varies between flat faces).
``elastic_tangent`` returns the elastic section tangent with the elastic-plastic stresses: the
first iteration after a load reversal, where a perfectly plastic tangent is (nearly) singular
along the very direction in which the sheet unloads elastically.
"""

import math

import numpy as np

from shellform.material import section
from shellform import _jit as jit


def section_update(e, taper, mat, thickness, plastic, finite, zeta, wz, ep_n, p_n, ep, p, stretch,
                   S, D, elastic_tangent=False, threads=1):
    """Every cell's sections, on `threads` threads (update_share); returns the counts (plastic
    layers, failed layers, points past the guard)."""
    counts = jit.over_threads(update_share, threads, e, taper, mat, thickness, plastic, finite, zeta, wz, ep_n, p_n,
                              ep, p, stretch, S, D, elastic_tangent)
    return tuple(sum(c[i] for c in counts) for i in range(3))


@jit.njit(nogil=True)
def update_share(counter, e, taper, mat, thickness, plastic, finite, zeta, wz, ep_n, p_n, ep, p,
                 stretch, S, D, elastic_tangent):
    """The sections of the cells, a chunk of them at a time from the threads' shared counter
    (jit.over_threads, jit.next_chunk); returns this thread's counts."""
    # the views taken below count no references (jit.borrowed)
    e, taper, mat, zeta, wz = jit.borrowed(e), jit.borrowed(taper), jit.borrowed(mat), jit.borrowed(zeta), \
        jit.borrowed(wz)
    ep_n, p_n = jit.borrowed(ep_n), jit.borrowed(p_n)
    ep, p, stretch, S, D = jit.borrowed(ep), jit.borrowed(p), jit.borrowed(stretch), jit.borrowed(S), jit.borrowed(D)
    nplastic, nfail, nguard = 0, 0, 0
    w = np.zeros((4, 16))  # scratch
    zero, k, dlever = np.zeros(3), np.zeros(3), np.zeros(3)
    n = e.shape[0]
    start = jit.next_chunk(counter)
    while start < n:
        for c in range(start, min(start + jit.CHUNK, n)):
            for g in range(e.shape[1]):
                em = e[c, g, :3]
                for a in range(3):
                    k[a] = e[c, g, 3 + a] - taper[c, g, a]
                Sg, Dg = S[c, g], D[c, g]
                size, real = 0.0, True  # real: every strain finite
                for a in range(3):
                    size = max(size, abs(em[a]), abs(k[a]) * thickness)
                    real = real and math.isfinite(em[a]) and math.isfinite(k[a])
                if not real or size > 10.0:  # the strain guard: no material takes 1000 %
                    nguard += 1
                    section.elastic_section(zero, zero, thickness, mat, Sg, Dg)
                elif plastic:
                    if finite:  # the lever follows the membrane strain
                        lever = section.incompressible_lever(em, thickness, dlever)
                        st, e33 = section.section_response(em, k, thickness, lever, zeta, wz, ep_n[c, g], p_n[c, g],
                                                           mat, finite, elastic_tangent, Sg, Dg, ep[c, g], p[c, g],
                                                           w, dlever)
                    else:
                        st, e33 = section.section_response(em, k, thickness, thickness, zeta, wz, ep_n[c, g],
                                                           p_n[c, g], mat, finite, elastic_tangent, Sg, Dg, ep[c, g],
                                                           p[c, g], w)
                    stretch[c, g] = math.exp(e33) if finite else 1.0
                    if st < 0:
                        nfail += 1
                    else:
                        nplastic += st
                else:
                    section.elastic_section(em, k, thickness, mat, Sg, Dg)
        start = jit.next_chunk(counter)
    return nplastic, nfail, nguard
