"""Elastic-plastic sheet material: plane stress, a registered yield function, numba kernels.

A material travels to the numba functions as one packed float64 array ``mat`` (slots by name):

    E_, NU_       Young's modulus and Poisson ratio (plane-stress isotropic elasticity)
    LAW_          the hardening law: 0 elastic (never yields), 1 power law, 2 Swift, 3 Voce,
                  4 Swift-Voce, 5 table (shellform.material.hardening states each law and its
                  parameters H_ ...)
    H_ .. H_+NH   the hardening law's parameters (A_, B_, C_ the first three)
    CRITERION_    the yield function's id (shellform.material.criteria: its place in REGISTRY)
    COS_, SIN_    cos and sin of the rolling direction's angle theta from the x axis
    ROTATED_      1.0 where the return mapping turns strains into the rolling-direction axes
                  (theta not a multiple of 180 degrees, a criterion that is not planar
                  isotropic), else 0.0
    PAR_ .. PAR_+NPAR  the yield function's parameters (its file says which)
    TABLE_ ..     a tabulated flow curve: its number of points N + 1, p_0..p_N, sigma_0..sigma_N
                  (shellform.material.flow_curve; the array ends there, 1 + 0 points without one)

The yield function, its parameters and its derivatives live in one file each (hill79, ...),
registered by its name in shellform.material.criteria.REGISTRY; the return mapping
(plane_stress) is written once for all of them; section integrates the layers through the
thickness; point drives a material point for tests and studies.
"""

from dataclasses import dataclass, field
import math

import numpy as np


from shellform.material.layout import (A_, B_, C_, COS_, CRITERION_, E_, H_, LAW_, LAW_ELASTIC, LAW_POWER,  # noqa: F401
                                       LAW_SWIFT, LAW_SWIFT_VOCE, LAW_TABLE, LAW_VOCE, LAWS, NH, NPAR, NU_, PAR_,
                                       ROTATED_, SIN_, SIZE, TABLE_, number, require)


