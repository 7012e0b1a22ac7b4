"""Scenes: what to simulate, read from TOML and checked before any computation.

A scene states the geometry of the blank, its reference surface, the mesh, the material, the
supports, the loads and the physical effects to simulate; only the terms of those effects are
assembled. A scene with any of the effects geometric_nonlinearity, plasticity, anisotropy
(``Scene.nonlinear``) is a nonlinear elastic-plastic sheet, stepped through the load factors of
its [process] section; ``Scene.hill79()`` is its material. The effect 'contact' needs a [tools]
table (``Scene.tools``: the rigid tools of the square cup, shellform.contact.tools). Every bad
value raises shellform.errors.InputError naming its field, e.g.
``material.thickness: must be > 0, got -1.0``.
See docs/scenes.md for every key.
"""

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from shellform.forms.functional import EFFECTS, NONLINEAR_EFFECTS
from shellform.errors import InputError
from shellform.mesh import outline

TOOL_SHAPES = ("square", "round")
SQUARE_TOOL_KEYS = ("punch_half_width", "punch_corner_radius", "die_half_width", "die_corner_radius")
SPREADS = ("area", "rigid")  # the blank holder's spread of its force (shellform/contact/holder.py)
CONTACT_EFFECTS = ("contact", "friction")  # the rigid tools of [tools] (shellform/contact/)

SUPPORTS = ("simply_supported", "clamped", "symmetry", "free", "clamped_sliding")
NONLINEAR_SUPPORTS = ("clamped_sliding",)  # only the nonlinear sheet knows these (shellform/supports.py)
SIDES = ("left", "right", "bottom", "top")
# what a mirror line needs (u_n = 0, w,n = 0; shellform/supports.py): symmetry, or a support holding more
MIRROR_SUPPORTS = ("symmetry", "clamped", "clamped_sliding")
MAY_BE_INFINITE = ("surface.R1", "surface.R2")  # inf: flat along that direction
REGIONS = ("full", "quarter")  # rectangle
CIRCLE_REGIONS = ("full", "half", "quarter")
MESH_KINDS = ("structured", "unstructured")
DIAGONALS = ("right", "left", "crossed", "right/left", "left/right")
HARDENING = ("none", "power", "swift")
CURVE_PARAMETERS = {"none": (), "power": ("yield_stress", "n"), "swift": ("K", "eps0", "n")}


@dataclass
class Geometry:
    shape: str = "rectangle"  # rectangle, circle, polygon or file (shellform/mesh/outline.py)
    lx: float = 1.0  # rectangle: blank size along x
    ly: float = 1.0  # rectangle: blank size along y
    region: str = "full"  # rectangle, circle: "quarter" x, y >= 0; circle: "half" y >= 0
    radius: float = 0.0  # circle (0: unset)
    vertices: list[list[float]] = field(default_factory=list, metadata={"items": "points"})  # polygon
    edges: list[str] = field(default_factory=list, metadata={"items": "names"})  # polygon: a name per edge
    file: str = ""  # file: a gmsh .msh, .geo (or CAD) file, relative to the scene's folder


@dataclass
class Surface:
    R1: float = math.inf  # principal radius along x of z0 = -(x^2/R1 + y^2/R2)/2
    R2: float = math.inf
    z0: str = ""  # or any z0(x, y) as text, e.g. "0.1*sin(pi*x)*sin(pi*y)" (forms/reference_surface.py)


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
    hardening: str = "none"  # "none" (elastic), "power" (yield_stress, n) or "swift" (K, eps0, n)
    yield_stress: float = 0.0  # power law: sigma_y (0: unset)
    n: float = 0.0  # power law: n >= 1; Swift: n >= 0
    K: float = 0.0  # Swift: sigma_bar = K (eps0 + p)^n (0: unset)
    eps0: float = 0.0  # Swift (0: unset)
    r: float = 1.0  # Lankford coefficient of Hill 1979 (> 0; != 1 needs 'anisotropy')
    m: float = 2.0  # Hill 1979 exponent (>= 1; != 2 needs 'anisotropy')


@dataclass
class PointLoad:
    x: float = 0.0
    y: float = 0.0
    fz: float = 0.0  # force along +w
    fx: float = 0.0  # in-plane forces along +x, +y (need 'membrane')
    fy: float = 0.0


