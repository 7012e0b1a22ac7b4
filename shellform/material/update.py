"""The constitutive update of every section point of the sheet, in one numba loop.

For each cell c and quadrature point g, from the section strains e = (E, K) (6), either the
closed-form elastic section (no layers) or the layered elastic-plastic section from the
committed state (ep_n, p_n) to the trial state (ep, p). Returns the resultants S (6), the
section tangents D (6 x 6) and the counts of plastic layers, of layers whose return mapping
failed, and of points past the strain guard: a strain that is not finite or beyond 1000 % is
not updated (no material takes it; the iterate has left the physical range) and the driver
cuts back, naming which of the two stopped it.
``elastic_tangent`` returns the elastic section tangent with the elastic-plastic stresses: the
first iteration after a load reversal, where a perfectly plastic tangent is (nearly) singular
along the very direction in which the sheet unloads elastically.
"""

import numba
import numpy as np

from shellform.material import section


@numba.njit(parallel=True)  # not cached: numba would not see edits of section.py
def section_update(e, mat, thickness, plastic, zeta, wz, ep_n, p_n, ep, p, S, D, elastic_tangent=False):
    nplastic, nfail, nguard = 0, 0, 0
    for c in numba.prange(e.shape[0]):  # cells are independent: threads share them
        Sg = np.zeros(6)
        Dg = np.zeros((6, 6))
        for g in range(e.shape[1]):
            em = e[c, g, :3].copy()
            k = e[c, g, 3:].copy()
            size = max(np.abs(em).max(), np.abs(k).max() * thickness)
            if not np.isfinite(size) or size > 10.0:  # the strain guard: no material takes 1000 %
                nguard += 1
                section.elastic_section(em * 0.0, k * 0.0, thickness, mat, Sg, Dg)
            elif plastic:
                st = section.section_response(em, k, thickness, zeta, wz, ep_n[c, g], p_n[c, g], mat,
                                              Sg, Dg, ep[c, g], p[c, g])
                if st < 0:
                    nfail += 1
                else:
                    nplastic += st
            else:
                section.elastic_section(em, k, thickness, mat, Sg, Dg)
            S[c, g, :] = Sg
            if elastic_tangent:  # the unloading predictor: stresses plastic, tangent elastic
                section.elastic_section(em, k, thickness, mat, np.zeros(6), Dg)
            D[c, g, :, :] = Dg
    return nplastic, nfail, nguard
