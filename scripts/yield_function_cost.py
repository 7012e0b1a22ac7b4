"""The constitutive update's cost per layer for each yield function (docs/material.md: cost).

    python scripts/yield_function_cost.py

Times shellform.material.update.section_update (the sheet's material loop, finite strains, one
thread) on
2,000 cells x 3 quadrature points x 5 layers, every layer plastic from a virgin state (the
local Newton from its radial start), the least process CPU time of 7 runs after a warm-up
(CPU time: a machine shared with other jobs slows the wall clock, less the CPU time), and
prints microseconds per layer. It runs against any checkout on PYTHONPATH: criteria that checkout
lacks are skipped (to compare with the code before the yield functions were parts).
"""

import time

import numpy as np

from shellform.material import Hill79Material, through_thickness_rule
from shellform.material.update import section_update

CELLS, QP, NZ = 2000, 3, 5
SWIFT = dict(hardening="swift", K=565.32, eps0=0.007117, n=0.2589)


def materials():
    out = {"hill79 m=2": Hill79Material(206e3, 0.3, 1.5, 2.0, **SWIFT),
           "hill79 m=6": Hill79Material(206e3, 0.3, 1.5, 6.0, **SWIFT)}
    try:
        from shellform.material import SheetMaterial, criteria
    except ImportError:
        return out
    steel = {"r0": 1.79, "r45": 1.51, "r90": 2.27}
    if "hill48" in criteria.CRITERIA:
        out["hill48 rd=0"] = SheetMaterial(206e3, 0.3, **SWIFT, yield_function="hill48", yield_parameters=steel)
        out["hill48 rd=30"] = SheetMaterial(206e3, 0.3, **SWIFT, yield_function="hill48", yield_parameters=steel,
                                            rolling_direction=30.0)
    if "yld2000" in criteria.CRITERIA:
        aa2090 = {"alpha": [0.4865, 1.3783, 0.7536, 1.0246, 1.0363, 0.9036, 1.2321, 1.4858], "a": 8.0}
        out["yld2000 a=8"] = SheetMaterial(206e3, 0.3, **SWIFT, yield_function="yld2000", yield_parameters=aa2090)
    if "poly6" in criteria.CRITERIA:  # PolyN's Poly6 of AA6016-T4, as the ESAFORM study runs it
        from shellform.studies.esaform_cup import POLYN

        out["poly6"] = SheetMaterial(206e3, 0.3, **SWIFT, yield_function="poly6",
                                     yield_parameters={"coefficients": POLYN})
    return out


def main():
    rng = np.random.default_rng(0)
    e = np.zeros((CELLS, QP, 6))
    e[..., :3] = rng.normal(scale=0.05, size=(CELLS, QP, 3))
    e[..., 3:] = rng.normal(scale=0.02, size=(CELLS, QP, 3))
    zeta, wz = through_thickness_rule(NZ)
    for name, material in materials().items():
        mat = material.pack()
        args = lambda: (e, np.zeros((CELLS, QP, 3)), mat, 0.8, True, True, zeta, wz,  # noqa: E731
                        np.zeros((CELLS, QP, NZ, 3)),
                        np.zeros((CELLS, QP, NZ)), np.ones((CELLS, QP)), np.zeros((CELLS, QP, NZ, 3)),
                        np.zeros((CELLS, QP, NZ)), np.ones((CELLS, QP)), np.zeros((CELLS, QP, 6)),
                        np.zeros((CELLS, QP, 6, 6)))
        section_update(*args())
        times = []
        for _ in range(7):
            a = args()
            t0 = time.process_time()
            nplastic, nfail, _ = section_update(*a)
            times.append(time.process_time() - t0)
        print(f"{name:14s} {1e6 * min(times) / (CELLS * QP * NZ):7.3f} us/layer "
              f"(plastic {nplastic}, failed {nfail})", flush=True)


if __name__ == "__main__":
    main()
