"""The kind of tools "cad": the punch and the die as CAD surfaces (surface_tool.py) or surface
meshes (.stl, .msh: mesh_tool.py, by the file's suffix), placed in the scene by a rotation and
a translation (placement.py), the blank holder the flat analytic one or, held at a gap
(tools.holder = "gap"), a face from a file too (a curved binder: HolderFace); the checks of
their keys, and of their placement around the blank at the start."""

import math
from pathlib import Path

import numpy as np

from shellform.errors import InputError, require
from shellform.mesh.outline import MIRROR_NORMALS
from shellform.tools import square
from shellform.tools.analytic import BlankHolder
from shellform.tools.holder_edge import OutlineEdge, RoundedSquareEdge, signed_area
from shellform.tools.mesh_tool import MESH_SUFFIXES, MeshTool
from shellform.tools.placement import UP, Placed, rotation
from shellform.tools.protocol import BinderPlan, ram_travel
from shellform.tools.surface_tool import SurfaceTool

NAME = "cad"

FIELDS = (
    ("punch_file", "", "the punch's STEP, IGES or BREP file (or an .stl, .msh surface mesh), relative to the scene's folder"),
    ("die_file", "", "the die's"),
    ("punch_translation", [0.0, 0.0, 0.0], "mm, moving the file's frame into the scene's"),
    ("die_translation", [0.0, 0.0, 0.0], "mm"),
    ("punch_rotation", [0.0, 0.0, 0.0], "degrees, turning the file's frame about the scene's x, then y, then z "
     "(before the translation)"),
    ("die_rotation", [0.0, 0.0, 0.0], "degrees"),
    ("punch_direction", [0.0, 0.0, -1.0], "the way the punch travels"),
    ("punch_normals", "outward", "'outward' (the faces' normals point to the sheet) or 'inward'"),
    ("die_normals", "outward", "as punch_normals"),
    ("holder_file", "", "the holder's face from a file, placed resting on the sheet (holder = 'gap' only; "
     "'': the flat analytic holder)"),
    ("holder_translation", [0.0, 0.0, 0.0], "mm"),
    ("holder_rotation", [0.0, 0.0, 0.0], "degrees"),
    ("holder_normals", "outward", "as punch_normals"),
    ("binder_rise", 0.0, "how far the holder comes down with the ram before it stops at its gap (the binder "
     "wrap)"),
    ("holder_half_width", 0.0, "the holder's inner edge, a rounded square (where the die's flat top begins; "
     "0: the die's own)"),
    ("holder_corner_radius", 0.0, "its corner radius"),
)
NORMALS = ("outward", "inward")  # which way a CAD tool's faces' normals point: to the sheet, or away

LINES = square.LINES  # a cup drawn by CAD tools: the square cup's lines
RIM = False


def refuse(key: str, owners: tuple) -> str:
    return "is a key of analytic tools: shape = 'cad' takes punch_file, die_file and their placements"


def complete(spec) -> None:
    """Nothing derived."""


def picture_depth(spec) -> float:
    """The analytic tools' depth with their default profile radii (square.FIELDS): the stroke and 8 mm."""
    return spec.stroke + max(spec.punch_profile_radius, spec.die_profile_radius)


def cad_cup_tools(spec, thickness: float) -> dict:
    """Punch, die and blank holder of a scene's [tools] with shape = "cad" around a sheet of that
    thickness whose mid-surface is z = 0: the punch and the die from their files, turned by
    their rotations and moved by their translations (placement.Placed), the punch travelling
    along punch_direction. A file is a CAD model or a surface mesh by its suffix (_tool). The
    holder is the flat analytic one (tools.BlankHolder) with its face on the sheet's upper
    surface outside its inner edge: the rounded square (holder_half_width, holder_corner_radius),
    or where holder_half_width is 0 the inner boundary of the die's flat top (die_opening). It
    pinches the flange onto the die's flat top, which check_start asks to lie on the sheet's
    lower surface there. With holder_file the holder's face is that file's, placed by its
    rotation and translation resting on the sheet's upper surface (HolderFace; holder = "gap"
    only)."""
    def placed(name, axis=UP):
        path = getattr(spec, f"{name}_file")
        tool = _tool(path).from_file(path, normals=getattr(spec, f"{name}_normals"), field=f"tools.{name}_file")
        return Placed(tool, rotation(getattr(spec, f"{name}_rotation")), getattr(spec, f"{name}_translation"), axis)

    die = placed("die")
    if spec.holder_file:
        face = placed("holder")
        return dict(punch=placed("punch", -np.asarray(spec.punch_direction, dtype=float)), die=die,
                    holder=HolderFace(face.tool, face.R, face.translation, rise=spec.binder_rise))
    if spec.holder_half_width > 0:
        edge = RoundedSquareEdge(spec.holder_half_width, spec.holder_corner_radius)
    else:
        edge = die_opening(die)
    return dict(
        punch=placed("punch", -np.asarray(spec.punch_direction, dtype=float)),  # it travels -stroke along its axis
        die=die,
        holder=BlankHolder(edge, thickness / 2),
    )


