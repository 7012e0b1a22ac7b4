"""The kind of tools "round": a round punch and die, the square ones (square.py) with plan
corner radius = half-width = radius (their plans are circles), and the round cup's output (its
thickness lines at 0 and 90 degrees to the x axis, the rim's ear profile)."""

import numpy as np

from shellform.errors import require
from shellform.tools import square
from shellform.tools.protocol import BinderPlan

NAME = "round"

FIELDS = (
    ("punch_radius", 0.0, "the punch's radius (0: unset)"),
    ("die_radius", 0.0, "the die opening's radius (0: unset)"),
    ("punch_profile_radius", 8.0, "nose radius"),
    ("die_profile_radius", 5.0, "die shoulder radius"),
    ("punch_gap", 0.0, "initial gap between the punch face and the sheet (>= 0)"),
)

LINES = {"0deg": lambda X, tol: np.abs(X[:, 1]) < tol, "90deg": lambda X, tol: np.abs(X[:, 0]) < tol}
RIM = True


def refuse(key: str, owners: tuple) -> str:
    if "square" in owners:
        return "is a key of square tools: round tools take punch_radius and die_radius"
    return f"is a key of shape = {owners[0]!r}"


def complete(spec) -> None:
    """Circles: the square tools' corner radius = half-width = radius."""
    spec.punch_half_width = spec.punch_corner_radius = spec.punch_radius
    spec.die_half_width = spec.die_corner_radius = spec.die_radius


def check(s) -> BinderPlan:
    t = s.tools
    for name in ("punch_radius", "die_radius"):
        require(getattr(t, name) > 0, f"tools.{name}", f"round tools need {name} > 0, got {getattr(t, name)}")
    return square.check_dimensions(s)


tools = square.square_cup_tools
travel = square.travel
check_placement = square.check_placement
picture_depth = square.picture_depth
