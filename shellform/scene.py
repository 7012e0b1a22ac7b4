"""Scenes: what to simulate, read from TOML and checked before any computation.

A scene states the geometry of the blank, its reference surface, the mesh, the material, the
supports, the loads and the physical effects to simulate; only the terms of those effects are
assembled. Every bad value raises shellform.errors.InputError naming its field, e.g.
``material.thickness: must be > 0, got -1.0``. See docs/scenes.md for every key.
"""

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from forms.functional import EFFECTS
from shellform.errors import InputError

SUPPORTS = ("simply_supported", "clamped", "symmetry", "free")
SIDES = ("left", "right", "bottom", "top")
REGIONS = ("full", "quarter")
MESH_KINDS = ("structured", "unstructured")
DIAGONALS = ("right", "left", "crossed", "right/left", "left/right")


@dataclass
class Geometry:
    lx: float = 1.0  # blank size along x
    ly: float = 1.0  # blank size along y
    region: str = "full"  # "quarter": x, y >= 0 with symmetry at x = 0 and y = 0


@dataclass
class Surface:
    R1: float = math.inf  # principal radius along x of z0 = -(x^2/R1 + y^2/R2)/2
    R2: float = math.inf


@dataclass
class MeshSpec:
    kind: str = "structured"
    n: int = 8  # elements along x of the region (structured: n x n x 2 triangles)
    diagonal: str = "right"
    refine: int = 0  # uniform refinements of that mesh (nested meshes for convergence studies)


@dataclass
class Material:
    E: float = 1.0
    nu: float = 0.3
    thickness: float = 0.01


@dataclass
class PointLoad:
    x: float = 0.0
    y: float = 0.0
    fz: float = 0.0  # force along +w


@dataclass
class Loads:
    pressure: float = 0.0  # uniform, along +w
    point: list[PointLoad] = field(default_factory=list)


@dataclass
class Supports:
    left: str = "free"
    right: str = "free"
    bottom: str = "free"
    top: str = "free"


@dataclass
class Solver:
    mapped: bool = True  # False: no Jacobian map of the slopes (plain DOLFINx); for studies only


@dataclass
class Output:
    vtx: bool = True
    png: bool = True


@dataclass
class Scene:
    title: str = "shellform scene"
    effects: tuple[str, ...] = ("bending",)
    geometry: Geometry = field(default_factory=Geometry)
    surface: Surface = field(default_factory=Surface)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    material: Material = field(default_factory=Material)
    supports: Supports = field(default_factory=Supports)
    loads: Loads = field(default_factory=Loads)
    solver: Solver = field(default_factory=Solver)
    output: Output = field(default_factory=Output)

    def __post_init__(self):
        validate(self)

    @property
    def kappa0(self) -> tuple[float, float]:
        return (1.0 / self.surface.R1, 1.0 / self.surface.R2)


# -- reading ---------------------------------------------------------------------------------
_SECTIONS = {
    "geometry": Geometry, "surface": Surface, "mesh": MeshSpec, "material": Material,
    "supports": Supports, "solver": Solver, "output": Output,
}


def _number(value, name, integer=False):
    ok = isinstance(value, int) if integer else isinstance(value, int | float)
    if isinstance(value, bool) or not ok:
        raise InputError(name, f"must be {'an integer' if integer else 'a number'}, got {value!r}")
    return value if integer else float(value)


def _record(cls, data, name):
    if not isinstance(data, dict):
        raise InputError(name, f"must be a table, got {data!r}")
    known = {f.name: f for f in fields(cls)}
    values = {}
    for key, value in data.items():
        if key not in known:
            raise InputError(f"{name}.{key}", f"unknown key; known keys: {', '.join(known)}")
        default = getattr(cls(), key)
        if isinstance(default, bool):
            if not isinstance(value, bool):
                raise InputError(f"{name}.{key}", f"must be true or false, got {value!r}")
        elif isinstance(default, int | float):
            value = _number(value, f"{name}.{key}", integer=isinstance(default, int))
        elif isinstance(default, str) and not isinstance(value, str):
            raise InputError(f"{name}.{key}", f"must be a string, got {value!r}")
        values[key] = value
    return cls(**values)


