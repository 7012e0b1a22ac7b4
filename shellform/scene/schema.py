"""The schema of a scene: its sections as dataclasses, their keys, defaults and allowed names.

A scene states the geometry of the blank, its reference surface, the mesh, the material, the
supports, the loads and the physical effects to simulate (shellform.effects: what each effect
switches on and needs). Its effects select the solver (``Scene.route``): the linear shell, the
nonlinear elastic-plastic sheet stepped through the load factors of [process]
(``Scene.nonlinear``; ``Scene.hill79()`` is its material), or the sheet drawn by the rigid tools
of [tools] (``Scene.tools``; its kinds: shellform.tools.kinds).

The Scene that holds these sections is read and checked in shellform.scene.read (the checks:
shellform.scene.checks, shellform.scene.machine); a changed scene is a new one, made by
``Scene.changed`` and checked again. See docs/scenes.md for every key.
"""

import math
import re
from dataclasses import dataclass, field, fields, make_dataclass

from shellform.material import criteria
from shellform.mesh import outline
from shellform.tools import kinds as tool_kinds

__all__ = ["LOAD_STEP_KEYS", "STROKE_STEP_KEYS", "TOOL_SHAPES", "SPREADS", "HOLDERS",
           "SUPPORTS", "NONLINEAR_SUPPORTS", "SIDES", "MIRROR_SUPPORTS",
           "MAY_BE_INFINITE", "REGIONS", "CIRCLE_REGIONS", "MESH_KINDS", "DIAGONALS", "HARDENING", "CURVE_PARAMETERS",
           "YIELD_FUNCTIONS", "YIELD_PARAMETERS", "ANISOTROPY_PARAMETERS", "ANISOTROPY_LISTS",
           "Geometry", "Surface", "MeshSpec", "Material", "PointLoad", "EdgeMoment", "Loads", "Solver", "Process",
           "Drawbead", "ToolsSpec", "Probe", "Output", "bounds"]

# [process]: a sheet scene steps its load factor, a tool scene the punch's travel in mm
LOAD_STEP_KEYS = ("initial_step", "min_step", "max_step")
STROKE_STEP_KEYS = ("initial_step_mm", "min_step_mm", "max_step_mm")
TOOL_SHAPES = tool_kinds.SHAPES  # tools.shape: the registered kinds of tools (shellform.tools.kinds)
SPREADS = ("area", "rigid")  # the blank holder's spread of its force (shellform/contact/holder_split.py SPREAD_RULES)
HOLDERS = ("force", "gap")  # the blank holder presses with a force, or is held at a gap over the die