@dataclass
class EdgeMoment:
    side: str = ""  # left, right, bottom or top
    m: float = 0.0  # per unit length about the side's tangent; > 0 turns the outward fibre towards +z


@dataclass
class Loads:
    pressure: float = 0.0  # uniform, along +w
    point: list[PointLoad] = field(default_factory=list)
    moment: list[EdgeMoment] = field(default_factory=list)  # nonlinear scenes only


@dataclass
class Solver:
    mapped: bool = True  # False: no Jacobian map of the slopes (plain DOLFINx); for studies only


@dataclass
class Process:
    """Load stepping of the nonlinear sheet (shellform.nonlinear.driver); ignored by linear scenes."""

    thickness_points: int = 5  # Gauss points through the thickness (>= 2 with plasticity)
    initial_step: float = 0.1  # first load-factor increment
    min_step: float = 1e-4  # 0 < min_step <= initial_step <= max_step <= 1
    max_step: float = 0.25
    max_iterations: int = 12  # Newton iterations per increment (>= 1)
    rtol: float = 1e-9  # residual tolerance (> 0)
    path: list[float] = field(default_factory=lambda: [1.0])  # load factors to step through, in order
    report: list[float] = field(default_factory=list)  # load factors at which results are recorded
    springback: bool = False  # tool scenes: after the stroke the tools withdraw (contact/springback.py)


@dataclass
class ToolsSpec:
    """Rigid tools of cup deep drawing (shellform.contact.tools): square (NUMISHEET'93) or round.
    A round punch is the square one with plan corner radius = half-width = punch_radius (its
    plan is a circle), a round die the same with die_radius."""

    shape: str = "square"  # "square" or "round"
    punch_radius: float = 0.0  # round: the punch's radius (0: unset)
    die_radius: float = 0.0  # round: the die opening's radius (0: unset)
    punch_half_width: float = 35.0  # 70 mm square punch
    punch_corner_radius: float = 10.0  # plan corner radius
    punch_profile_radius: float = 8.0  # nose radius
    die_half_width: float = 37.0  # 74 mm die opening
    die_corner_radius: float = 12.0
    die_profile_radius: float = 5.0  # die shoulder radius
    punch_gap: float = 0.0  # initial gap between the punch face and the sheet (>= 0)
    blank_holder_force: float = 19600.0  # N, on the whole blank (a quarter model carries a quarter)
    friction: float = 0.0  # Coulomb coefficient (> 0 needs the effect 'friction')
    stroke: float = 30.0  # punch travel, mm
    holder_spread: str = "area"  # how the closed holder spreads its force: "area" or "rigid" (contact/holder.py)

    def __post_init__(self):
        if self.shape == "round":  # circles: corner radius = half-width = radius
            self.punch_half_width = self.punch_corner_radius = self.punch_radius
            self.die_half_width = self.die_corner_radius = self.die_radius


@dataclass
class Output:
    vtx: bool = True
    png: bool = True
    fld: bool = True  # tool scenes with plasticity: the forming-limit view (results/fld.py)
    checkpoint_every: float = 60.0  # tool scenes: seconds of wall time between checkpoints (0: at reports only)


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

    def __post_init__(self):
        validate(self)

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

    @property
    def symmetry_copies(self) -> int:
        """How many copies of the meshed region make the whole blank (4 for a quarter)."""
        g = self.geometry
        if g.shape in ("rectangle", "circle"):
            return {"full": 1, "half": 2, "quarter": 4}[g.region]
        return 2 ** sum(v == "symmetry" for v in self.supports.values())

    @property
    def nonlinear(self) -> bool:
        """Whether any effect of the nonlinear sheet is on (forms.functional.NONLINEAR_EFFECTS)."""
        return any(e in NONLINEAR_EFFECTS for e in self.effects)

    def hill79(self):
        """The scene's shellform.material.Hill79Material: elastic (hardening "none") unless the
        effect 'plasticity' is on. Its own validation names the field (material.yield_stress, ...)."""
        from shellform.material import Hill79Material  # numba modules: imported only when needed

        mat = self.material
        if "plasticity" not in self.effects:
            return Hill79Material(mat.E, mat.nu, mat.r, mat.m)
        unset = lambda v: v if v != 0.0 else None  # noqa: E731  0.0: not given
        # n = 0 is a valid Swift exponent (perfect plasticity) but no power law (n >= 1): unset there
        n = unset(mat.n) if mat.hardening == "power" else mat.n
        return Hill79Material(mat.E, mat.nu, mat.r, mat.m, mat.hardening, unset(mat.yield_stress), n,
                              unset(mat.K), unset(mat.eps0))


