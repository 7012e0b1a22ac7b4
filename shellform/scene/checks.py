"""The checks of a scene's values across fields, run when a Scene is read (``validate``, from shellform.scene.read): every
bad value raises shellform.errors.InputError naming its field, e.g.
``material.thickness: must be > 0, got -1.0``, before any computation. The effects are checked
by their registry (shellform.effects.check), what depends on the machine (files, memory) by
shellform.scene.machine, the [tools] table by shellform.scene.tool_checks.
"""

import math
from dataclasses import fields
from pathlib import Path

import numpy as np

from shellform import effects as registry
from shellform.errors import InputError
from shellform.material.criteria import CRITERIA
from shellform.mesh import outline
from shellform.scene import machine
from shellform.scene.rules import keys_of_effects, require, sheet_effects
from shellform.scene.tool_checks import validate_tools
from shellform.scene.schema import (ANISOTROPY_LISTS, ANISOTROPY_PARAMETERS, CIRCLE_REGIONS, CURVE_PARAMETERS,
                                    DIAGONALS, DRAWBEAD_PARAMETER, FRICTION_KEYS, FRICTION_TOOLS, HARDENING, LOAD_STEP_KEYS,
                                    MAY_BE_INFINITE, STROKE_STEP_KEYS, YIELD_FUNCTIONS, YIELD_PARAMETERS, MESH_KINDS,
                                    MIRROR_SUPPORTS, NONLINEAR_SUPPORTS, PRESSURE_PER, REGIONS, SIDES, SUPPORTS, bounds)


MAX_THICKNESS_POINTS = 1000  # process.thickness_points: numpy's Gauss rule of n points takes O(n^3)
# process.report: each station stops the stepping there and writes the fields of the whole
# sheet (a step of the .pvd and VTX series; a tool scene also its checkpoint and reports.json)
MAX_REPORTS = 200


def validate(s) -> None:
    """Raise InputError naming the first bad field of s."""
    _validate_finite(s)
    registry.check(s.effects)
    _validate_geometry(s)
    m = s.mesh
    for name in ("R1", "R2"):
        v = getattr(s.surface, name)
        require(v != 0 and not math.isnan(v), f"surface.{name}", f"must be non-zero (inf for flat), got {v}")
    keys_of_effects(s, "surface")
    for name in ("R1", "R2"):
        if math.isfinite(getattr(s.surface, name)):
            require(not s.surface.z0, f"surface.{name}", "give either z0 or the radii R1, R2, not both")
    if s.surface.z0:
        from shellform.forms.reference_surface import ReferenceSurface

        _check_plan_field(ReferenceSurface(s.surface.z0), s, "tool scenes draw a flat blank")
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
                f"nonlinear sheet: needs one of the effects {', '.join(sheet_effects())}")
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
    _validate_sensitivities(s)
    validate_tools(s)
    machine.check_size(s)  # first: a count too large for memory is named with the memory it needs
    _plausible_values(s)
    n = s.process.thickness_points
    require(n <= MAX_THICKNESS_POINTS, "process.thickness_points",
            f"must be <= {MAX_THICKNESS_POINTS} (the Gauss rule costs n^3: 10,000 points take minutes before "
            f"anything is solved), got {n}")


def _validate_finite(s) -> None:
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


def _validate_geometry(s) -> None:
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


