"""The kind of tools "square": the square cup's punch, die and blank holder (NUMISHEET'93),
analytic (analytic.py), and what a scene says of them.

A kind of tools declares what shellform.tools.kinds asks of it: its name, its [tools] keys, its
checks, the factory of its tools, whether they need checking against the blank, and its
output (the cup's thickness lines, the rim's ear profile, the depth of the tools' pictures).
"""

import math

import numpy as np

from shellform.errors import require
from shellform.tools.analytic import BlankHolder, Die, Punch
from shellform.tools.holder_edge import RoundedSquareEdge
from shellform.tools.protocol import BinderPlan, ram_travel

NAME = "square"

# its [tools] keys (name, default, what): punch_radius and die_radius are round tools', which
# a square scene keeps at 0 (check)
FIELDS = (
    ("punch_radius", 0.0, "round: the punch's radius (0: unset)"),
    ("die_radius", 0.0, "round: the die opening's radius (0: unset)"),
    ("punch_half_width", 35.0, "70 mm square punch"),
    ("punch_corner_radius", 10.0, "plan corner radius"),
    ("punch_profile_radius", 8.0, "nose radius"),
    ("die_half_width", 37.0, "74 mm die opening"),
    ("die_corner_radius", 12.0, "plan corner radius of the opening"),
    ("die_profile_radius", 5.0, "die shoulder radius"),
    ("punch_gap", 0.0, "initial gap between the punch face and the sheet (>= 0)"),
)

SQUARE_KEYS = ("punch_half_width", "punch_corner_radius", "die_half_width", "die_corner_radius")

# the thickness lines of the drawn cup: name -> nodes on it (initial positions X, tolerance)
LINES = {"diagonal": lambda X, tol: np.abs(X[:, 0] - X[:, 1]) < tol,
         "transverse": lambda X, tol: np.abs(X[:, 1]) < tol}
RIM = False  # the rim's ear profile (rim.csv, rim.png) is a round cup's


def refuse(key: str, owners: tuple) -> str:
    """The message for a key of other kinds (owners: their names) in a square scene."""
    return f"is a key of shape = {owners[0]!r}"


def complete(spec) -> None:
    """Nothing derived: a square scene gives every dimension."""


def check(s) -> BinderPlan:
    """The dimensions of square tools (punch_radius and die_radius unset); returns where the
    die's flat top begins."""
    t = s.tools
    for name in ("punch_radius", "die_radius"):
        require(getattr(t, name) == 0, f"tools.{name}", "is a key of shape = 'round' (square tools: "
                "punch_half_width, punch_corner_radius, die_half_width, die_corner_radius)")
    return check_dimensions(s)


def check_dimensions(s) -> BinderPlan:
    """Square and round tools' dimensions and clearance; returns where the die's flat top (and
    the holder) begins: the rounded square die_half_width + die_profile_radius."""
    t = s.tools
    for name, _, _ in FIELDS:
        v = getattr(t, name)
        require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{name}", f"must be finite, got {v}")
    for name in ("punch_half_width", "punch_profile_radius", "die_half_width", "die_profile_radius", "stroke"):
        v = getattr(t, name)
        require(v > 0, f"tools.{name}", f"must be > 0, got {v}")
    for name in ("punch_corner_radius", "die_corner_radius", "blank_holder_force", "friction"):
        v = getattr(t, name)
        require(v >= 0, f"tools.{name}", f"must be >= 0, got {v}")
    require(t.punch_profile_radius <= t.punch_corner_radius <= t.punch_half_width, "tools.punch_corner_radius",
            f"must lie between punch_profile_radius ({t.punch_profile_radius}) and punch_half_width "
            f"({t.punch_half_width}), got {t.punch_corner_radius}")
    require(t.die_corner_radius <= t.die_half_width, "tools.die_corner_radius",
            f"must be <= die_half_width ({t.die_half_width}), got {t.die_corner_radius}")
    require(t.punch_half_width < t.die_half_width, "tools.punch_half_width",
            f"the punch must fit in the die opening: must be < die_half_width ({t.die_half_width}), "
            f"got {t.punch_half_width}")
    thickness = s.material.thickness
    require(t.die_half_width - t.punch_half_width >= thickness, "tools.die_half_width",
            f"the clearance die_half_width - punch_half_width = {t.die_half_width - t.punch_half_width} "
            f"is smaller than the thickness {thickness}: the sheet cannot pass")
    require(t.punch_gap >= 0, "tools.punch_gap",
            f"must be >= 0 (the punch would overlap the blank), got {t.punch_gap}")
    return BinderPlan(t.die_half_width + t.die_profile_radius, t.die_corner_radius + t.die_profile_radius,
                      "die_half_width + die_profile_radius")


def square_cup_tools(spec, thickness: float) -> dict:
    """Punch, die and blank holder of a scene's ToolsSpec around a sheet of that thickness whose
    mid-surface is z = 0: the die's top touches the sheet's lower surface, the holder rests on
    its upper surface, the punch face lies spec.punch_gap above it."""
    die = Die(spec.die_half_width, spec.die_corner_radius, spec.die_profile_radius, -thickness / 2)
    rd = spec.die_profile_radius
    return dict(
        punch=Punch(spec.punch_half_width, spec.punch_corner_radius, spec.punch_profile_radius,
                    thickness / 2 + spec.punch_gap),
        die=die,
        holder=BlankHolder(RoundedSquareEdge(spec.die_half_width + rd, spec.die_corner_radius + rd), thickness / 2),
    )


tools = square_cup_tools
travel = ram_travel


def check_placement(tools: dict, x, half, planes, comm, tolerance: float) -> None:
    """Nothing to check: analytic tools are placed around the blank by construction."""


def picture_depth(spec) -> float:
    """How far above and below its travelled height a tool's picture reaches: the walls, as deep
    as the stroke and the larger profile radius."""
    return spec.stroke + max(spec.punch_profile_radius, spec.die_profile_radius)