# -- reading ---------------------------------------------------------------------------------
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
        if isinstance(default, bool):
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
    kwargs = {name: _record(cls, data[name], name) for name, cls in _SECTIONS.items() if name in data}
    if "supports" in data:
        kwargs["supports"] = _supports(data["supports"])
    tools = data.get("tools")
    if isinstance(tools, dict) and tools.get("shape") == "round":
        for key in SQUARE_TOOL_KEYS:
            if key in tools:
                raise InputError(f"tools.{key}", "is a key of square tools: round tools take punch_radius and "
                                 "die_radius")
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
    return Scene(**kwargs)


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
    return from_dict(data)


# -- checking --------------------------------------------------------------------------------
def _require(cond, name, message):
    if not cond:
        raise InputError(name, message)


def validate(s: Scene) -> None:
    _validate_finite(s)
    _validate_effects(s)
    _validate_geometry(s)
    m = s.mesh
    for name in ("R1", "R2"):
        v = getattr(s.surface, name)
        _require(v != 0 and not math.isnan(v), f"surface.{name}", f"must be non-zero (inf for flat), got {v}")
        if math.isfinite(v):
            _require("shallow_curvature" in s.effects, f"surface.{name}",
                     "a curved reference surface needs the effect 'shallow_curvature'")
            _require(not s.surface.z0, f"surface.{name}", "give either z0 or the radii R1, R2, not both")
    if s.surface.z0:
        from shellform.forms.reference_surface import ReferenceSurface

        surface = ReferenceSurface(s.surface.z0)
        problem = surface.problem()
        _require(problem is None, "surface.z0", f"{surface.quoted()}: {problem}")
        _require("shallow_curvature" in s.effects, "surface.z0",
                 "a curved reference surface needs the effect 'shallow_curvature'")
        _require(s.tools is None, "surface.z0", "tool scenes draw a flat blank")
        try:
            value = surface.value(0.123, 0.456)
        except (ArithmeticError, ValueError) as err:
            raise InputError("surface.z0", f"{surface.quoted()} cannot be evaluated: {err}") from None
        _require(math.isfinite(value), "surface.z0", f"{surface.quoted()} is not finite at (0.123, 0.456)")
    _require(m.kind in MESH_KINDS, "mesh.kind", f"must be one of {MESH_KINDS}, got {m.kind!r}")
    _require(m.n >= 1, "mesh.n", f"must be >= 1, got {m.n}")
    _require(m.refine >= 0, "mesh.refine", f"must be >= 0, got {m.refine}")
    _require(m.diagonal in DIAGONALS, "mesh.diagonal", f"must be one of {DIAGONALS}, got {m.diagonal!r}")
    _validate_material(s)
    groups = outline.group_names(s.geometry)
    for group, v in s.supports.items():
        _require(group in groups, f"supports.{group}",
                 f"the blank has no boundary group {group!r}; its groups: {', '.join(groups)}")
        _require(v in SUPPORTS, f"supports.{group}", f"unknown support {v!r}; known supports: {', '.join(SUPPORTS)}")
        _require(v not in NONLINEAR_SUPPORTS or s.nonlinear, f"supports.{group}", f"{v!r} is a support of the "
                 f"nonlinear sheet: needs one of the effects {', '.join(NONLINEAR_EFFECTS)}")
    for group in outline.symmetry_lines(s.geometry):
        v = s.supports.get(group, "free")
        _require(v in MIRROR_SUPPORTS, f"supports.{group}",
                 f"the {s.geometry.region} {s.geometry.shape} is mirrored across this edge to make the whole blank: "
                 f"it needs 'symmetry' (or {' or '.join(repr(m) for m in MIRROR_SUPPORTS[1:])}), got {v!r}")
    _validate_loads(s)
    _validate_process(s)
    every = s.output.checkpoint_every
    _require(math.isfinite(every) and every >= 0, "output.checkpoint_every", f"must be finite and >= 0, got {every}")
    _validate_tools(s)
    _validate_size(s)


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
                _require(not math.isnan(v), name, f"must be a number (inf: flat), got {v}")
            else:
                _require(math.isfinite(v), name, f"must be finite, got {v}")