SUPPORTS = ("simply_supported", "clamped", "symmetry", "free", "clamped_sliding")
NONLINEAR_SUPPORTS = ("clamped_sliding",)  # only the nonlinear sheet knows these (shellform/supports.py)
SIDES = ("left", "right", "bottom", "top")
PRESSURE_PER = ("plan", "surface")  # the pressure per unit plan area or per unit area of the curved surface
# what a mirror line needs (u_n = 0, w,n = 0; shellform/supports.py): symmetry, or a support holding more
MIRROR_SUPPORTS = ("symmetry", "clamped", "clamped_sliding")
MAY_BE_INFINITE = ("surface.R1", "surface.R2")  # inf: flat along that direction
REGIONS = ("full", "quarter")  # rectangle
CIRCLE_REGIONS = ("full", "half", "quarter")
MESH_KINDS = ("structured", "unstructured")
DIAGONALS = ("right", "left", "crossed", "right/left", "left/right")
HARDENING = ("none", "power", "swift", "voce", "swift_voce", "table")
# the [material] keys of each yield function, as its file declares them (shellform.material.criteria)
YIELD_PARAMETERS = {name: criterion.PARAMETERS for name, criterion in criteria.CRITERIA.items()}
YIELD_FUNCTIONS = tuple(YIELD_PARAMETERS)
CURVE_PARAMETERS = {"none": (), "power": ("yield_stress", "n"), "swift": ("K", "eps0", "n"),
                    "voce": ("yield_stress", "Q", "beta"),
                    "swift_voce": ("K", "eps0", "n", "yield_stress", "Q", "beta", "swift_weight"),
                    "table": ("flow_curve", "extrapolation")}


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
    hardening: str = "none"  # one of HARDENING; its parameters: CURVE_PARAMETERS
    yield_stress: float = 0.0  # power law: sigma_y; Voce: sigma0 (0: unset), MPa
    n: float = 0.0  # power law: n > 1; Swift: n >= 0
    K: float = 0.0  # Swift: sigma_bar = K (eps0 + p)^n (0: unset), MPa
    eps0: float = 0.0  # Swift (0: unset)
    Q: float = 0.0  # Voce: sigma_bar = sigma0 + Q (1 - exp(-beta p)), MPa
    beta: float = 0.0  # Voce (0: unset)
    swift_weight: float = 0.0  # Swift-Voce: w Swift + (1 - w) Voce, 0 < w < 1 (0: unset)
    flow_curve: str = ""  # table: a CSV file of (plastic strain, true stress MPa), relative to the scene
    extrapolation: str = ""  # table: beyond its last point, one of flow_curve.EXTRAPOLATIONS
    forming_limit_curve: str = ""  # a CSV of (minor, major) true strains, relative to the scene (results/fld.py)
    r: float = 1.0  # Lankford coefficient of Hill 1979 (> 0; != 1 needs 'anisotropy')
    m: float = 2.0  # Hill 1979 exponent (>= 1; != 2 needs 'anisotropy')
    yield_function: str = "hill79"  # one of YIELD_FUNCTIONS (shellform.material.criteria); others need 'anisotropy'
    rolling_direction: float = 0.0  # degrees from the x axis to the rolling direction (needs 'anisotropy')
    r0: float = 0.0  # hill48, yld2000: Lankford coefficients at 0, 45, 90 degrees to the rolling direction
    r45: float = 0.0  # (0: unset)
    r90: float = 0.0
    r_b: float = 0.0  # yld2000: the balanced-biaxial strain ratio dep22/dep11
    sigma0: float = 0.0  # hill48 (instead of r0, r45, r90), yld2000: uniaxial yield stresses at 0, 45, 90
    sigma45: float = 0.0  # degrees and the balanced-biaxial one, MPa (only their ratios count; 0: unset)
    sigma90: float = 0.0
    sigma_b: float = 0.0
    alpha: list[float] = field(default_factory=list, metadata={"items": "numbers"})  # yld2000: alpha1..alpha8
    # yld2000, least squares (with sigma_b, r_b): angles to the rolling direction (degrees, 0 among them),
    # the r value and the uniaxial yield stress at each (MPa; only the ratios to the one at 0 count)
    fit_angles: list[float] = field(default_factory=list, metadata={"items": "numbers"})
    fit_r: list[float] = field(default_factory=list, metadata={"items": "numbers"})
    fit_sigma: list[float] = field(default_factory=list, metadata={"items": "numbers"})
    a: float = 0.0  # yld2000: the exponent (6 bcc, 8 fcc; >= 2)
    coefficients: list[float] = field(default_factory=list, metadata={"items": "numbers"})  # poly6: c1..c16


# The yield functions' keys beyond Hill 1979's r and m (which SheetMaterial takes itself): the
# numbers (0: unset) and the lists (empty: unset) that Scene.hill79 passes as yield_parameters,
# in Material's order.
_CRITERION_KEYS = {k for keys in YIELD_PARAMETERS.values() for k in keys} - {"r", "m"}
ANISOTROPY_PARAMETERS = tuple(f.name for f in fields(Material) if f.name in _CRITERION_KEYS and f.type is float)
ANISOTROPY_LISTS = tuple(f.name for f in fields(Material)
                         if f.name in _CRITERION_KEYS and getattr(f.type, "__origin__", None) is list)


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
    pressure: float = 0.0  # along +w, per unit plan area (uniform unless pressure_shape says otherwise)
    pressure_shape: str = ""  # p(x, y) = pressure * pressure_shape, an expression in x, y (forms/plan_field.py)
    pressure_per: str = "plan"  # "plan": per unit plan area; "surface": per unit area of the curved surface (self weight)
    point: list[PointLoad] = field(default_factory=list)
    moment: list[EdgeMoment] = field(default_factory=list)  # nonlinear scenes only


