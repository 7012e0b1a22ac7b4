"""The checks of a scene's values across fields, run when a Scene is made (``validate``): every
bad value raises shellform.errors.InputError naming its field, e.g.
``material.thickness: must be > 0, got -1.0``, before any computation. The effects are checked
by their registry (shellform.effects.check), what depends on the machine (files, memory) by
shellform.scene.machine.
"""

import math
from dataclasses import fields
from pathlib import Path

import numpy as np

from shellform import effects as registry
from shellform.errors import InputError
from shellform.mesh import outline
from shellform.scene import machine
from shellform.scene.schema import (ANISOTROPY_PARAMETERS, CIRCLE_REGIONS, CURVE_PARAMETERS, DIAGONALS, HARDENING,
                                    MAY_BE_INFINITE, YIELD_FUNCTIONS, YIELD_PARAMETERS,
                                    MESH_KINDS, MIRROR_SUPPORTS, NONLINEAR_SUPPORTS, REGIONS, SIDES, SPREADS,
                                    SUPPORTS, TOOL_NORMALS, TOOL_SHAPES, CAD_TOOL_KEYS, Scene, ToolsSpec, bounds)


MAX_THICKNESS_POINTS = 1000  # process.thickness_points: numpy's Gauss rule of n points takes O(n^3)

def _sheet_effects() -> tuple[str, ...]:
    """The effects that select the nonlinear sheet."""
    return tuple(n for n, e in registry.EFFECTS.items() if e.route == registry.SHEET)


def _keys_of_effects(s: Scene, section: str) -> None:
    """The keys of `section` that take a meaning only with an effect (shellform.effects, Effect.keys)
    keep their defaults unless that effect is on. (A whole table, as [tools] of 'contact', is
    checked with its table.)"""
    for e in registry.EFFECTS.values():
        for key in e.keys:
            table, _, name = key.partition(".")
            if e.name in s.effects or table != section or not name or getattr(s, table) is None:
                continue
            value, default = getattr(getattr(s, table), name), getattr(type(getattr(s, table))(), name)
            require(value == default, key, f"{value!r} takes a meaning only with the effect {e.name!r}: switch it "
                    f"on, or leave the default {default!r}")


def require(cond, name, message):
    """Raise InputError(name, message) unless cond."""
    if not cond:
        raise InputError(name, message)


def validate(s: Scene) -> None:
    """Raise InputError naming the first bad field of s."""
    _validate_finite(s)
    registry.check(s.effects)
    _validate_geometry(s)
    m = s.mesh
    for name in ("R1", "R2"):
        v = getattr(s.surface, name)
        require(v != 0 and not math.isnan(v), f"surface.{name}", f"must be non-zero (inf for flat), got {v}")
    _keys_of_effects(s, "surface")
    for name in ("R1", "R2"):
        if math.isfinite(getattr(s.surface, name)):
            require(not s.surface.z0, f"surface.{name}", "give either z0 or the radii R1, R2, not both")
    if s.surface.z0:
        from shellform.forms.reference_surface import ReferenceSurface

        surface = ReferenceSurface(s.surface.z0)
        problem = surface.problem()
        require(problem is None, "surface.z0", f"{surface.quoted()}: {problem}")
        require(s.tools is None, "surface.z0", "tool scenes draw a flat blank")
        try:
            value = surface.value(0.123, 0.456)
        except (ArithmeticError, ValueError) as err:
            raise InputError("surface.z0", f"{surface.quoted()} cannot be evaluated: {err}") from None
        require(math.isfinite(value), "surface.z0", f"{surface.quoted()} is not finite at (0.123, 0.456)")
    require(m.kind in MESH_KINDS, "mesh.kind", f"must be one of {MESH_KINDS}, got {m.kind!r}")
    require(m.n >= 1, "mesh.n", f"must be >= 1, got {m.n}")
    require(m.refine >= 0, "mesh.refine", f"must be >= 0, got {m.refine}")
    require(m.diagonal in DIAGONALS, "mesh.diagonal", f"must be one of {DIAGONALS}, got {m.diagonal!r}")
    _validate_material(s)
    groups = outline.group_names(s.geometry)
    for group, v in s.supports.items():
        require(group in groups, f"supports.{group}",
                f"the blank has no boundary group {group!r}; its groups: {', '.join(groups)}")
        require(v in SUPPORTS, f"supports.{group}", f"unknown support {v!r}; known supports: {', '.join(SUPPORTS)}")
        require(v not in NONLINEAR_SUPPORTS or s.nonlinear, f"supports.{group}", f"{v!r} is a support of the "
                f"nonlinear sheet: needs one of the effects {', '.join(_sheet_effects())}")
    for group in outline.symmetry_lines(s.geometry):
        v = s.supports.get(group, "free")
        require(v in MIRROR_SUPPORTS, f"supports.{group}",
                f"the {s.geometry.region} {s.geometry.shape} is mirrored across this edge to make the whole blank: "
                f"it needs 'symmetry' (or {' or '.join(repr(m) for m in MIRROR_SUPPORTS[1:])}), got {v!r}")
    _validate_loads(s)
    _validate_process(s)
    every = s.output.checkpoint_every
    require(math.isfinite(every) and every >= 0, "output.checkpoint_every", f"must be finite and >= 0, got {every}")
    _validate_probes(s)
    _validate_tools(s)
    machine.check_size(s)  # first: a count too large for memory is named with the memory it needs
    n = s.process.thickness_points
    require(n <= MAX_THICKNESS_POINTS, "process.thickness_points",
            f"must be <= {MAX_THICKNESS_POINTS} (the Gauss rule costs n^3: 10,000 points take minutes before "
            f"anything is solved), got {n}")


