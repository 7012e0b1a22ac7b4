"""pi_m, load part: work of the external loads (subtracted from the strain energy).

Uniform pressure p on the transverse displacement: W = int_K p w dA, with w the reduced cubic
(consistent load). Point loads act on vertex values directly and are added by shellform.loads.
"""

import ufl


def pressure_work(w, pressure):
    return pressure * w * ufl.dx