@dataclass
class Solver:
    mapped: bool = True  # False: no Jacobian map of the slopes (plain DOLFINx); for studies only


@dataclass
class Process:
    """Load stepping of the nonlinear sheet (shellform.nonlinear.driver); ignored by linear scenes.
    A sheet scene steps its load factor (initial_step, min_step, max_step), a tool scene the
    punch's travel in mm (initial_step_mm, min_step_mm, max_step_mm), so that its increments do
    not depend on the stroke: each kind of scene takes only its own keys."""

    thickness_points: int = 5  # Gauss points through the thickness (>= 2 with plasticity)
    initial_step: float = 0.1  # sheet scenes: first load-factor increment
    min_step: float = 1e-4  # 0 < min_step <= initial_step <= max_step <= 1
    max_step: float = 0.25
    initial_step_mm: float = 0.06  # tool scenes: first increment of the punch's travel, mm
    min_step_mm: float = 4e-4  # 0 < min_step_mm <= initial_step_mm <= max_step_mm
    max_step_mm: float = 0.24
    max_iterations: int = 12  # Newton iterations per increment (>= 1)
    rtol: float = 1e-9  # residual tolerance (> 0)
    path: list[float] = field(default_factory=lambda: [1.0])  # load factors to step through, in order
    report: list[float] = field(default_factory=list)  # load factors at which results are recorded
    springback: bool = False  # tool scenes: after the stroke the tools withdraw (contact/springback.py)
    # tool scenes with plasticity: the stroke ends where an element's margin to the forming-limit
    # curve reaches 0 (results/fld.py, FormingLimitWatch): a Nakajima test's limit dome height
    stop_at_forming_limit: bool = False
    # nonlinear scenes with plasticity: the stroke (or load path) ends where a cell's membrane
    # stability reaches 0, the onset of a neck (results/neck.py, NeckWatch); reported either way
    stop_at_neck: bool = False


@dataclass
class Drawbead:
    """A drawbead on the flange (shellform.contact.drawbead, the equivalent drawbead model): a
    polyline in the plane, its restraining force and its uplift force per unit length."""

    points: list[list[float]] = field(default_factory=list, metadata={"items": "points"})  # [x, y], mm
    restraint: float = 0.0  # N/mm, against the flow across the line
    uplift: float = 0.0  # N/mm, lifting the sheet off the die (the holder takes it)


def _tool_field(default):
    """A dataclass field of a kind's key (shellform.tools.kinds: FIELDS), a list copied per scene."""
    if isinstance(default, list):
        return field(default_factory=lambda: list(default))
    return field(default=default)


def _complete_tools(self):
    """The keys its kind derives from others (a round tool's half-width from its radius)."""
    if self.shape in tool_kinds.KINDS:
        tool_kinds.kind(self.shape).complete(self)


DRAWBEAD_PARAMETER = re.compile(r"tools\.drawbead\[(\d+)\]\.(restraint|uplift)")  # a bead's force as a sensitivity's parameter
FRICTION_TOOLS = ("punch", "die", "holder")  # each has its own key NAME_friction (unset: `friction`)
FRICTION_KEYS = ("friction",) + tuple(f"{name}_friction" for name in FRICTION_TOOLS)  # [tools]' coefficients