class HolderFace(Placed):
    """The holder's face from a file (a CAD model or a surface mesh), placed (`translation`)
    resting on the sheet's upper surface where it closes: on the flat blank, or on the blank
    wrapped onto a curved binder, in which case it starts `rise` higher (binder_rise: it comes
    down with the ram and stops, travel.Capped). ``at_gap(gap, t)`` raises it by gap - t along
    z, its face then `gap` over the die's binder face under it (tools.holder = "gap": a third
    rigid tool). A binder of any shape: the force-controlled holder needs the flat analytic face
    (holder.py)."""

    def __init__(self, tool, rotation, translation, axis=UP, rise: float = 0.0):
        self.rise = float(rise)
        super().__init__(tool, rotation, np.asarray(translation, dtype=float) + self.rise * UP, axis)

    def at_gap(self, gap: float, thickness: float) -> "HolderFace":
        return HolderFace(self.tool, self.R, self.translation - self.rise * UP + (gap - thickness) * UP, self.axis,
                          self.rise)


def die_opening(die: Placed) -> OutlineEdge:
    """The holder's inner edge from the die: the inner boundary loop of its flat top
    (SurfaceTool.flat_top_boundary), placed, in plan; InputError naming tools.die_file where the
    die has no flat top or its top has not exactly one opening."""
    try:
        loops = die.tool.flat_top_boundary()
    except ValueError as exc:
        raise InputError("tools.die_file", f"the holder covers the die's flat top: {exc}") from None
    plans = [(loop @ die.R.T + die.translation)[:, :2] for loop in loops]
    if len(plans) != 2:
        raise InputError("tools.die_file", f"the die's flat top has {len(plans) - 1} openings: the holder's inner "
                         "edge is taken from a top with one opening (or give holder_half_width)")
    return OutlineEdge(min(plans, key=lambda p: abs(signed_area(p))))


def _tool(path):
    """The tool class of a file by its suffix: a surface mesh (.stl, .msh) a MeshTool, else a
    SurfaceTool (CAD)."""
    return MeshTool if Path(path).suffix.lower() in MESH_SUFFIXES else SurfaceTool


def read_tool_file(path, field: str):
    """A tool's file checked as a run checks it before reading it (the tool class's check_file,
    which its from_file calls first: cad_files.probe for a CAD model, mesh_files.read_surface_mesh
    for a surface mesh); `shellform check` calls it through check_files. InputError naming `field`."""
    return _tool(path).check_file(Path(path), field)


def check_files(spec) -> None:
    """The punch's and the die's files checked as a run checks them (read_tool_file), before
    anything is computed: `shellform check` refuses what `shellform run` refuses."""
    for name in ("punch", "die", "holder"):
        if name != "holder" or spec.holder_file:
            read_tool_file(getattr(spec, f"{name}_file"), f"tools.{name}_file")


class ToolSymmetryWarning(UserWarning):
    """A tool is not mirror-symmetric about a symmetry line of the modelled blank."""


MIRROR_TOLERANCE = 1e-9  # the largest difference of the distances (per mm of the tool's size) at mirror points