def _validate_material(s) -> None:
    mat = s.material
    require(math.isfinite(mat.E) and mat.E > 0, "material.E", f"must be > 0, got {mat.E}")
    require(-1.0 < mat.nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {mat.nu}")
    require(math.isfinite(mat.thickness) and mat.thickness > 0, "material.thickness",
            f"must be > 0, got {mat.thickness}")
    require(math.isfinite(mat.r) and mat.r > 0, "material.r", f"must be > 0, got {mat.r}")
    require(math.isfinite(mat.m) and mat.m >= 1, "material.m",
            f"must be >= 1 (convex yield function), got {mat.m}")
    keys_of_effects(s, "material")
    require(mat.yield_function in YIELD_FUNCTIONS, "material.yield_function",
            f"must be one of {', '.join(YIELD_FUNCTIONS)}, got {mat.yield_function!r}")
    require(math.isfinite(mat.rolling_direction), "material.rolling_direction",
            f"must be finite (degrees), got {mat.rolling_direction}")
    for name in ANISOTROPY_PARAMETERS + ANISOTROPY_LISTS:
        v = getattr(mat, name)
        if name in ANISOTROPY_PARAMETERS:
            require(math.isfinite(v) and v >= 0.0, f"material.{name}", f"must be > 0 (0: unset), got {v}")
        require(not v or name in YIELD_PARAMETERS[mat.yield_function], f"material.{name}",
                f"is no parameter of yield_function = {mat.yield_function!r} "
                f"(its parameters: {', '.join(YIELD_PARAMETERS[mat.yield_function])})")
    check_keys = getattr(CRITERIA[mat.yield_function], "check", None)
    if check_keys is not None:
        # the criterion checks its own keys (a fit's data: lists of one length, angles in [0, 90],
        # positive r and stresses), here before the material's fit runs
        check_keys({**{k: getattr(mat, k) for k in ANISOTROPY_PARAMETERS if getattr(mat, k) != 0.0},
                    **{k: list(getattr(mat, k)) for k in ANISOTROPY_LISTS if getattr(mat, k)}})
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
    if s.process.stop_at_forming_limit:
        require(s.tools is not None and plastic, "process.stop_at_forming_limit",
                "ends a tool scene's stroke at the forming-limit curve: it needs the effects contact and plasticity")
    if s.process.stop_at_neck:
        require(s.nonlinear and plastic, "process.stop_at_neck",
                "ends a nonlinear scene's stroke or load path where the sheet starts to neck: it needs the effects "
                "geometric_nonlinearity and plasticity")
    limits_view = s.tools is not None and (s.output.fld or s.process.stop_at_forming_limit)
    if plastic and (mat.forming_limit_curve or limits_view):
        from shellform.results import fld

        fld.curves(mat)  # reads a measured curve; without one, Keeler-Brazier needs a Swift or power-law n


def _validate_sensitivities(s) -> None:
    """[output] sensitivities: a nonlinear scene's, each a number the sheet depends on (a tool
    scene's: of its parts that have derivatives, rigid tools, friction and a force-controlled
    holder: docs/sensitivity.md, Tool scenes); scatter: one standard deviation >= 0 each."""
    names, scatter = s.output.sensitivities, s.output.scatter
    if not names:
        require(not scatter, "output.scatter", "needs output.sensitivities (a standard deviation per parameter)")
        return
    require(s.nonlinear, "output.sensitivities", "a scene reports sensitivities of a nonlinear sheet")
    if s.tools is not None:
        _validate_tool_sensitivities(s)
    numbers = {f.name for f in fields(s.material) if f.type is float and f.name != "thickness"}
    base = s.hill79().pack()
    require(len(set(names)) == len(names), "output.sensitivities", "names a parameter twice")
    for name in names:
        field_ = f"output.sensitivities ({name})"
        section, _, key = name.partition(".")
        if name in ("material.thickness", "loads.pressure"):
            require(name != "loads.pressure" or s.loads.pressure != 0, field_, "needs a pressure other than 0")
            continue
        if name == "tools.blank_holder_force" and s.tools is not None:
            require(s.tools.holder != "gap" and s.tools.blank_holder_force > 0, field_,
                    "needs a holder pressing with a force > 0 (not one held at a gap)")
            continue
        bead = DRAWBEAD_PARAMETER.fullmatch(name)
        if bead is not None and s.tools is not None:
            index = int(bead.group(1))
            require("drawbeads" in s.effects and index < len(s.tools.drawbead), field_,
                    f"needs the effect 'drawbeads' and a [[tools.drawbead]] number {index} (counted from 0; the "
                    f"scene has {len(s.tools.drawbead)})")
            require(getattr(s.tools.drawbead[index], bead.group(2)) > 0, field_, "needs that force > 0")
            continue
        if section == "tools" and s.tools is not None and key in FRICTION_KEYS:
            value = getattr(s.tools, key)
            require("friction" in s.effects and value is not None and value > 0, field_,
                    "needs the effect 'friction' and that coefficient set > 0 (a tool's own where it is given)")
            own = [getattr(s.tools, f"{t}_friction") for t in FRICTION_TOOLS]
            require(key != "friction" or None in own, field_,
                    "every tool has its own coefficient: tools.friction is none of theirs")
            continue
        require(section == "material" and key in numbers, field_,
                "must be material.<a number of [material]>, material.thickness or loads.pressure (a tool scene: "
                "tools.friction, a tool's own coefficient, tools.blank_holder_force or tools.drawbead[i].restraint "
                "and .uplift too)")
        value = getattr(s.material, key)
        require(not np.array_equal(s.with_material(key, value * (1 + 1e-3) if value else 1e-3).hill79().pack(),
                                   base), field_,
                f"the sheet does not depend on material.{key} (its hardening and yield function do not use it)")
    require(not scatter or len(scatter) == len(names), "output.scatter",
            f"needs one standard deviation per parameter of output.sensitivities ({len(names)}), got {len(scatter)}")
    for i, sd in enumerate(scatter):
        require(math.isfinite(sd) and sd >= 0, f"output.scatter[{i}]", f"must be finite and >= 0, got {sd}")


def _validate_tool_sensitivities(s) -> None:
    """A tool scene's sensitivities: its rigid tools, its holder, friction, drawbeads and ironing
    have derivatives, with finite strains (the nodes' thickness), and no parameter that moves the
    tools."""
    require("finite_strain" in s.effects, "effects",
            "a tool scene's output.sensitivities need the effect 'finite_strain' (the nodes' thickness)")
    for name in s.output.sensitivities:
        require(name not in ("material.thickness", "loads.pressure"), f"output.sensitivities ({name})",
                "moves the tools or loads no tool scene: a tool scene takes material.<number>, tools.friction, "
                "a tool's own coefficient or tools.blank_holder_force")


def _validate_probes(s) -> None:
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


# tools.friction (or a tool's own) above this is warned about: sheet metal on tools lies about 0.02 to 0.3
MAX_FRICTION = 1.0


def _warn(field: str, message: str) -> None:
    import warnings

    warnings.warn(PlausibilityWarning(f"{field}: {message}"), stacklevel=3)


def _plausible_values(s) -> None:
    """Warn (PlausibilityWarning, naming the field) about values that are valid but make a run
    that computes nothing of use with exit 0: one cell per side (mesh.n = 1 but for a file
    blank, whose own mesh n refines), a friction coefficient above MAX_FRICTION (friction, or a
    tool's own), a punch whose gap to the sheet is at least its stroke (it never touches the
    sheet: zero force), a drawbead wholly outside the blank (mirrored across its symmetry lines:
    it holds nothing)."""
    if s.mesh.n == 1 and s.geometry.shape != "file":  # a file's n refines its own mesh
        _warn("mesh.n", "n = 1 makes one cell per side: no answer of such a mesh means anything (a cup needs n "
              ">= 8)")
    t = s.tools
    if t is None:
        return
    for key in ("friction", *(f"{name}_friction" for name in FRICTION_TOOLS)):
        v = getattr(t, key)
        if v is not None and v > MAX_FRICTION:
            _warn(f"tools.{key}", f"{v:g} is no friction coefficient of sheet metal on tools (about 0.02 to "
                  "0.3): is it a percentage?")
    if t.shape in ("square", "round") and t.punch_gap >= t.stroke:
        _warn("tools.punch_gap", f"the punch starts {t.punch_gap:g} mm above the sheet and travels {t.stroke:g} mm "
              "(tools.stroke): it never touches the sheet, and the force stays zero")
    g = s.geometry
    if g.shape not in ("rectangle", "circle"):
        return
    for i, bead in enumerate(t.drawbead):
        p = np.abs(np.asarray(bead.points, dtype=float))  # the blank mirrored: |x|, |y|
        along = np.linspace(0.0, 1.0, 21)[:, None, None]
        q = (p[:-1] + along * (p[1:] - p[:-1])).reshape(-1, 2)
        inside = (np.hypot(q[:, 0], q[:, 1]) <= g.radius if g.shape == "circle"
                  else (q[:, 0] <= g.lx / 2) & (q[:, 1] <= g.ly / 2))
        if not inside.any():
            _warn(f"tools.drawbead[{i}]", f"lies wholly outside the blank {bead.points}: it holds nothing")


def _check_plan_field(f, s, no_tools: str, key: str | None = None) -> None:
    """A field's text (forms.plan_field) is an expression of x and y, finite at a sample point,
    and the scene draws no tools (`no_tools` says why); errors name `key` (default f.FIELD)."""
    key = key or f.FIELD
    problem = f.problem()
    require(problem is None, key, f"{f.quoted()}: {problem}")
    require(s.tools is None, key, no_tools)
    try:
        value = f.value(0.123, 0.456)
    except (ArithmeticError, ValueError) as err:
        raise InputError(key, f"{f.quoted()} cannot be evaluated: {err}") from None
    require(math.isfinite(value), key, f"{f.quoted()} is not finite at (0.123, 0.456)")


def _validate_loads(s) -> None:
    g, loads = s.geometry, s.loads
    require(math.isfinite(loads.pressure), "loads.pressure", "must be finite")
    require(loads.pressure_per in PRESSURE_PER, "loads.pressure_per",
            f"must be one of {', '.join(map(repr, PRESSURE_PER))}, got {loads.pressure_per!r}")
    if loads.pressure_shape:
        from shellform.forms.plan_field import PlanField

        _check_plan_field(PlanField(loads.pressure_shape), s, "tool scenes take no pressure", "loads.pressure_shape")
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
                f"need one of the effects {', '.join(sheet_effects())}")
        require(g.shape == "rectangle", f"loads.moment[{i}]", "edge moments act on the sides of a rectangle")


