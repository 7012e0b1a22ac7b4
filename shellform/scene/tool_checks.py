"""The checks of a scene's [tools] table: the analytic square or round tools and their
clearances, CAD tools' files and placements, drawbeads, and the effects 'contact', 'friction'
and 'drawbeads' (run by checks.validate after the material: the clearance is checked against
the thickness). Every bad value raises InputError naming its field."""

import math
from dataclasses import fields
from pathlib import Path

import numpy as np

from shellform.mesh.outline import MIRROR_NORMALS
from shellform.scene.rules import keys_of_effects, require
from shellform.scene.schema import CAD_TOOL_KEYS, HOLDERS, SIDES, SPREADS, TOOL_NORMALS, TOOL_SHAPES, Scene, ToolsSpec


def _validate_drawbead(bead, name: str, flat: float, corner: float) -> None:
    """A drawbead: a polyline of at least two distinct points, all on the die's flat top (outside
    its opening and shoulder, where the holder pinches the flange), and forces >= 0."""
    from shellform.contact.tools import rounded_square_sdf

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
    distance, _, _ = rounded_square_sdf(samples[:, 0], samples[:, 1], flat, corner)
    require(bool(np.all(distance >= 0)), f"{name}.points",
            f"must lie on the die's flat top, outside its opening and shoulder (the rounded square of "
            f"half-width {flat}, where the holder begins); "
            f"{samples[int(np.argmin(distance))].tolist()} lies within it")


def validate_tools(s: Scene) -> None:
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
    if t.shape == "cad":
        flat, corner = _validate_cad_tools(t), t.holder_corner_radius
        _validate_punch_travel(s, t)
    else:
        flat, corner = _validate_analytic_tools(s, t), t.die_corner_radius + t.die_profile_radius
    g = s.geometry
    what = "holder_half_width" if t.shape == "cad" else "die_half_width + die_profile_radius"
    if g.shape == "rectangle":
        side = "lx" if g.lx <= g.ly else "ly"
        require(min(g.lx, g.ly) / 2 > flat, f"geometry.{side}",
                f"the blank does not reach the blank holder and the die's flat top: half its size "
                f"{getattr(g, side) / 2} must exceed {what} = {flat}")
    elif g.shape == "circle":
        require(g.radius > flat, "geometry.radius",
                f"the blank does not reach the blank holder and the die's flat top: its radius {g.radius} "
                f"must exceed {what} = {flat}")
    require(t.friction > 0 or "friction" not in s.effects, "tools.friction", "the effect 'friction' needs friction > 0")
    require(bool(t.drawbead) or "drawbeads" not in s.effects, "tools.drawbead",
            "the effect 'drawbeads' needs at least one [[tools.drawbead]]")
    for i, bead in enumerate(t.drawbead):
        _validate_drawbead(bead, f"tools.drawbead[{i}]", flat, corner)
    if g.shape == "rectangle":
        outer = ("right", "top") if g.region == "quarter" else SIDES
    else:  # an outline's edges are free or symmetry lines
        outer = tuple(k for k, v in s.supports.items() if v != "symmetry")
    for side in outer:
        v = s.supports.get(side, "free")
        require(v == "free", f"supports.{side}",
                f"the tools hold the blank: its outer edges must be 'free', got {v!r}")


def _validate_holder(s: Scene, t) -> None:
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


def _validate_analytic_tools(s: Scene, t) -> float:
    """Square and round tools' dimensions; returns the half-width where the die's flat top
    (and the holder) begins."""
    if t.shape == "round":
        for name in ("punch_radius", "die_radius"):
            require(getattr(t, name) > 0, f"tools.{name}", f"round tools need {name} > 0, got {getattr(t, name)}")
    else:
        for name in ("punch_radius", "die_radius"):
            require(getattr(t, name) == 0, f"tools.{name}", "is a key of shape = 'round' (square tools: "
                    "punch_half_width, punch_corner_radius, die_half_width, die_corner_radius)")
    for f in fields(ToolsSpec):
        v = getattr(t, f.name)
        if f.name not in ("holder_spread", "holder", "shape", "drawbead", *CAD_TOOL_KEYS):
            require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{f.name}", f"must be finite, got {v}")
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
    return t.die_half_width + t.die_profile_radius


def _validate_punch_travel(s: Scene, t) -> None:
    """A punch travelling aslant keeps the blank's mirror symmetry only within the mirror planes:
    along x = 0 (the `left` edge) no x component, along y = 0 (`bottom`) no y component
    (outline.MIRROR_NORMALS), along any other symmetry line none in the plane."""
    d = np.asarray(t.punch_direction, dtype=float)
    for group, support in s.supports.items():
        if support != "symmetry":
            continue
        across = np.array([MIRROR_NORMALS[group]] if group in MIRROR_NORMALS else list(MIRROR_NORMALS.values()))
        require(not np.any(across @ d), "tools.punch_direction",
                f"{t.punch_direction} leaves the mirror plane of the symmetry line {group!r}: a punch travelling "
                "aslant needs the blank modelled without that symmetry")


def _validate_cad_tools(t) -> float:
    """CAD tools: their files exist (what they hold is checked when they are read:
    shellform.contact.surface_tool), their placements and the holder's inner edge; returns
    holder_half_width."""
    for name in ("punch_file", "die_file"):
        v = getattr(t, name)
        require(bool(v), f"tools.{name}",
                "shape = 'cad' needs the tool's STEP, IGES or BREP file (or .stl, .msh surface mesh)")
        require(Path(v).is_file(), f"tools.{name}", f"no such file: {v}")
    for name, what in (("punch_translation", "[x, y, z] (mm)"), ("die_translation", "[x, y, z] (mm)"),
                       ("punch_rotation", "angles about x, y, z (degrees)"),
                       ("die_rotation", "angles about x, y, z (degrees)"), ("punch_direction", "[x, y, z]")):
        v = getattr(t, name)
        require(len(v) == 3 and all(isinstance(c, (int, float)) and math.isfinite(c) for c in v), f"tools.{name}",
                f"must be three finite numbers {what}, got {v}")
    d = np.asarray(t.punch_direction, dtype=float)
    require(np.linalg.norm(d) > 0, "tools.punch_direction", "must be a non-zero vector, the way the punch travels")
    require(d[2] < 0, "tools.punch_direction", f"must point down into the die (a negative z component): the punch "
                                               f"draws the sheet into the die below it, got {t.punch_direction}")
    for name in ("punch_normals", "die_normals"):
        require(getattr(t, name) in TOOL_NORMALS, f"tools.{name}",
                f"must be one of {TOOL_NORMALS}, got {getattr(t, name)!r}")
    require(math.isfinite(t.holder_half_width) and t.holder_half_width >= 0, "tools.holder_half_width",
            f"must be >= 0: the holder's inner edge (where the die's flat top begins), 0 for the die's own, got "
            f"{t.holder_half_width}")
    require(math.isfinite(t.holder_corner_radius) and 0 <= t.holder_corner_radius <= t.holder_half_width,
            "tools.holder_corner_radius", f"must lie in [0, holder_half_width], got {t.holder_corner_radius}")
    return t.holder_half_width