def _validate_geometry(s: Scene) -> None:
    g, m = s.geometry, s.mesh
    _require(g.shape in outline.SHAPES, "geometry.shape", f"must be one of {outline.SHAPES}, got {g.shape!r}")
    own = {"rectangle": (), "circle": ("radius",), "polygon": ("vertices", "edges"), "file": ("file",)}
    for shape, keys in own.items():
        for key in keys:
            _require(shape == g.shape or not getattr(g, key), f"geometry.{key}",
                     f"is a key of shape = {shape!r}, but the shape is {g.shape!r}")
    if g.shape == "rectangle":
        for name in ("lx", "ly"):
            v = getattr(g, name)
            _require(math.isfinite(v) and v > 0, f"geometry.{name}", f"must be > 0, got {v}")
        _require(g.region in REGIONS, "geometry.region", f"rectangle: must be one of {REGIONS}, got {g.region!r}")
        return
    _require(m.kind == "unstructured", "mesh.kind",
             f"a {g.shape} blank is meshed by gmsh: set kind = 'unstructured', got {m.kind!r}")
    if g.shape == "circle":
        _require(math.isfinite(g.radius) and g.radius > 0, "geometry.radius", f"must be > 0, got {g.radius}")
        _require(g.region in CIRCLE_REGIONS, "geometry.region",
                 f"circle: must be one of {CIRCLE_REGIONS}, got {g.region!r}")
        return
    _require(g.region == "full", "geometry.region",
             f"a {g.shape} blank is the region meshed: name its symmetry lines in [supports] instead")
    if g.shape == "polygon":
        _require(all(math.isfinite(c) for p in g.vertices for c in p), "geometry.vertices", "must be finite")
        problem = outline.polygon_problem(g.vertices)
        _require(problem is None, "geometry.vertices", str(problem))
        _require(not g.edges or len(g.edges) == len(g.vertices), "geometry.edges",
                 f"needs one name per edge ({len(g.vertices)}), got {len(g.edges)}")
        return
    path = Path(g.file)
    _require(bool(g.file), "geometry.file", "shape = 'file' needs a file name")
    _require(path.suffix.lower() in outline.FILE_SUFFIXES, "geometry.file",
             f"must be a gmsh file ({', '.join(outline.FILE_SUFFIXES)}), got {g.file!r}")
    _require(path.is_file(), "geometry.file", f"no such file: {g.file}")


def _validate_size(s: Scene) -> None:
    """A mesh whose estimated memory exceeds what the machine allows is refused before it is built."""
    from shellform.mesh import budget

    g, m = s.geometry, s.mesh
    if g.shape == "file":
        cells = outline.file_cells(g, m.n, m.refine)
    elif g.shape == "rectangle":
        cells = budget.estimated_cells(g.lx, g.ly, g.region, m.kind, m.n, m.refine)
    else:
        x0, x1, _, _ = outline.region_bounds(g)
        cells = budget.gmsh_cells(outline.region_area(g), (x1 - x0) / m.n, m.refine)
    nonlinear = s.nonlinear or s.tools is not None
    layers = s.process.thickness_points if "plasticity" in s.effects else 0  # a plastic section's points
    need, have = budget.estimated_bytes(cells, nonlinear, layers=layers), budget.available_bytes()
    usual = min(layers, Process().thickness_points)
    _require(need <= have or budget.estimated_bytes(cells, nonlinear, layers=usual) > have, "process.thickness_points",
             f"{layers:,} points through the thickness on {cells:,} cells need about {need / 1e9:.3g} GB; "
             f"this machine allows {have / 1e9:.3g} GB (shellform/mesh/budget.py)")
    _require(need <= have, "mesh.n", f"n = {m.n} (refine {m.refine}) makes about {cells:,} cells, which need about "
             f"{need / 1e9:.3g} GB; this machine allows {have / 1e9:.3g} GB (shellform/mesh/budget.py)")


