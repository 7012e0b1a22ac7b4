"""Elastic-plastic sheet material: plane stress, Hill 1979 (planar isotropy), numba kernels.

A material travels to the numba functions as one packed float64 array

    mat = [E, nu, r, m, law, a, b, c]

    E, nu   Young's modulus and Poisson ratio (plane-stress isotropic elasticity)
    r, m    Lankford coefficient and Hill-1979 exponent (r > 0, m >= 1)
    law     0 elastic (never yields)
            1 power law  eps_bar / eps_y = (sigma_bar / sigma_y)^n above yield, eps_y = sigma_y/E,
                         eps_bar the total uniaxial strain; a = sigma_y, b = n >= 1 (1: perfect)
            2 Swift      sigma_bar = K (eps0 + p)^n;  a = K, b = eps0 > 0, c = n >= 0 (0: perfect)

Modules: hardening (flow stress), hill79 (yield function, return map), section (through-thickness
integration), point (material-point drivers for tests and studies).
"""

from dataclasses import dataclass
import math

import numpy as np

from shellform.errors import InputError

# Packed layout (the numba modules read these as compile-time constants).
E_, NU_, R_, M_, LAW_, A_, B_, C_ = range(8)
LAW_ELASTIC, LAW_POWER, LAW_SWIFT = 0, 1, 2
LAWS = {"none": LAW_ELASTIC, "power": LAW_POWER, "swift": LAW_SWIFT}


def _number(field: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a number, got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x):
        raise InputError(field, f"must be a finite number, got {value!r}")
    return x


def _require(ok: bool, field: str, message: str) -> None:
    if not ok:
        raise InputError(field, message)


@dataclass(frozen=True)
class Hill79Material:
    """Plane-stress elastic-plastic sheet: isotropic elasticity, Hill 1979, isotropic hardening.

    hardening: "none" (elastic), "power" (needs yield_stress, n >= 1) or "swift" (needs K,
    eps0 > 0, n >= 0). Invalid fields raise InputError naming ``material.<field>``.
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

    def __post_init__(self):
        self.pack()

    def _curve(self, name: str) -> float:
        value = getattr(self, name)
        _require(value is not None, f"material.{name}",
                 f"is required for hardening = {self.hardening!r}")
        return _number(f"material.{name}", value)

    def pack(self) -> np.ndarray:
        """Validate the fields and return mat = [E, nu, r, m, law, a, b, c] (float64)."""
        E = _number("material.E", self.E)
        nu = _number("material.nu", self.nu)
        r = _number("material.r", self.r)
        m = _number("material.m", self.m)
        _require(E > 0.0, "material.E", f"must be positive, got {E}")
        _require(-1.0 < nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {nu}")
        _require(r > 0.0, "material.r", f"must be positive, got {r}")
        _require(m >= 1.0, "material.m", f"must be >= 1 (convex yield function), got {m}")
        _require(isinstance(self.hardening, str) and self.hardening in LAWS, "material.hardening",
                 f"must be one of {', '.join(LAWS)}, got {self.hardening!r}")
        law = LAWS[self.hardening]
        a = b = c = 0.0
        if law == LAW_POWER:
            a, b = self._curve("yield_stress"), self._curve("n")
            _require(a > 0.0, "material.yield_stress", f"must be positive, got {a}")
            _require(b >= 1.0, "material.n", f"must be >= 1 for the power law, got {b}")
        elif law == LAW_SWIFT:
            a, b, c = self._curve("K"), self._curve("eps0"), self._curve("n")
            _require(a > 0.0, "material.K", f"must be positive, got {a}")
            _require(b > 0.0, "material.eps0", f"must be positive, got {b}")
            _require(c >= 0.0, "material.n", f"must be >= 0 for the Swift law, got {c}")
        return np.array([E, nu, r, m, float(law), a, b, c], dtype=np.float64)


from shellform.material.hardening import flow_stress  # noqa: E402
from shellform.material.hill79 import (  # noqa: E402
    equivalent_stress, return_map, thickness_strain, yield_derivatives,
)
from shellform.material.section import (  # noqa: E402
    elastic_section, section_response, through_thickness_rule,
)

__all__ = [
    "Hill79Material", "LAW_ELASTIC", "LAW_POWER", "LAW_SWIFT", "flow_stress", "equivalent_stress",
    "yield_derivatives", "return_map", "thickness_strain", "through_thickness_rule",
    "section_response", "elastic_section",
]