def from_dict(data: dict) -> Scene:
    """A validated Scene from a parsed TOML document."""
    known = {f.name for f in fields(Scene)}
    for key in data:
        if key not in known:
            raise InputError(key, f"unknown key; known keys: {', '.join(sorted(known))}")
    kwargs = {name: _record(cls, data[name], name) for name, cls in _SECTIONS.items() if name in data}
    if "loads" in data:
        loads = dict(data["loads"]) if isinstance(data["loads"], dict) else data["loads"]
        if not isinstance(loads, dict):
            raise InputError("loads", "must be a table")
        points = loads.pop("point", [])
        if not isinstance(points, list):
            raise InputError("loads.point", "must be an array of tables [[loads.point]]")
        kwargs["loads"] = _record(Loads, loads, "loads")
        kwargs["loads"].point = [_record(PointLoad, p, f"loads.point[{i}]") for i, p in enumerate(points)]
    if "effects" in data:
        effects = data["effects"]
        if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
            raise InputError("effects", f"must be a list of effect names, got {effects!r}")
        kwargs["effects"] = tuple(effects)
    if "title" in data:
        kwargs["title"] = str(data["title"])
    return Scene(**kwargs)


def load(path: str | Path) -> Scene:
    path = Path(path)
    if not path.is_file():
        raise InputError("scene", f"no such file: {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise InputError("scene", f"{path} is not valid TOML: {err}") from None
    return from_dict(data)


# -- checking --------------------------------------------------------------------------------
def _require(cond, name, message):
    if not cond:
        raise InputError(name, message)


def validate(s: Scene) -> None:
    for e in s.effects:
        _require(e in EFFECTS, "effects", f"unknown effect {e!r}; known effects: {', '.join(EFFECTS)}")
    _require(len(set(s.effects)) == len(s.effects), "effects", "an effect is listed twice")
    _require("bending" in s.effects or "membrane" in s.effects, "effects",
             "needs 'bending' or 'membrane' (nothing would be assembled)")
    if "shallow_curvature" in s.effects:
        _require("bending" in s.effects and "membrane" in s.effects, "effects",
                 "'shallow_curvature' couples membrane and bending: switch both on")
    g, m, mat = s.geometry, s.mesh, s.material
    for name in ("lx", "ly"):
        v = getattr(g, name)
        _require(math.isfinite(v) and v > 0, f"geometry.{name}", f"must be > 0, got {v}")
    _require(g.region in REGIONS, "geometry.region", f"must be one of {REGIONS}, got {g.region!r}")
    for name in ("R1", "R2"):
        v = getattr(s.surface, name)
        _require(v != 0 and not math.isnan(v), f"surface.{name}", f"must be non-zero (inf for flat), got {v}")
        if math.isfinite(v):
            _require("shallow_curvature" in s.effects, f"surface.{name}",
                     "a curved reference surface needs the effect 'shallow_curvature'")
    _require(m.kind in MESH_KINDS, "mesh.kind", f"must be one of {MESH_KINDS}, got {m.kind!r}")
    _require(m.n >= 1, "mesh.n", f"must be >= 1, got {m.n}")
    _require(m.refine >= 0, "mesh.refine", f"must be >= 0, got {m.refine}")
    _require(m.diagonal in DIAGONALS, "mesh.diagonal", f"must be one of {DIAGONALS}, got {m.diagonal!r}")
    _require(math.isfinite(mat.E) and mat.E > 0, "material.E", f"must be > 0, got {mat.E}")
    _require(-1.0 < mat.nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {mat.nu}")
    _require(math.isfinite(mat.thickness) and mat.thickness > 0, "material.thickness",
             f"must be > 0, got {mat.thickness}")
    for side in SIDES:
        v = getattr(s.supports, side)
        _require(v in SUPPORTS, f"supports.{side}", f"unknown support {v!r}; known supports: {', '.join(SUPPORTS)}")
    _require(math.isfinite(s.loads.pressure), "loads.pressure", "must be finite")
    needs_w = s.loads.pressure != 0 or any(p.fz != 0 for p in s.loads.point)
    _require(not needs_w or "bending" in s.effects, "loads", "transverse loads need the effect 'bending'")
    x0, x1, y0, y1 = bounds(s)
    tol = 1e-12 * max(g.lx, g.ly)
    for i, p in enumerate(s.loads.point):
        _require(x0 - tol <= p.x <= x1 + tol and y0 - tol <= p.y <= y1 + tol, f"loads.point[{i}]",
                 f"({p.x}, {p.y}) lies outside the blank [{x0}, {x1}] x [{y0}, {y1}]")


def bounds(s: Scene) -> tuple[float, float, float, float]:
    """x_min, x_max, y_min, y_max of the meshed region (the blank is centred at the origin)."""
    hx, hy = s.geometry.lx / 2, s.geometry.ly / 2
    return (0.0, hx, 0.0, hy) if s.geometry.region == "quarter" else (-hx, hx, -hy, hy)