def _validate_effects(s: Scene) -> None:
    known = EFFECTS + CONTACT_EFFECTS
    for e in s.effects:
        _require(e in known, "effects", f"unknown effect {e!r}; known effects: {', '.join(known)}")
    _require(len(set(s.effects)) == len(s.effects), "effects", "an effect is listed twice")
    _require("bending" in s.effects or "membrane" in s.effects, "effects",
             "needs 'bending' or 'membrane' (nothing would be assembled)")
    if "shallow_curvature" in s.effects:
        _require("bending" in s.effects and "membrane" in s.effects, "effects",
                 "'shallow_curvature' couples membrane and bending: switch both on")
    if "cubic_membrane" in s.effects:
        _require("membrane" in s.effects, "effects", "'cubic_membrane' interpolates the membrane: it needs 'membrane'")
        _require(not s.nonlinear, "effects", "'cubic_membrane' is an option of the linear element; the nonlinear "
                 "sheet's in-plane field is cubic already")
    for e in s.effects:
        if e in NONLINEAR_EFFECTS:
            _require("bending" in s.effects and "membrane" in s.effects, "effects",
                     f"{e!r} is an effect of the nonlinear sheet, a full shell: switch on 'bending' and 'membrane'")
    _require("anisotropy" not in s.effects or "plasticity" in s.effects, "effects",
             "'anisotropy' shapes the yield function: it needs 'plasticity'")
    _require("finite_strain" not in s.effects or
             ("plasticity" in s.effects and "geometric_nonlinearity" in s.effects), "effects",
             "'finite_strain' (logarithmic strains, thinning) needs 'plasticity' and 'geometric_nonlinearity'")
    _require("friction" not in s.effects or "contact" in s.effects, "effects",
             "'friction' acts at the contact with the tools: it needs 'contact'")
    _require("contact" not in s.effects or "geometric_nonlinearity" in s.effects, "effects",
             "'contact' with the tools needs the large displacements of 'geometric_nonlinearity'")


def _validate_material(s: Scene) -> None:
    mat = s.material
    _require(math.isfinite(mat.E) and mat.E > 0, "material.E", f"must be > 0, got {mat.E}")
    _require(-1.0 < mat.nu < 0.5, "material.nu", f"must lie in (-1, 0.5), got {mat.nu}")
    _require(math.isfinite(mat.thickness) and mat.thickness > 0, "material.thickness",
             f"must be > 0, got {mat.thickness}")
    _require(math.isfinite(mat.r) and mat.r > 0, "material.r", f"must be > 0, got {mat.r}")
    _require(math.isfinite(mat.m) and mat.m >= 1, "material.m",
             f"must be >= 1 (convex yield function), got {mat.m}")
    if "anisotropy" not in s.effects:
        _require(mat.r == 1.0, "material.r", f"r = {mat.r} (isotropic: 1) needs the effect 'anisotropy'")
        _require(mat.m == 2.0, "material.m", f"m = {mat.m} (von Mises: 2) needs the effect 'anisotropy'")
    _require(mat.hardening in HARDENING, "material.hardening",
             f"must be one of {', '.join(HARDENING)}, got {mat.hardening!r}")
    plastic = "plasticity" in s.effects
    if not plastic:
        _require(mat.hardening == "none", "material.hardening",
                 "set, but the scene's effects do not include 'plasticity'")
    elif mat.hardening == "none":
        raise InputError("material.hardening",
                         "plasticity needs a hardening curve: 'power' (yield_stress, n) or 'swift' (K, eps0, n)")
    for name in ("yield_stress", "n", "K", "eps0"):
        v = getattr(mat, name)
        _require(math.isfinite(v), f"material.{name}", f"must be finite, got {v}")
        if v != 0.0:
            _require(plastic, f"material.{name}", "set, but the scene's effects do not include 'plasticity'")
            _require(name in CURVE_PARAMETERS[mat.hardening], f"material.{name}",
                     f"is no parameter of hardening = {mat.hardening!r} "
                     f"(its parameters: {', '.join(CURVE_PARAMETERS[mat.hardening])})")
    if plastic:
        s.hill79()  # Hill79Material validates the curve and names the field


