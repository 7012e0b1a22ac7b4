"""A scene (``Scene``: the sections of shellform.scene.schema and the queries the solvers ask of
them) and its reading: TOML (``load``), a parsed TOML document (``from_dict``) and a changed
scene (``changed``: the scene as a document, ``to_dict``, with the changes applied, read again).
Each key's type is checked here against its default in the schema, naming the field; the values
are checked once the Scene is read (``from_dict`` runs shellform.scene.checks.validate), so a
Scene made here is a checked one.
"""

import copy
import json
import tomllib
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path

from shellform import effects as registry
from shellform.errors import InputError
from shellform.material import SheetMaterial
from shellform.scene.checks import validate
from shellform.scene.schema import (ANISOTROPY_LISTS, ANISOTROPY_PARAMETERS, LOAD_STEP_KEYS, STROKE_STEP_KEYS,
                                    TOOL_SHAPES, Drawbead, EdgeMoment, Geometry, Loads, Material, MeshSpec, Output,
                                    PointLoad, Probe, Process, Solver, Surface, ToolsSpec)
from shellform.tools import kinds as tool_kinds

@dataclass
class Scene:
    title: str = "shellform scene"
    effects: tuple[str, ...] = ("bending",)
    geometry: Geometry = field(default_factory=Geometry)
    surface: Surface = field(default_factory=Surface)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    material: Material = field(default_factory=Material)
    supports: dict[str, str] = field(default_factory=dict)  # boundary group -> support; unnamed: free
    loads: Loads = field(default_factory=Loads)
    solver: Solver = field(default_factory=Solver)
    process: Process = field(default_factory=Process)
    output: Output = field(default_factory=Output)
    tools: ToolsSpec | None = None  # None: no [tools] table, no tools

    def changed(self, changes: dict) -> "Scene":
        """A new scene with `changes` {"section.key": value, "effects": [...], ...} applied at once,
        read and checked as a scene file is: a bad value raises InputError naming its field.
        This scene is left as it is."""
        return changed(self, changes)

    def with_material(self, key: str, value: float) -> "Scene":
        """This scene with material.<key> = value, not checked again: a parameter moved by a
        small step (the sensitivities' differences, nonlinear/sensitivity.py)."""
        return replace(self, material=replace(self.material, **{key: value}))

    def largest_r(self) -> float:
        """The largest Lankford coefficient the material states (r of Hill 1979, r0, r45, r90,
        the fitted ones; 1 for an isotropic sheet): how much uniaxial tension thins it."""
        m = self.material
        given = [m.r0, m.r45, m.r90, *m.fit_r] if self.material.yield_function != "hill79" else [m.r]
        return max([v for v in given if v > 0] or [1.0])

    @property
    def kappa0(self) -> tuple[float, float]:
        return (1.0 / self.surface.R1, 1.0 / self.surface.R2)

    def curvature(self):
        """What the forms take as kappa0 with 'shallow_curvature': the ReferenceSurface of
        surface.z0, or the principal curvatures diag(1/R1, 1/R2) as an array; None if flat."""
        import numpy as np

        from shellform.forms.reference_surface import ReferenceSurface

        if "shallow_curvature" not in self.effects:
            return None
        if self.surface.z0:
            return ReferenceSurface(self.surface.z0)
        return np.diag(self.kappa0).astype(np.float64)

    def pressure_field(self):
        """How the pressure spreads (forms.loads.PressureField): its shape over the plan and, per
        unit surface area, the curved surface it is measured on; None for a uniform pressure per
        unit plan area (or on a flat sheet, where the two are the same)."""
        import numpy as np

        from shellform.forms.loads import PressureField
        from shellform.forms.reference_surface import ReferenceSurface

        surface = None
        if self.loads.pressure_per == "surface" and self.surface.z0:
            surface = ReferenceSurface(self.surface.z0)
        elif self.loads.pressure_per == "surface" and any(k != 0 for k in self.kappa0):
            surface = tuple(float(v) for v in np.diag(self.kappa0).ravel())
        if not self.loads.pressure_shape and surface is None:
            return None
        return PressureField(self.loads.pressure_shape, surface)

    @property
    def symmetry_copies(self) -> int:
        """How many copies of the meshed region make the whole blank (4 for a quarter)."""
        g = self.geometry
        if g.shape in ("rectangle", "circle"):
            return {"full": 1, "half": 2, "quarter": 4}[g.region]
        return 2 ** sum(v == "symmetry" for v in self.supports.values())

    @property
    def route(self) -> str:
        """The solver its effects select (shellform.effects.route): linear shell, nonlinear sheet or tools."""
        return registry.route(self.effects)

    @property
    def nonlinear(self) -> bool:
        """Whether its effects select the nonlinear sheet (alone or drawn by the tools)."""
        return self.route != registry.LINEAR

    def hill79(self):
        """The scene's shellform.material.SheetMaterial (its yield function, Hill 1979 by default):
        elastic (hardening "none") unless the effect 'plasticity' is on. Its own validation names
        the field (material.yield_stress, material.r0, ...)."""
        mat = self.material
        if "plasticity" not in self.effects:
            return SheetMaterial(mat.E, mat.nu, mat.r, mat.m)
        unset = lambda v: v if v != 0.0 else None  # noqa: E731  0.0: not given
        # n = 0 is a valid Swift exponent (perfect plasticity) but no power law (n > 1): unset there
        n = unset(mat.n) if mat.hardening == "power" else mat.n
        given = {k: getattr(mat, k) for k in ANISOTROPY_PARAMETERS if getattr(mat, k) != 0.0}
        given.update({k: list(getattr(mat, k)) for k in ANISOTROPY_LISTS if getattr(mat, k)})
        table = None
        if mat.hardening == "table" and mat.flow_curve:
            from shellform.material.flow_curve import read_csv

            table = read_csv(mat.flow_curve)
        return SheetMaterial(mat.E, mat.nu, mat.r, mat.m, mat.hardening, unset(mat.yield_stress), n,
                             unset(mat.K), unset(mat.eps0), mat.yield_function, given, mat.rolling_direction,
                             unset(mat.Q), unset(mat.beta), unset(mat.swift_weight), table,
                             mat.extrapolation or None)