def _validate_process(s) -> None:
    """Checked in every scene, though only nonlinear scenes step through a load path."""
    pr = s.process
    low = 2 if "plasticity" in s.effects else 1
    require(pr.thickness_points >= low, "process.thickness_points",
            f"must be >= {low}{' with plasticity' if low == 2 else ''}, got {pr.thickness_points}")
    first, least, most = STROKE_STEP_KEYS if s.tools is not None else LOAD_STEP_KEYS
    steps = {name: getattr(pr, name) for name in (least, first, most)}
    for name, v in steps.items():
        require(math.isfinite(v) and v > 0, f"process.{name}", f"must be > 0, got {v}")
    require(steps[least] <= steps[first], f"process.{least}",
            f"must be <= {first} ({steps[first]}), got {steps[least]}")
    require(steps[first] <= steps[most], f"process.{first}", f"must be <= {most} ({steps[most]}), got {steps[first]}")
    require(s.tools is not None or steps[most] <= 1, f"process.{most}", f"must be <= 1, got {steps[most]}")
    require(pr.max_iterations >= 1, "process.max_iterations", f"must be >= 1, got {pr.max_iterations}")
    require(math.isfinite(pr.rtol) and pr.rtol > 0, "process.rtol", f"must be > 0, got {pr.rtol}")
    require(len(pr.path) > 0, "process.path", "must list at least one load factor, e.g. [1.0]")
    require(all(math.isfinite(v) for v in pr.path), "process.path", f"must be finite numbers, got {pr.path}")
    lo, hi = min(0.0, *pr.path), max(0.0, *pr.path)  # the path starts at load factor 0
    require(len(pr.report) <= MAX_REPORTS, "process.report",
            f"lists {len(pr.report):,} stations; at most {MAX_REPORTS} (each writes the whole sheet's fields: "
            "the force and the draw-in are recorded at every increment anyway)")
    for v in pr.report:
        require(math.isfinite(v) and lo <= v <= hi, "process.report",
                f"{v} lies outside the load factors [{lo}, {hi}] that process.path covers")