def _validate_finite(s: Scene) -> None:
    """Every number of the scene is finite (surface.R1 and R2 may be inf: flat)."""
    def numbers(value, name):
        if isinstance(value, list):
            for i, item in enumerate(value):
                yield from numbers(item, f"{name}[{i}]" if hasattr(item, "__dataclass_fields__") else name)
        elif hasattr(value, "__dataclass_fields__"):
            for f in fields(value):
                yield from numbers(getattr(value, f.name), f"{name}.{f.name}")
        elif isinstance(value, float):
            yield name, value

    for section in ("geometry", "surface", "mesh", "material", "loads", "process", "tools"):
        for name, v in numbers(getattr(s, section), section):
            if name in MAY_BE_INFINITE:
                require(not math.isnan(v), name, f"must be a number (inf: flat), got {v}")
            else:
                require(math.isfinite(v), name, f"must be finite, got {v}")


def _validate_geometry(s: Scene) -> None:
    g, m = s.geometry, s.mesh
    require(g.shape in outline.SHAPES, "geometry.shape", f"must be one of {outline.SHAPES}, got {g.shape!r}")
    own = {"rectangle": (), "circle": ("radius",), "polygon": ("vertices", "edges"), "file": ("file",)}
    for shape, keys in own.items():
        for key in keys:
            require(shape == g.shape or not getattr(g, key), f"geometry.{key}",
                    f"is a key of shape = {shape!r}, but the shape is {g.shape!r}")
    if g.shape == "rectangle":
        for name in ("lx", "ly"):
            v = getattr(g, name)
            require(math.isfinite(v) and v > 0, f"geometry.{name}", f"must be > 0, got {v}")
        require(g.region in REGIONS, "geometry.region", f"rectangle: must be one of {REGIONS}, got {g.region!r}")
        return
    require(m.kind == "unstructured", "mesh.kind",
            f"a {g.shape} blank is meshed by gmsh: set kind = 'unstructured', got {m.kind!r}")
    if g.shape == "circle":
        require(math.isfinite(g.radius) and g.radius > 0, "geometry.radius", f"must be > 0, got {g.radius}")
        require(g.region in CIRCLE_REGIONS, "geometry.region",
                f"circle: must be one of {CIRCLE_REGIONS}, got {g.region!r}")
        return
    require(g.region == "full", "geometry.region",
            f"a {g.shape} blank is the region meshed: name its symmetry lines in [supports] instead")
    if g.shape == "polygon":
        require(all(math.isfinite(c) for p in g.vertices for c in p), "geometry.vertices", "must be finite")
        problem = outline.polygon_problem(g.vertices)
        require(problem is None, "geometry.vertices", str(problem))
        require(not g.edges or len(g.edges) == len(g.vertices), "geometry.edges",
                f"needs one name per edge ({len(g.vertices)}), got {len(g.edges)}")
        return
    path = Path(g.file)
    require(bool(g.file), "geometry.file", "shape = 'file' needs a file name")
    require(path.suffix.lower() in outline.FILE_SUFFIXES, "geometry.file",
            f"must be a gmsh file ({', '.join(outline.FILE_SUFFIXES)}), got {g.file!r}")
    machine.check_file(s)


