"""The checks of a scene's [tools] table: the keys every kind of tools takes (the holder, the
force, friction, the stroke), the kind's own (its module's check: shellform.tools.kinds), the
blank's reach beyond the die's flat top, drawbeads, and the effects 'contact', 'friction' and
'drawbeads' (run by checks.validate after the material: the clearance is checked against the
thickness). Every bad value raises InputError naming its field."""

import math

import numpy as np

from shellform.scene.rules import keys_of_effects, require
from shellform.scene.schema import FRICTION_TOOLS, HOLDERS, SIDES, SPREADS, TOOL_SHAPES
from shellform.tools import kinds as tool_kinds

# tools.drawbead: the points of all beads together. Every Newton iteration clips each segment to
# the sheet's cells near it (shellform.contact.drawbead); a bead's line needs no segment shorter
# than a cell, and a quarter blank's flange is crossed by a few hundred cells at the finest meshes.
MAX_DRAWBEAD_POINTS = 1000


def _validate_drawbead(bead, name: str, plan) -> None:
    """A drawbead: a polyline of at least two distinct points, all on the die's flat top (outside
    its opening and shoulder, where the holder pinches the flange), and forces >= 0."""
    pts = bead.points
    require(len(pts) >= 2, f"{name}.points", f"needs at least two points [x, y], got {len(pts)}")
    require(all(math.isfinite(c) for p in pts for c in p), f"{name}.points", "must be finite")
    for a, b in zip(pts[:-1], pts[1:]):
        require(a != b, f"{name}.points", f"two consecutive points coincide: {a}")
    for key in ("restraint", "uplift"):
        v = getattr(bead, key)
        require(v >= 0, f"{name}.{key}", f"must be >= 0 (N/mm), got {v}")
    require(bead.restraint > 0 or bead.uplift > 0, name, "a drawbead with no restraint and no uplift does nothing")
    p = np.asarray(pts, dtype=float)
    along = np.linspace(0.0, 1.0, 21)[:, None, None]
    samples = (p[:-1] + along * (p[1:] - p[:-1])).reshape(-1, 2)  # 21 points on every segment
    distance = plan.distance(samples[:, 0], samples[:, 1])
    require(bool(np.all(distance >= 0)), f"{name}.points",
            f"must lie on the die's flat top, outside its opening and shoulder (the rounded square of "
            f"half-width {plan.half_width}, where the holder begins); "
            f"{samples[int(np.argmin(distance))].tolist()} lies within it")


def validate_tools(s) -> None:
    """The [tools] table and the effects 'contact' and 'friction' (after the material: the
    clearance is checked against the thickness)."""
    t = s.tools
    if t is None:
        require("contact" not in s.effects, "tools", "the effect 'contact' needs a [tools] table")
        return
    require("contact" in s.effects, "effects", "a [tools] table needs the effect 'contact'")
    keys_of_effects(s, "tools")
    require(t.shape in TOOL_SHAPES, "tools.shape", f"must be one of {TOOL_SHAPES}, got {t.shape!r}")
    require(t.holder_spread in SPREADS, "tools.holder_spread", f"must be one of {SPREADS}, got {t.holder_spread!r}")
    _validate_holder(s, t)
    for name in ("blank_holder_force", "friction", "stroke"):
        v = getattr(t, name)
        require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{name}", f"must be finite, got {v}")
    require(t.stroke > 0, "tools.stroke", f"must be > 0, got {t.stroke}")
    for name in ("blank_holder_force", "friction"):
        require(getattr(t, name) >= 0, f"tools.{name}", f"must be >= 0, got {getattr(t, name)}")
    _validate_friction_per_tool(s, t)
    plan = tool_kinds.kind(t.shape).check(s)
    flat, what = plan.half_width, plan.keys
    g = s.geometry
    if g.shape == "rectangle":
        sides = [k for k in ("lx", "ly") if k[1] in plan.across]
        side = min(sides, key=lambda k: getattr(g, k))
        require(getattr(g, side) / 2 > flat, f"geometry.{side}",
                f"the blank does not reach the blank holder and the die's flat top: half its size "
                f"{getattr(g, side) / 2} must exceed {what} = {flat}")
    elif g.shape == "circle":
        require(g.radius > flat, "geometry.radius",
                f"the blank does not reach the blank holder and the die's flat top: its radius {g.radius} "
                f"must exceed {what} = {flat}")
    require(bool(t.drawbead) or "drawbeads" not in s.effects, "tools.drawbead",
            "the effect 'drawbeads' needs at least one [[tools.drawbead]]")
    points = sum(len(bead.points) for bead in t.drawbead)
    require(points <= MAX_DRAWBEAD_POINTS, "tools.drawbead",
            f"holds {points:,} points in all; at most {MAX_DRAWBEAD_POINTS:,} (each segment is clipped to the "
            "sheet's cells at every Newton iteration: a bead needs no segment shorter than a cell)")
    for i, bead in enumerate(t.drawbead):
        _validate_drawbead(bead, f"tools.drawbead[{i}]", plan)
    if g.shape == "rectangle":
        outer = ("right", "top") if g.region == "quarter" else SIDES
    else:  # an outline's edges are free or symmetry lines
        outer = tuple(k for k, v in s.supports.items() if v != "symmetry")
    for side in outer:
        v = s.supports.get(side, "free")
        require(v == "free", f"supports.{side}",
                f"the tools hold the blank: its outer edges must be 'free', got {v!r}")


def _validate_friction_per_tool(s, t) -> None:
    """Each tool's own coefficient, where given: finite and >= 0; the effect 'friction' needs
    one > 0 among the coefficients the tools carry (the error names tools.friction, or
    tools.punch_friction where every tool has its own and `friction` is used by none)."""
    for name in FRICTION_TOOLS:
        key = f"{name}_friction"
        v = getattr(t, key)
        if v is None:
            continue
        require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{key}", f"must be finite, got {v}")
        require(v >= 0, f"tools.{key}", f"must be >= 0, got {v}")
    own = all(getattr(t, f"{name}_friction") is not None for name in FRICTION_TOOLS)
    mu = t.friction_per_tool()
    require(max(mu.values()) > 0 or "friction" not in s.effects, "tools.punch_friction" if own else "tools.friction",
            "the effect 'friction' needs friction > 0 on at least one tool (friction, or a tool's own punch_friction, "
            f"die_friction, holder_friction), got {', '.join(f'{k} {v:g}' for k, v in mu.items())}")


def _validate_holder(s, t) -> None:
    """The holder's mode: pressing with blank_holder_force, or held at holder_gap over the die's top
    (at least the sheet's thickness; the flange that thickens into the gap is ironed, which needs
    the effect 'ironing')."""
    require(t.holder in HOLDERS, "tools.holder", f"must be one of {HOLDERS}, got {t.holder!r}")
    gap = t.holder_gap
    require(isinstance(gap, (int, float)) and math.isfinite(gap), "tools.holder_gap", f"must be finite, got {gap}")
    if t.holder == "force":
        require(gap == 0, "tools.holder_gap", "is a key of tools.holder = 'gap' (the holder presses with "
                "blank_holder_force)")
        return
    require("ironing" in s.effects, "tools.holder",
            "'gap' needs the effect 'ironing': the flange thickens into the gap and the faces iron it")
    thickness = s.material.thickness
    require(gap >= thickness, "tools.holder_gap",
            f"must be at least the sheet's thickness {thickness}, got {gap}: the holder would squeeze the blank "
            "before the draw")