_SECTIONS = {
    "geometry": Geometry, "surface": Surface, "mesh": MeshSpec, "material": Material,
    "solver": Solver, "process": Process, "output": Output, "tools": ToolsSpec,
}


def _number(value, name, integer=False):
    ok = isinstance(value, int) if integer else isinstance(value, int | float)
    if isinstance(value, bool) or not ok:
        raise InputError(name, f"must be {'an integer' if integer else 'a number'}, got {value!r}")
    return value if integer else float(value)


def _numbers(value, name) -> list[float]:
    if not isinstance(value, list):
        raise InputError(name, f"must be a list of numbers, got {value!r}")
    return [_number(v, name) for v in value]


def _points(value, name) -> list[list[float]]:
    if not isinstance(value, list) or not all(isinstance(p, list) and len(p) == 2 for p in value):
        raise InputError(name, f"must be a list of points [x, y], got {value!r}")
    return [_numbers(p, name) for p in value]


def _names(value, name) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise InputError(name, f"must be a list of names, got {value!r}")
    return list(value)


_LIST_ITEMS = {"numbers": _numbers, "points": _points, "names": _names}


def _supports(data) -> dict[str, str]:
    if not isinstance(data, dict):
        raise InputError("supports", "must be a table of boundary group = support")
    for key, value in data.items():
        if not isinstance(value, str):
            raise InputError(f"supports.{key}", f"must be a support name (a string), got {value!r}")
    return dict(data)


def _records(cls, tables, name) -> list:
    if not isinstance(tables, list):
        raise InputError(name, f"must be an array of tables [[{name}]]")
    return [_record(cls, t, f"{name}[{i}]") for i, t in enumerate(tables)]