def _validate_loads(s: Scene) -> None:
    g, loads = s.geometry, s.loads
    _require(math.isfinite(loads.pressure), "loads.pressure", "must be finite")
    for i, p in enumerate(loads.point):
        for name in ("x", "y", "fx", "fy", "fz"):
            _require(math.isfinite(getattr(p, name)), f"loads.point[{i}].{name}", "must be finite")
    needs_w = loads.pressure != 0 or any(p.fz != 0 for p in loads.point)
    _require(not needs_w or "bending" in s.effects, "loads", "transverse loads need the effect 'bending'")
    box = bounds(s) if g.shape != "file" else None
    for i, p in enumerate(loads.point):
        if box is not None:
            x0, x1, y0, y1 = box
            tol = 1e-12 * max(x1 - x0, y1 - y0)
            _require(x0 - tol <= p.x <= x1 + tol and y0 - tol <= p.y <= y1 + tol, f"loads.point[{i}]",
                     f"({p.x}, {p.y}) lies outside the blank [{x0}, {x1}] x [{y0}, {y1}]")
        _require((p.fx == 0 and p.fy == 0) or "membrane" in s.effects, f"loads.point[{i}]",
                 "in-plane forces (fx, fy) need the effect 'membrane'")
    for i, mo in enumerate(loads.moment):
        _require(mo.side in SIDES, f"loads.moment[{i}].side", f"must be one of {', '.join(SIDES)}, got {mo.side!r}")
        _require(math.isfinite(mo.m), f"loads.moment[{i}].m", f"must be finite, got {mo.m}")
        _require(s.nonlinear, f"loads.moment[{i}]", "edge moments are loads of the nonlinear sheet: "
                 f"need one of the effects {', '.join(NONLINEAR_EFFECTS)}")
        _require(g.shape == "rectangle", f"loads.moment[{i}]", "edge moments act on the sides of a rectangle")


def _validate_process(s: Scene) -> None:
    """Checked in every scene, though only nonlinear scenes step through a load path."""
    pr = s.process
    low = 2 if "plasticity" in s.effects else 1
    _require(pr.thickness_points >= low, "process.thickness_points",
             f"must be >= {low}{' with plasticity' if low == 2 else ''}, got {pr.thickness_points}")
    for name in ("min_step", "initial_step", "max_step"):
        v = getattr(pr, name)
        _require(math.isfinite(v) and v > 0, f"process.{name}", f"must be > 0, got {v}")
    _require(pr.min_step <= pr.initial_step, "process.min_step",
             f"must be <= initial_step ({pr.initial_step}), got {pr.min_step}")
    _require(pr.initial_step <= pr.max_step, "process.initial_step",
             f"must be <= max_step ({pr.max_step}), got {pr.initial_step}")
    _require(pr.max_step <= 1, "process.max_step", f"must be <= 1, got {pr.max_step}")
    _require(pr.max_iterations >= 1, "process.max_iterations", f"must be >= 1, got {pr.max_iterations}")
    _require(math.isfinite(pr.rtol) and pr.rtol > 0, "process.rtol", f"must be > 0, got {pr.rtol}")
    _require(len(pr.path) > 0, "process.path", "must list at least one load factor, e.g. [1.0]")
    _require(all(math.isfinite(v) for v in pr.path), "process.path", f"must be finite numbers, got {pr.path}")
    lo, hi = min(0.0, *pr.path), max(0.0, *pr.path)  # the path starts at load factor 0
    for v in pr.report:
        _require(math.isfinite(v) and lo <= v <= hi, "process.report",
                 f"{v} lies outside the load factors [{lo}, {hi}] that process.path covers")


