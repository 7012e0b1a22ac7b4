"""The packed material array's layout (its slots by name: shellform.material's docstring) and
the validation of a material's numbers. The numba modules read the slots as compile-time
constants; every module of shellform.material imports them from here, and the package
re-exports them."""

import math

from shellform.errors import InputError

# Packed layout (the numba modules read these as compile-time constants).
E_, NU_, LAW_, CRITERION_, COS_, SIN_, ROTATED_ = range(7)
H_, NH = 8, 8  # hardening parameters
A_, B_, C_ = H_, H_ + 1, H_ + 2
PAR_, NPAR = H_ + NH, 16  # yield-function parameters
TABLE_ = PAR_ + NPAR
SIZE = TABLE_ + 1  # without a table
LAW_ELASTIC, LAW_POWER, LAW_SWIFT, LAW_VOCE, LAW_SWIFT_VOCE, LAW_TABLE = range(6)
LAWS = {"none": LAW_ELASTIC, "power": LAW_POWER, "swift": LAW_SWIFT, "voce": LAW_VOCE, "swift_voce": LAW_SWIFT_VOCE,
        "table": LAW_TABLE}


def number(field: str, value) -> float:
    """value as a finite float, else InputError naming `field`."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a number, got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x):
        raise InputError(field, f"must be a finite number, got {value!r}")
    return x


def require(ok: bool, field: str, message: str) -> None:
    if not ok:
        raise InputError(field, message)