def _record(cls, data, name):
    if not isinstance(data, dict):
        raise InputError(name, f"must be a table, got {data!r}")
    known = {f.name: f for f in fields(cls)}
    values = {}
    for key, value in data.items():
        if key not in known:
            raise InputError(f"{name}.{key}", f"unknown key; known keys: {', '.join(known)}")
        default = getattr(cls(), key)
        if default is None:  # an optional number (tools.punch_friction): unset (None) or a number
            value = None if value is None else _number(value, f"{name}.{key}")
        elif isinstance(default, bool):
            if not isinstance(value, bool):
                raise InputError(f"{name}.{key}", f"must be true or false, got {value!r}")
        elif isinstance(default, int | float):
            value = _number(value, f"{name}.{key}", integer=isinstance(default, int))
        elif isinstance(default, str) and not isinstance(value, str):
            raise InputError(f"{name}.{key}", f"must be a string, got {value!r}")
        elif isinstance(default, list):
            value = _LIST_ITEMS[known[key].metadata.get("items", "numbers")](value, f"{name}.{key}")
        values[key] = value
    return cls(**values)


def from_dict(data: dict) -> Scene:
    """A validated Scene from a parsed TOML document."""
    known = {f.name for f in fields(Scene)}
    for key in data:
        if key not in known:
            raise InputError(key, f"unknown key; known keys: {', '.join(sorted(known))}")
    beads, tools = None, data.get("tools")
    if isinstance(tools, dict) and "drawbead" in tools:  # [[tools.drawbead]]: an array of tables
        beads = _records(Drawbead, tools["drawbead"], "tools.drawbead")
        data = {**data, "tools": {k: v for k, v in tools.items() if k != "drawbead"}}
    probes, output = None, data.get("output")
    if isinstance(output, dict) and "probe" in output:  # [[output.probe]]: an array of tables
        probes = _records(Probe, output["probe"], "output.probe")
        data = {**data, "output": {k: v for k, v in output.items() if k != "probe"}}
    kwargs = {name: _record(cls, data[name], name) for name, cls in _SECTIONS.items() if name in data}
    if beads is not None:
        kwargs["tools"].drawbead = beads
    if probes is not None:
        kwargs["output"].probe = probes
    if "supports" in data:
        kwargs["supports"] = _supports(data["supports"])
    if "tools" in kwargs:  # the keys of the other kinds of tools are not this kind's
        shape = kwargs["tools"].shape
        if shape not in TOOL_SHAPES:
            raise InputError("tools.shape", f"must be one of {TOOL_SHAPES}, got {shape!r}")
        for key, message in tool_kinds.foreign_keys(shape).items():
            if key in tools:
                raise InputError(f"tools.{key}", message)
    process = data.get("process")
    if isinstance(process, dict):
        for key in LOAD_STEP_KEYS if "tools" in data else STROKE_STEP_KEYS:
            if key in process:
                raise InputError(f"process.{key}", f"a tool scene steps the punch's travel in mm: give "
                                 f"process.{key}_mm (the load-factor step times tools.stroke)" if "tools" in data else
                                 "is a key of tool scenes (the punch's travel in mm): a sheet scene steps its load "
                                 f"factor with process.{key.removesuffix('_mm')}")
    if "loads" in data:
        loads = dict(data["loads"]) if isinstance(data["loads"], dict) else data["loads"]
        if not isinstance(loads, dict):
            raise InputError("loads", "must be a table")
        points = _records(PointLoad, loads.pop("point", []), "loads.point")
        moments = _records(EdgeMoment, loads.pop("moment", []), "loads.moment")
        kwargs["loads"] = _record(Loads, loads, "loads")
        kwargs["loads"].point, kwargs["loads"].moment = points, moments
    if "effects" in data:
        effects = data["effects"]
        if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
            raise InputError("effects", f"must be a list of effect names, got {effects!r}")
        kwargs["effects"] = tuple(effects)
    if "title" in data:
        kwargs["title"] = str(data["title"])
    s = Scene(**kwargs)
    validate(s)
    return s