def check_mirrors(tools: dict, x, planes, comm) -> dict:
    """Whether the punch and the die are symmetric about the blank's mirror planes through the
    z axis (planes: their unit normals, (1, 0, 0) for x = 0): at the blank's nodes x and their
    mirror images M x, a symmetric tool's distances are equal, d(M x) = d(x). (Its normals are
    mirror images too, except where two faces are equally near, whose normal either face may
    give: the distances are compared.) Where they differ by more than MIRROR_TOLERANCE of the
    tools' extent (a surface mesh triangulated without that symmetry, a tool off the centre), a
    ToolSymmetryWarning names the tool's file: the symmetry lines then carry a force of the
    order of the normals' difference times the tool's force. Returns the largest difference
    (mm) per tool, all ranks."""
    import warnings

    from mpi4py import MPI

    x = np.asarray(x, dtype=float).reshape(-1, 3)
    size = comm.allreduce(float(np.abs(x).max(initial=0.0)), op=MPI.MAX)
    worst = {}
    for name in ("punch", "die", "holder"):
        if name == "holder" and not isinstance(tools[name], HolderFace):
            continue
        tool, largest = tools[name], 0.0
        g = tool.gap(x, 0.0, 0.0)[0]
        for m in planes:
            gm = tool.gap(x @ (np.eye(3) - 2.0 * np.outer(m, m)), 0.0, 0.0)[0]
            both = np.isfinite(g) & np.isfinite(gm)
            largest = max(largest, float(np.abs(gm[both] - g[both]).max(initial=0.0)))
        worst[name] = comm.allreduce(largest, op=MPI.MAX)
        if worst[name] > MIRROR_TOLERANCE * max(size, 1.0):
            warnings.warn(ToolSymmetryWarning(
                f"tools.{name}_file: the {name} is not mirror-symmetric about the blank's symmetry lines: its "
                f"distances at mirror points differ by up to {worst[name]:.2g} mm. The modelled part's symmetry lines "
                "then carry a force; model the whole blank, or give a surface meshed with the symmetry"), stacklevel=2)
    return worst


def check_start(tools: dict, x, half, comm, tolerance: float) -> None:
    """The CAD tools around the blank at the start (x: its nodes, half: their half thicknesses,
    every rank its own): InputError naming the field where

    - a tool's faces' normals point away from the sheet: every node lies behind the tool's
      surface (tools.punch_normals, tools.die_normals);
    - a tool overlaps the blank: a node penetrates it by more than `tolerance`
      (tools.punch_translation, tools.die_translation);
    - the die's top under the holder is not flat on the sheet's lower surface: the holder pinches
      the flange onto it (tools.die_translation where it lies off the sheet by more than
      `tolerance`, tools.holder_half_width where its normal is not +z: the holder's plan reaches
      over the die's shoulder)."""
    from mpi4py import MPI

    x = np.asarray(x, dtype=float).reshape(-1, 3)
    for name in ("punch", "die"):
        g, _ = tools[name].gap(x, half, 0.0)
        highest = comm.allreduce(float(g.max(initial=-np.inf)), op=MPI.MAX)
        deepest = comm.allreduce(float(g.min(initial=np.inf)), op=MPI.MIN)
        if highest < -tolerance:
            raise InputError(f"tools.{name}_normals", f"the {name}'s faces' normals point away from the sheet: "
                             "every node of the blank lies behind its surface (turn them with "
                             f"{name}_normals = 'inward', or 'outward' if that was set)")
        if deepest < -tolerance:
            raise InputError(f"tools.{name}_translation", f"the {name} overlaps the blank at the start: a node "
                             f"penetrates it by {-deepest:.4g} mm (more than {tolerance:g} mm)")
    if isinstance(tools["holder"], HolderFace):  # a binder face of any shape, held at a gap
        _check_face_start(tools["holder"], x, half, comm, tolerance)
        return
    under = np.isfinite(tools["holder"].gap(x, 0.0, 0.0)[0])
    if comm.allreduce(int(under.sum()), op=MPI.SUM) == 0:
        raise InputError("geometry", "the blank does not reach the blank holder: no node of it lies over the die's "
                                     "flat top, where the holder pinches the flange")
    g, n = tools["die"].gap(x[under], half[under] if np.ndim(half) else half, 0.0)
    off = comm.allreduce(float(np.abs(g).max(initial=0.0)), op=MPI.MAX)
    tilt = comm.allreduce(float(np.abs(n[:, 2] - 1.0).max(initial=0.0)), op=MPI.MAX)
    if tilt > 1e-9:
        raise InputError("tools.holder_half_width", "the holder reaches over a part of the die that is not its flat "
                         "top (the die's normal there is not +z): the holder's inner edge must lie on the flat top")
    if off > tolerance:
        raise InputError("tools.die_translation", f"the die's flat top under the holder lies {off:.4g} mm off the "
                         "sheet's lower surface z = -t/2: the holder pinches the flange onto it")