def _validate_tools(s: Scene) -> None:
    """The [tools] table and the effects 'contact' and 'friction' (after the material: the
    clearance is checked against the thickness)."""
    t = s.tools
    if t is None:
        _require("contact" not in s.effects, "tools", "the effect 'contact' needs a [tools] table")
        return
    _require("contact" in s.effects, "effects", "a [tools] table needs the effect 'contact'")
    _require(t.shape in TOOL_SHAPES, "tools.shape", f"must be one of {TOOL_SHAPES}, got {t.shape!r}")
    if t.shape == "round":
        for name in ("punch_radius", "die_radius"):
            _require(getattr(t, name) > 0, f"tools.{name}", f"round tools need {name} > 0, got {getattr(t, name)}")
    else:
        for name in ("punch_radius", "die_radius"):
            _require(getattr(t, name) == 0, f"tools.{name}", "is a key of shape = 'round' (square tools: "
                     "punch_half_width, punch_corner_radius, die_half_width, die_corner_radius)")
    _require(t.holder_spread in SPREADS, "tools.holder_spread", f"must be one of {SPREADS}, got {t.holder_spread!r}")
    for f in fields(ToolsSpec):
        v = getattr(t, f.name)
        if f.name not in ("holder_spread", "shape"):
            _require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{f.name}", f"must be finite, got {v}")
    for name in ("punch_half_width", "punch_profile_radius", "die_half_width", "die_profile_radius", "stroke"):
        v = getattr(t, name)
        _require(v > 0, f"tools.{name}", f"must be > 0, got {v}")
    for name in ("punch_corner_radius", "die_corner_radius", "blank_holder_force", "friction"):
        v = getattr(t, name)
        _require(v >= 0, f"tools.{name}", f"must be >= 0, got {v}")
    _require(t.punch_profile_radius <= t.punch_corner_radius <= t.punch_half_width, "tools.punch_corner_radius",
             f"must lie between punch_profile_radius ({t.punch_profile_radius}) and punch_half_width "
             f"({t.punch_half_width}), got {t.punch_corner_radius}")
    _require(t.die_corner_radius <= t.die_half_width, "tools.die_corner_radius",
             f"must be <= die_half_width ({t.die_half_width}), got {t.die_corner_radius}")
    _require(t.punch_half_width < t.die_half_width, "tools.punch_half_width",
             f"the punch must fit in the die opening: must be < die_half_width ({t.die_half_width}), "
             f"got {t.punch_half_width}")
    thickness = s.material.thickness
    _require(t.die_half_width - t.punch_half_width >= thickness, "tools.die_half_width",
             f"the clearance die_half_width - punch_half_width = {t.die_half_width - t.punch_half_width} "
             f"is smaller than the thickness {thickness}: the sheet cannot pass")
    _require(t.punch_gap >= 0, "tools.punch_gap",
             f"must be >= 0 (the punch would overlap the blank), got {t.punch_gap}")
    g = s.geometry
    flat = t.die_half_width + t.die_profile_radius  # where the die's flat top and the holder start
    if g.shape == "rectangle":
        side = "lx" if g.lx <= g.ly else "ly"
        _require(min(g.lx, g.ly) / 2 > flat, f"geometry.{side}",
                 f"the blank does not reach the blank holder and the die's flat top: half its size "
                 f"{getattr(g, side) / 2} must exceed die_half_width + die_profile_radius = {flat}")
    elif g.shape == "circle":
        _require(g.radius > flat, "geometry.radius",
                 f"the blank does not reach the blank holder and the die's flat top: its radius {g.radius} "
                 f"must exceed die_half_width + die_profile_radius = {flat}")
    if t.friction > 0:
        _require("friction" in s.effects, "tools.friction", f"friction = {t.friction} needs the effect 'friction'")
    else:
        _require("friction" not in s.effects, "tools.friction", "the effect 'friction' needs friction > 0")
    if g.shape == "rectangle":
        outer = ("right", "top") if g.region == "quarter" else SIDES
    else:  # an outline's edges are free or symmetry lines
        outer = tuple(k for k, v in s.supports.items() if v != "symmetry")
    for side in outer:
        v = s.supports.get(side, "free")
        _require(v == "free", f"supports.{side}",
                 f"the tools hold the blank: its outer edges must be 'free', got {v!r}")


def bounds(s: Scene) -> tuple[float, float, float, float]:
    """x_min, x_max, y_min, y_max of the meshed region (a rectangle or circle is centred at the
    origin; a polygon is where its vertices are; a file's region is known once it is read)."""
    if s.geometry.shape in ("circle", "polygon"):
        return outline.region_bounds(s.geometry)
    hx, hy = s.geometry.lx / 2, s.geometry.ly / 2
    return (0.0, hx, 0.0, hy) if s.geometry.region == "quarter" else (-hx, hx, -hy, hy)