def load(path: str | Path) -> Scene:
    path = Path(path)
    if not path.is_file():
        raise InputError("scene", f"no such file: {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise InputError("scene", f"{path} is not valid TOML: {err}") from None
    geometry = data.get("geometry")
    if isinstance(geometry, dict) and isinstance(geometry.get("file"), str) and geometry["file"]:
        data["geometry"] = {**geometry, "file": str(path.parent / geometry["file"])}  # relative to the scene
    material = data.get("material")
    for key in ("flow_curve", "forming_limit_curve"):  # files relative to the scene
        if isinstance(material, dict) and isinstance(material.get(key), str) and material[key]:
            material = data["material"] = {**material, key: str(path.parent / material[key])}
    tools = data.get("tools")
    if isinstance(tools, dict):
        for key in ("punch_file", "die_file", "holder_file"):
            if isinstance(tools.get(key), str) and tools[key]:
                tools[key] = str(path.parent / tools[key])  # relative to the scene
    return from_dict(data)




def to_dict(s: Scene) -> dict:
    """The scene as a parsed TOML document: from_dict(to_dict(s)) equals s."""
    data = {"title": s.title, "effects": list(s.effects), "supports": dict(s.supports),
            "loads": copy.deepcopy(asdict(s.loads))}
    for name in _SECTIONS:
        section = getattr(s, name)
        if section is not None:
            data[name] = {f.name: copy.deepcopy(getattr(section, f.name)) for f in fields(section)
                          if getattr(section, f.name) is not None}  # unset: not given (TOML has no null)
    if s.tools is not None:
        data["tools"]["drawbead"] = [asdict(b) for b in s.tools.drawbead]
    data["output"]["probe"] = [asdict(p) for p in s.output.probe]
    if s.tools is not None:  # the keys of the other kinds of tools are not the scene's (a round tool's
        for key in tool_kinds.foreign_keys(s.tools.shape):  # half-width is set from its radius: ToolsSpec)
            data["tools"].pop(key, None)
    for key in LOAD_STEP_KEYS if s.tools is not None else STROKE_STEP_KEYS:  # the other kind of scene's steps
        del data["process"][key]
    return data


def changed(s: Scene, changes: dict) -> Scene:
    """A new Scene: `s` with `changes` applied, checked as a scene file is. Keys name a field as
    its errors do: "effects", "title", "mesh.n", "tools.friction", "supports.left" (a [tools]
    table is added if the scene has none). Every change is applied before any check, so that
    changes that hold only together (friction 0 without the effect 'friction') may be made."""
    data = to_dict(s)
    for key, value in changes.items():
        value = list(value) if isinstance(value, tuple) else copy.deepcopy(value)
        section, dot, name = key.partition(".")
        if not dot:
            data[key] = value
            continue
        table = data.setdefault(section, {})
        if not isinstance(table, dict) or not name:
            raise InputError(key, f"is no key of a scene's tables, got the change {key!r}")
        table[name] = value
    return from_dict(data)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)  # inf and nan are TOML's too
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"no TOML value for {value!r}")


def _is_tables(value) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _toml_table(name: str, table: dict, lines: list[str]) -> None:
    """The table's keys, then its sub-tables ([name.key]) and arrays of tables ([[name.key]])."""
    lines += [f"{k} = {_toml_value(v)}" for k, v in table.items() if not isinstance(v, dict) and not _is_tables(v)]
    for k, v in table.items():
        if isinstance(v, dict):
            lines += ["", f"[{name}.{k}]" if name else f"[{k}]"]
            _toml_table(f"{name}.{k}" if name else k, v, lines)
        elif _is_tables(v):
            for item in v:
                lines += ["", f"[[{name}.{k}]]" if name else f"[[{k}]]"]
                _toml_table(f"{name}.{k}" if name else k, item, lines)


def to_toml(s: Scene) -> str:
    """The scene with every key resolved (defaults included) as a TOML document: load() of it
    gives the same scene."""
    lines: list[str] = []
    _toml_table("", to_dict(s), lines)
    return "\n".join(lines).lstrip("\n") + "\n"


def settings(texts) -> dict:
    """The changes of command-line settings "section.key=value" (for Scene.changed): the value is
    read as a TOML value (24, 0.5, true, [0.25, 0.5], "text"), else taken as a string."""
    changes = {}
    for text in texts:
        key, eq, value = text.partition("=")
        key = key.strip()
        if not eq or not key:
            raise InputError("--set", f"expects key=value (as mesh.n=24), got {text!r}")
        try:
            changes[key] = tomllib.loads(f"v = {value.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            changes[key] = value.strip()
    return changes