def _check_face_start(face, x, half, comm, tolerance: float) -> None:
    """A holder's face from a file at the start: its normals point to the sheet
    (tools.holder_normals), it overlaps no node (tools.holder_translation; tools.binder_rise
    where it starts raised) and, where it closes on the flat blank (no rise), it rests on it:
    some node lies within `tolerance` of it (tools.holder_translation)."""
    from mpi4py import MPI

    g, _ = face.gap(x, half, 0.0)
    highest = comm.allreduce(float(g.max(initial=-np.inf)), op=MPI.MAX)
    deepest = comm.allreduce(float(g.min(initial=np.inf)), op=MPI.MIN)
    if highest < -tolerance:
        raise InputError("tools.holder_normals", "the holder's faces' normals point away from the sheet: every node "
                         "of the blank lies behind its surface (turn them with holder_normals)")
    if deepest < -tolerance:
        field = "tools.binder_rise" if face.rise > 0 else "tools.holder_translation"
        raise InputError(field, f"the holder's face overlaps the blank at the start: a node penetrates it by "
                         f"{-deepest:.4g} mm (more than {tolerance:g} mm)" + (
                             f"; binder_rise ({face.rise:g} mm) must lift it clear of the flat blank" if face.rise > 0
                             else ""))
    if face.rise == 0 and deepest > tolerance:
        raise InputError("tools.holder_translation", f"the holder's face does not rest on the blank: the nearest node "
                         f"lies {deepest:.4g} mm from it (place it on the sheet's upper surface; holder_gap lifts it)")


tools = cad_cup_tools


travel = ram_travel  # a holder's face from a file that starts raised comes down by binder_rise and stops


def check_placement(tools: dict, x, half, planes, comm, tolerance: float) -> None:
    """The tools around the blank's nodes x at the start (check_start) and their symmetry about
    the blank's mirror planes (check_mirrors: a warning)."""
    check_start(tools, x, half, comm, tolerance)
    check_mirrors(tools, x, np.array(planes), comm)


def check(s) -> BinderPlan:
    """CAD tools: their files exist (what they hold is checked when they are read:
    surface_tool.py, mesh_tool.py), their placements, the punch's travel and the holder's inner
    edge; returns where the die's flat top begins (holder_half_width)."""
    t = s.tools
    for name in ("punch_file", "die_file", "holder_file"):
        v = getattr(t, name)
        if name == "holder_file" and not v:
            continue
        require(bool(v), f"tools.{name}",
                "shape = 'cad' needs the tool's STEP, IGES or BREP file (or .stl, .msh surface mesh)")
        require(Path(v).is_file(), f"tools.{name}", f"no such file: {v}")
    for name, what in (("punch_translation", "[x, y, z] (mm)"), ("die_translation", "[x, y, z] (mm)"),
                       ("holder_translation", "[x, y, z] (mm)"), ("punch_rotation", "angles about x, y, z (degrees)"),
                       ("die_rotation", "angles about x, y, z (degrees)"),
                       ("holder_rotation", "angles about x, y, z (degrees)"), ("punch_direction", "[x, y, z]")):
        v = getattr(t, name)
        require(len(v) == 3 and all(isinstance(c, (int, float)) and math.isfinite(c) for c in v), f"tools.{name}",
                f"must be three finite numbers {what}, got {v}")
    d = np.asarray(t.punch_direction, dtype=float)
    require(np.linalg.norm(d) > 0, "tools.punch_direction", "must be a non-zero vector, the way the punch travels")
    require(d[2] < 0, "tools.punch_direction", f"must point down into the die (a negative z component): the punch "
                                               f"draws the sheet into the die below it, got {t.punch_direction}")
    for name in ("punch_normals", "die_normals", "holder_normals"):
        require(getattr(t, name) in NORMALS, f"tools.{name}",
                f"must be one of {NORMALS}, got {getattr(t, name)!r}")
    require(math.isfinite(t.binder_rise) and t.binder_rise >= 0, "tools.binder_rise",
            f"must be >= 0, got {t.binder_rise}")
    require(t.binder_rise == 0 or t.holder_file, "tools.binder_rise",
            "a holder that comes down onto a curved binder takes its face from a file (holder_file)")
    require(t.stroke > t.binder_rise, "tools.stroke",
            f"must exceed binder_rise ({t.binder_rise}): the ram closes the holder first, got {t.stroke}")
    require(not t.holder_file or t.holder == "gap", "tools.holder_file",
            "a holder's face from a file is held at a gap (tools.holder = 'gap'): the force-controlled holder pinches "
            "the flange with the flat analytic face")
    require(math.isfinite(t.holder_half_width) and t.holder_half_width >= 0, "tools.holder_half_width",
            f"must be >= 0: the holder's inner edge (where the die's flat top begins), 0 for the die's own, got "
            f"{t.holder_half_width}")
    require(math.isfinite(t.holder_corner_radius) and 0 <= t.holder_corner_radius <= t.holder_half_width,
            "tools.holder_corner_radius", f"must lie in [0, holder_half_width], got {t.holder_corner_radius}")
    _check_punch_travel(s, t)
    return BinderPlan(t.holder_half_width, t.holder_corner_radius, "holder_half_width")


def _check_punch_travel(s, t) -> None:
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