@dataclass(frozen=True)
class SheetMaterial:
    """Plane-stress elastic-plastic sheet: isotropic elasticity, a yield function, isotropic
    hardening.

    hardening: "none" (elastic), "power" (needs yield_stress, n > 1), "swift" (needs K,
    eps0 > 0, n >= 0), "voce" (yield_stress > 0, Q >= 0, beta > 0), "swift_voce" (all of these
    and the Swift share 0 < swift_weight < 1) or "table" (flow_curve: rows (p, true stress),
    extrapolation one of shellform.material.flow_curve.EXTRAPOLATIONS). yield_function: a name of shellform.material.criteria.CRITERIA (the
    paper's "hill79" with r, m by default); its parameters are r, m and the entries of
    yield_parameters (the criterion's file names them). rolling_direction: the angle of the
    rolling direction from the x axis, degrees. Invalid fields raise InputError naming
    ``material.<field>``.
    """

    E: float
    nu: float
    r: float = 1.0
    m: float = 2.0
    hardening: str = "none"
    yield_stress: float | None = None
    n: float | None = None
    K: float | None = None
    eps0: float | None = None
    yield_function: str = "hill79"
    yield_parameters: dict = field(default_factory=dict)
    rolling_direction: float = 0.0
    Q: float | None = None
    beta: float | None = None
    swift_weight: float | None = None
    flow_curve: object = None  # a table (N + 1, 2) of (p, sigma), or None
    extrapolation: str | None = None  # table: beyond its last point (required)

    def __post_init__(self):
        self.pack()

    def _curve(self, name: str) -> float:
        value = getattr(self, name)
        require(value is not None, f"material.{name}", f"is required for hardening = {self.hardening!r}")
        return number(f"material.{name}", value)

    def pack(self) -> np.ndarray:
        """Validate the fields and return the packed material (float64, layout above)."""
        from shellform.material import criteria

        E = number("material.E", self.E)
        nu = number("material.nu", self.nu)
        require(E > 0.0, "material.E", f"must be positive, got {E}")
        require(-1.0 < nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {nu}")
        require(isinstance(self.yield_function, str) and self.yield_function in criteria.CRITERIA,
                "material.yield_function",
                f"must be one of {', '.join(criteria.CRITERIA)}, got {self.yield_function!r}")
        criterion = criteria.CRITERIA[self.yield_function]
        par = criterion.parameters({"r": self.r, "m": self.m, **self.yield_parameters})
        theta = math.radians(number("material.rolling_direction", self.rolling_direction))
        require(isinstance(self.hardening, str) and self.hardening in LAWS, "material.hardening",
                f"must be one of {', '.join(LAWS)}, got {self.hardening!r}")
        law = LAWS[self.hardening]
        h = []
        if law == LAW_POWER:
            h = [self._curve("yield_stress"), self._curve("n")]
            require(h[0] > 0.0, "material.yield_stress", f"must be positive, got {h[0]}")
            require(h[1] > 1.0, "material.n",
                    f"must be > 1 for the power law, got {h[1]}: its total strain eps_y (s / sigma_y)^n "
                    "turns elastic as n falls to 1 (n -> infinity is the perfectly plastic limit); a "
                    "perfectly plastic sheet is hardening = \"swift\" with n = 0 and K = sigma_y")
        if law in (LAW_SWIFT, LAW_SWIFT_VOCE):
            h = [self._curve("K"), self._curve("eps0"), self._curve("n")]
            require(h[0] > 0.0, "material.K", f"must be positive, got {h[0]}")
            require(h[1] > 0.0, "material.eps0", f"must be positive, got {h[1]}")
            require(h[2] >= 0.0, "material.n", f"must be >= 0 for the Swift law, got {h[2]}")
        if law in (LAW_VOCE, LAW_SWIFT_VOCE):
            v = [self._curve("yield_stress"), self._curve("Q"), self._curve("beta")]
            require(v[0] > 0.0, "material.yield_stress", f"must be positive, got {v[0]}")
            require(v[1] >= 0.0, "material.Q", f"must be >= 0 (a Voce curve that hardens), got {v[1]}")
            require(v[2] > 0.0, "material.beta", f"must be positive, got {v[2]}")
            h += v
        if law == LAW_SWIFT_VOCE:
            w = self._curve("swift_weight")
            require(0.0 < w < 1.0, "material.swift_weight", f"must lie in (0, 1) (0, 1: use voce, swift), got {w}")
            h.append(w)
        table = np.zeros(1)
        if law == LAW_TABLE:
            from shellform.material.flow_curve import FlowCurve

            require(self.flow_curve is not None, "material.flow_curve", "is required for hardening = 'table'")
            curve = FlowCurve.from_table(self.flow_curve, self.extrapolation)
            h = [float(curve.extrapolation_id), *curve.parameters]
            table = curve.packed
        mat = np.zeros(SIZE - 1 + len(table))
        mat[E_], mat[NU_], mat[LAW_] = E, nu, float(law)
        mat[CRITERION_] = float(list(criteria.CRITERIA).index(self.yield_function))
        turns = math.remainder(math.degrees(theta), 180.0) != 0.0 and not criterion.PLANAR_ISOTROPIC
        mat[COS_], mat[SIN_], mat[ROTATED_] = (math.cos(theta), math.sin(theta), 1.0) if turns else (1.0, 0.0, 0.0)
        mat[H_:H_ + len(h)] = h
        mat[PAR_:PAR_ + len(par)] = par
        mat[TABLE_:] = table
        return mat

    def describe(self) -> str:
        """One line: the yield function (its parameters, what its ``describe`` adds, such as a
        least-squares fit's parameters and errors, the rolling direction) and the flow curve (a table's
        extrapolation as fitted), for a run's log."""
        words = [f"yield function {self.yield_function}"]
        if self.yield_function == "hill79":
            words.append(f"r {self.r:g}, m {self.m:g}")
        else:
            words.append(", ".join(f"{k} {v}" for k, v in self.yield_parameters.items()))
            from shellform.material import criteria

            more = getattr(criteria.CRITERIA[self.yield_function], "describe", lambda values: "")
            if text := more(self.yield_parameters):
                words.append(text)
            words.append(f"rolling direction {float(self.rolling_direction):g} deg from x")
        words.append(f"hardening {self.hardening}")
        if self.hardening == "table":
            from shellform.material.flow_curve import FlowCurve

            words.append(FlowCurve.from_table(self.flow_curve, self.extrapolation).extrapolation_text)
        return "material: " + "; ".join(words)


Hill79Material = SheetMaterial  # the paper's material (Hill 1979 by default), by its former name

from shellform.material.hardening import flow_stress  # noqa: E402
from shellform.material.hill79 import equivalent_stress, yield_derivatives  # noqa: E402
from shellform.material.plane_stress import return_map, thickness_strain  # noqa: E402
from shellform.material.section import (  # noqa: E402
    elastic_section, section_response, through_thickness_rule,
)

__all__ = [
    "SheetMaterial", "Hill79Material", "LAW_ELASTIC", "LAW_POWER", "LAW_SWIFT", "LAW_VOCE", "LAW_SWIFT_VOCE",
    "LAW_TABLE", "flow_stress",
    "equivalent_stress", "yield_derivatives", "return_map", "thickness_strain", "through_thickness_rule",
    "section_response", "elastic_section",
]