def _friction_per_tool(self) -> dict[str, float]:
    """Each tool's Coulomb coefficient, punch, die and holder in that order: its own key
    (punch_friction, die_friction, holder_friction), or `friction` where that is unset (None)."""
    own = {name: getattr(self, f"{name}_friction") for name in FRICTION_TOOLS}
    return {name: self.friction if v is None else v for name, v in own.items()}


# Rigid tools of cup deep drawing: tools.shape names their kind (shellform.tools.kinds: square,
# round, cad), whose keys (FIELDS) come first, then the keys every kind takes.
ToolsSpec = make_dataclass("ToolsSpec", [
    ("shape", str, field(default="square")),  # the kind of tools, one of TOOL_SHAPES
    *[(name, type(default) if not isinstance(default, list) else list[float], _tool_field(default))
      for name, default, _ in tool_kinds.fields()],
    # "force": the holder presses with blank_holder_force; "gap": its face is held at holder_gap
    ("holder", str, field(default="force")),
    ("holder_gap", float, field(default=0.0)),  # mm, holder = "gap": the face's distance from the die's top (>= t)
    ("blank_holder_force", float, field(default=19600.0)),  # N, on the whole blank (a quarter model carries a quarter)
    ("friction", float, field(default=0.0)),  # Coulomb coefficient (> 0 needs the effect 'friction')
    # a tool's own coefficient (None: unset, `friction`): a lubricated punch, a dry binder
    *[(f"{name}_friction", float | None, field(default=None)) for name in FRICTION_TOOLS],
    ("stroke", float, field(default=30.0)),  # punch travel, mm
    ("holder_spread", str, field(default="area")),  # how the closed holder spreads its force: "area" or "rigid"
    ("drawbead", list[Drawbead], field(default_factory=list, metadata={"items": "tables"})),  # [[tools.drawbead]]
], namespace={"__post_init__": _complete_tools, "friction_per_tool": _friction_per_tool,
              "__doc__": """Rigid tools of cup deep drawing: tools.shape
    names their kind (shellform.tools.kinds), whose keys come first (each kind's FIELDS), then
    the holder's, the force, friction (for all tools, and each tool's own: an optional number,
    None where unset), stroke and drawbeads every kind takes."""}, module=__name__)


@dataclass
class Probe:
    """A named vertex of the blank whose displacement (u, v, w) a nonlinear sheet scene reports
    at every report (summary.json's `probes`): a roof's free-edge midpoint, a strip's tip."""

    name: str = ""
    x: float = 0.0
    y: float = 0.0


@dataclass
class Output:
    vtx: bool = True
    vtu: bool = True  # a .pvd series: cup.pvd and the tools' (tool scenes, results/cup.py), sheet.pvd (others)
    png: bool = True
    fld: bool = True  # tool scenes with plasticity: the forming-limit view (results/fld.py)
    checkpoint_every: float = 60.0  # tool scenes: seconds of wall time between checkpoints (0: at reports only)
    probe: list[Probe] = field(default_factory=list, metadata={"items": "tables"})  # [[output.probe]]
    # nonlinear sheet scenes: the answers' derivatives in these parameters (nonlinear/sensitivity.py),
    # e.g. ["material.K", "material.n", "loads.pressure"]; scatter: a standard deviation per parameter
    # (the same order; empty: none) for the answers' first-order standard deviations
    sensitivities: list[str] = field(default_factory=list, metadata={"items": "names"})
    scatter: list[float] = field(default_factory=list, metadata={"items": "numbers"})


def bounds(s) -> tuple[float, float, float, float]:
    """x_min, x_max, y_min, y_max of the meshed region (a rectangle or circle is centred at the
    origin; a polygon is where its vertices are; a file's region is known once it is read)."""
    if s.geometry.shape in ("circle", "polygon"):
        return outline.region_bounds(s.geometry)
    hx, hy = s.geometry.lx / 2, s.geometry.ly / 2
    return (0.0, hx, 0.0, hy) if s.geometry.region == "quarter" else (-hx, hx, -hy, hy)