def _validate_material(s: Scene) -> None:
    mat = s.material
    require(math.isfinite(mat.E) and mat.E > 0, "material.E", f"must be > 0, got {mat.E}")
    require(-1.0 < mat.nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {mat.nu}")
    require(math.isfinite(mat.thickness) and mat.thickness > 0, "material.thickness",
            f"must be > 0, got {mat.thickness}")
    require(math.isfinite(mat.r) and mat.r > 0, "material.r", f"must be > 0, got {mat.r}")
    require(math.isfinite(mat.m) and mat.m >= 1, "material.m",
            f"must be >= 1 (convex yield function), got {mat.m}")
    _keys_of_effects(s, "material")
    require(mat.yield_function in YIELD_FUNCTIONS, "material.yield_function",
            f"must be one of {', '.join(YIELD_FUNCTIONS)}, got {mat.yield_function!r}")
    require(math.isfinite(mat.rolling_direction), "material.rolling_direction",
            f"must be finite (degrees), got {mat.rolling_direction}")
    for name in ANISOTROPY_PARAMETERS + ("alpha",):
        v = getattr(mat, name)
        if name != "alpha":
            require(math.isfinite(v) and v >= 0.0, f"material.{name}", f"must be > 0 (0: unset), got {v}")
        require(not v or name in YIELD_PARAMETERS[mat.yield_function], f"material.{name}",
                f"is no parameter of yield_function = {mat.yield_function!r} "
                f"(its parameters: {', '.join(YIELD_PARAMETERS[mat.yield_function])})")
    for name, default in (("r", 1.0), ("m", 2.0)):
        require(mat.yield_function == "hill79" or getattr(mat, name) == default, f"material.{name}",
                f"is Hill 1979's; yield_function = {mat.yield_function!r} takes its own parameters")
    require(mat.hardening in HARDENING, "material.hardening",
            f"must be one of {', '.join(HARDENING)}, got {mat.hardening!r}")
    plastic = "plasticity" in s.effects
    if plastic and mat.hardening == "none":
        raise InputError("material.hardening",
                         "plasticity needs a hardening curve: " + ", ".join(
                             f"'{k}' ({', '.join(v)})" for k, v in CURVE_PARAMETERS.items() if v))
    for name in ("yield_stress", "n", "K", "eps0", "Q", "beta", "swift_weight", "flow_curve", "extrapolation"):
        v = getattr(mat, name)
        require(isinstance(v, str) or math.isfinite(v), f"material.{name}", f"must be finite, got {v}")
        if v != 0.0 and v != "":
            require(name in CURVE_PARAMETERS[mat.hardening], f"material.{name}",
                    f"is no parameter of hardening = {mat.hardening!r} "
                    f"(its parameters: {', '.join(CURVE_PARAMETERS[mat.hardening])})")
    if plastic:
        _plausible_stiffness(s.hill79())  # SheetMaterial validates the curve and names the field
    if plastic and (mat.forming_limit_curve or (s.tools is not None and s.output.fld)):
        from shellform.results import fld

        fld.curves(mat)  # reads a measured curve; without one, Keeler-Brazier needs a Swift or power-law n


def _validate_probes(s: Scene) -> None:
    """Probes: a nonlinear sheet scene's, each named once, at finite coordinates within the blank's
    bounds (that a vertex lies there is checked on the mesh, before stepping)."""
    names = set()
    for i, probe in enumerate(s.output.probe):
        field_ = f"output.probe[{i}]"
        require(s.nonlinear and s.tools is None, field_, "probes are reported by nonlinear sheet scenes (the "
                "tool scenes report draw-in, force and thinning)")
        require(isinstance(probe.name, str) and probe.name.strip() != "", f"{field_}.name", "must be a non-empty name")
        require(probe.name not in names, f"{field_}.name", f"{probe.name!r} names another probe too")
        names.add(probe.name)
        for c in ("x", "y"):
            require(isinstance(getattr(probe, c), (int, float)) and math.isfinite(getattr(probe, c)),
                    f"{field_}.{c}", f"must be a finite number, got {getattr(probe, c)!r}")
        if s.geometry.shape != "file":
            x0, x1, y0, y1 = bounds(s)
            tol = 1e-9 * max(x1 - x0, y1 - y0)
            require(x0 - tol <= probe.x <= x1 + tol and y0 - tol <= probe.y <= y1 + tol, field_,
                    f"({probe.x}, {probe.y}) lies outside the blank's bounds x in [{x0}, {x1}], y in [{y0}, {y1}]")


E_OVER_YIELD = (100.0, 5000.0)  # E / initial yield stress of a sheet metal: about 300 (aluminium) to 2000


class PlausibilityWarning(UserWarning):
    """A value that is valid but unlikely for a sheet metal (a unit mixed up)."""


def _plausible_stiffness(material) -> None:
    """Warn, naming material.E, where E over the initial yield stress lies outside E_OVER_YIELD:
    E in GPa with the stresses in MPa (E = 206 for a steel) gives about 1, not 1000."""
    import warnings

    from shellform.material.hardening import flow_stress

    ratio = material.E / flow_stress(0.0, material.pack())[0]
    if not E_OVER_YIELD[0] <= ratio <= E_OVER_YIELD[1]:
        warnings.warn(PlausibilityWarning(
            f"material.E: E / initial yield stress = {ratio:.3g}, where a sheet metal's lies between about 300 and "
            f"2000: are E and the stresses in the same unit (MPa with lengths in mm)?"), stacklevel=2)


def _validate_loads(s: Scene) -> None:
    g, loads = s.geometry, s.loads
    require(math.isfinite(loads.pressure), "loads.pressure", "must be finite")
    for i, p in enumerate(loads.point):
        for name in ("x", "y", "fx", "fy", "fz"):
            require(math.isfinite(getattr(p, name)), f"loads.point[{i}].{name}", "must be finite")
    needs_w = loads.pressure != 0 or any(p.fz != 0 for p in loads.point)
    require(not needs_w or "bending" in s.effects, "loads", "transverse loads need the effect 'bending'")
    box = bounds(s) if g.shape != "file" else None
    for i, p in enumerate(loads.point):
        if box is not None:
            x0, x1, y0, y1 = box
            tol = 1e-12 * max(x1 - x0, y1 - y0)
            require(x0 - tol <= p.x <= x1 + tol and y0 - tol <= p.y <= y1 + tol, f"loads.point[{i}]",
                    f"({p.x}, {p.y}) lies outside the blank [{x0}, {x1}] x [{y0}, {y1}]")
        require((p.fx == 0 and p.fy == 0) or "membrane" in s.effects, f"loads.point[{i}]",
                "in-plane forces (fx, fy) need the effect 'membrane'")
    for i, mo in enumerate(loads.moment):
        require(mo.side in SIDES, f"loads.moment[{i}].side", f"must be one of {', '.join(SIDES)}, got {mo.side!r}")
        require(math.isfinite(mo.m), f"loads.moment[{i}].m", f"must be finite, got {mo.m}")
        require(s.nonlinear, f"loads.moment[{i}]", "edge moments are loads of the nonlinear sheet: "
                f"need one of the effects {', '.join(_sheet_effects())}")
        require(g.shape == "rectangle", f"loads.moment[{i}]", "edge moments act on the sides of a rectangle")


def _validate_process(s: Scene) -> None:
    """Checked in every scene, though only nonlinear scenes step through a load path."""
    pr = s.process
    low = 2 if "plasticity" in s.effects else 1
    require(pr.thickness_points >= low, "process.thickness_points",
            f"must be >= {low}{' with plasticity' if low == 2 else ''}, got {pr.thickness_points}")
    for name in ("min_step", "initial_step", "max_step"):
        v = getattr(pr, name)
        require(math.isfinite(v) and v > 0, f"process.{name}", f"must be > 0, got {v}")
    require(pr.min_step <= pr.initial_step, "process.min_step",
            f"must be <= initial_step ({pr.initial_step}), got {pr.min_step}")
    require(pr.initial_step <= pr.max_step, "process.initial_step",
            f"must be <= max_step ({pr.max_step}), got {pr.initial_step}")
    require(pr.max_step <= 1, "process.max_step", f"must be <= 1, got {pr.max_step}")
    require(pr.max_iterations >= 1, "process.max_iterations", f"must be >= 1, got {pr.max_iterations}")
    require(math.isfinite(pr.rtol) and pr.rtol > 0, "process.rtol", f"must be > 0, got {pr.rtol}")
    require(len(pr.path) > 0, "process.path", "must list at least one load factor, e.g. [1.0]")
    require(all(math.isfinite(v) for v in pr.path), "process.path", f"must be finite numbers, got {pr.path}")
    lo, hi = min(0.0, *pr.path), max(0.0, *pr.path)  # the path starts at load factor 0
    for v in pr.report:
        require(math.isfinite(v) and lo <= v <= hi, "process.report",
                f"{v} lies outside the load factors [{lo}, {hi}] that process.path covers")


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


def _validate_tools(s: Scene) -> None:
    """The [tools] table and the effects 'contact' and 'friction' (after the material: the
    clearance is checked against the thickness)."""
    t = s.tools
    if t is None:
        require("contact" not in s.effects, "tools", "the effect 'contact' needs a [tools] table")
        return
    require("contact" in s.effects, "effects", "a [tools] table needs the effect 'contact'")
    _keys_of_effects(s, "tools")
    require(t.shape in TOOL_SHAPES, "tools.shape", f"must be one of {TOOL_SHAPES}, got {t.shape!r}")
    require(t.holder_spread in SPREADS, "tools.holder_spread", f"must be one of {SPREADS}, got {t.holder_spread!r}")
    for name in ("blank_holder_force", "friction", "stroke"):
        v = getattr(t, name)
        require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{name}", f"must be finite, got {v}")
    require(t.stroke > 0, "tools.stroke", f"must be > 0, got {t.stroke}")
    for name in ("blank_holder_force", "friction"):
        require(getattr(t, name) >= 0, f"tools.{name}", f"must be >= 0, got {getattr(t, name)}")
    if t.shape == "cad":
        flat, corner = _validate_cad_tools(t), t.holder_corner_radius
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
        if f.name not in ("holder_spread", "shape", "drawbead", *CAD_TOOL_KEYS):
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


def _validate_cad_tools(t) -> float:
    """CAD tools: their files exist (what they hold is checked when they are read:
    shellform.contact.surface_tool), their placements and the holder's inner edge; returns
    holder_half_width."""
    for name in ("punch_file", "die_file"):
        v = getattr(t, name)
        require(bool(v), f"tools.{name}", "shape = 'cad' needs the tool's STEP, IGES or BREP file")
        require(Path(v).is_file(), f"tools.{name}", f"no such file: {v}")
    for name in ("punch_translation", "die_translation"):
        v = getattr(t, name)
        require(len(v) == 3 and all(math.isfinite(c) for c in v), f"tools.{name}",
                f"must be three finite numbers [x, y, z] (mm), got {v}")
    for name in ("punch_normals", "die_normals"):
        require(getattr(t, name) in TOOL_NORMALS, f"tools.{name}",
                f"must be one of {TOOL_NORMALS}, got {getattr(t, name)!r}")
    require(math.isfinite(t.holder_half_width) and t.holder_half_width > 0, "tools.holder_half_width",
            f"shape = 'cad' needs the holder's inner edge (where the die's flat top begins) > 0, got "
            f"{t.holder_half_width}")
    require(math.isfinite(t.holder_corner_radius) and 0 <= t.holder_corner_radius <= t.holder_half_width,
            "tools.holder_corner_radius", f"must lie in [0, holder_half_width], got {t.holder_corner_radius}")
    return t.holder_half_width
