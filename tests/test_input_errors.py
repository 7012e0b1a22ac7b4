"""Bad input gets a clear error naming the field, before any computation."""

import tomllib
from pathlib import Path

import pytest
from dolfinx import mesh
from mpi4py import MPI

from shellform import cli, scene
from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly.kernels import HybridShellForms
from shellform.errors import InputError
from shellform.linear import parameters


def assert_names_field(data: dict, field: str) -> None:
    """The scene `data` is rejected with an InputError whose field (and message prefix) is `field`."""
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert err.value.field == field
    assert str(err.value).startswith(field + ":")


@pytest.mark.parametrize("data, field", [
    ({"material": {"thickness": -0.1}}, "material.thickness"),
    ({"material": {"thickness": 0.0}}, "material.thickness"),
    ({"material": {"E": 0.0}}, "material.E"),
    ({"material": {"nu": 0.5}}, "material.nu"),
    ({"material": {"nu": -1.0}}, "material.nu"),
    ({"material": {"E": "steel"}}, "material.E"),
    ({"supports": {"left": "pinned"}}, "supports.left"),
    ({"supports": {"front": "clamped"}}, "supports.front"),
    ({"effects": ["bending", "plasticity"]}, "effects"),
    ({"effects": ["bending", "shallow_curvature"]}, "effects"),
    ({"surface": {"R1": 3.0}}, "surface.R1"),
    ({"surface": {"R2": 0.0}, "effects": ["bending", "membrane", "shallow_curvature"]}, "surface.R2"),
    ({"surface": {"z0": "sin(x, y)"}, "effects": ["bending", "membrane", "shallow_curvature"]}, "surface.z0"),
    ({"surface": {"z0": "sqrt()"}, "effects": ["bending", "membrane", "shallow_curvature"]}, "surface.z0"),
    ({"mesh": {"n": 0}}, "mesh.n"),
    ({"mesh": {"refine": -1}}, "mesh.refine"),
    ({"mesh": {"refine": 1.5}}, "mesh.refine"),
    ({"mesh": {"kind": "quad"}}, "mesh.kind"),
    ({"geometry": {"lx": -1.0}}, "geometry.lx"),
    ({"loads": {"point": [{"x": 5.0, "y": 0.0, "fz": 1.0}]}}, "loads.point[0]"),
    ({"loads": {"pressure": 1.0}, "effects": ["membrane"]}, "loads"),
    ({"materials": {}}, "materials"),
])
def test_scene_errors_name_the_field(data, field):
    assert_names_field(data, field)


FULL = ["bending", "membrane"]
SHEET = FULL + ["geometric_nonlinearity"]
PLASTIC = SHEET + ["plasticity"]
POWER = {"hardening": "power", "yield_stress": 2.0e-3, "n": 5.0}


@pytest.mark.parametrize("data, field", [
    ({"effects": FULL + ["hyperelasticity"]}, "effects"),
    ({"effects": ["membrane", "geometric_nonlinearity"]}, "effects"),  # the sheet is a full shell
    ({"effects": SHEET + ["anisotropy"]}, "effects"),  # anisotropy without plasticity
    ({"effects": SHEET + ["finite_strain"]}, "effects"),  # logarithmic strains of no plastic layers
    ({"effects": FULL + ["plasticity", "finite_strain"], "material": POWER}, "effects"),  # no large displacements
    ({"effects": PLASTIC}, "material.hardening"),  # plasticity without a curve
    ({"effects": SHEET, "material": POWER}, "material.hardening"),  # a curve without plasticity
    ({"effects": PLASTIC + ["anisotropy"], "material": {**POWER, "r": 0.0}}, "material.r"),
    ({"effects": PLASTIC + ["anisotropy"], "material": {**POWER, "r": -1.5}}, "material.r"),
    ({"material": {"r": 0.0}}, "material.r"),  # r > 0 even without plasticity
    ({"effects": PLASTIC + ["anisotropy"], "material": {**POWER, "m": 0.5}}, "material.m"),
    ({"material": {"m": 0.5}}, "material.m"),
    ({"effects": PLASTIC, "material": {**POWER, "r": 1.5}}, "material.r"),  # r != 1 without anisotropy
    ({"effects": PLASTIC, "material": {**POWER, "m": 8.0}}, "material.m"),
    ({"effects": PLASTIC, "material": {"hardening": "power", "n": 5.0}}, "material.yield_stress"),
    ({"effects": PLASTIC, "material": {"hardening": "power", "yield_stress": 2.0e-3}}, "material.n"),
    ({"effects": PLASTIC, "material": {**POWER, "yield_stress": -1.0}}, "material.yield_stress"),
    ({"effects": PLASTIC, "material": {"hardening": "swift", "eps0": 0.01, "n": 0.2}}, "material.K"),
    ({"effects": PLASTIC, "material": {"hardening": "swift", "K": 1.0, "n": 0.2}}, "material.eps0"),
    ({"effects": PLASTIC, "material": {**POWER, "K": 1.0}}, "material.K"),  # not a power-law parameter
    ({"effects": PLASTIC, "material": {"hardening": "ludwik"}}, "material.hardening"),
    ({"effects": PLASTIC, "material": {**POWER, "thickness": -0.01}}, "material.thickness"),
    ({"effects": PLASTIC, "material": POWER, "process": {"thickness_points": 1}}, "process.thickness_points"),
    ({"process": {"min_step": 0.2, "initial_step": 0.1}}, "process.min_step"),
    ({"process": {"initial_step": 0.5, "max_step": 0.25}}, "process.initial_step"),
    ({"process": {"max_step": 2.0}}, "process.max_step"),
    ({"process": {"min_step": 0.0}}, "process.min_step"),
    ({"process": {"max_iterations": 0}}, "process.max_iterations"),
    ({"process": {"rtol": 0.0}}, "process.rtol"),
    ({"process": {"path": []}}, "process.path"),
    ({"process": {"path": [1.0, "unload"]}}, "process.path"),
    ({"process": {"path": 1.0}}, "process.path"),
    ({"process": {"path": [1.0, 0.0], "report": [1.5]}}, "process.report"),
    ({"process": {"path": [1.0], "report": [-0.1]}}, "process.report"),
    ({"process": {"steps": 10}}, "process.steps"),
    ({"effects": SHEET, "loads": {"moment": [{"side": "front", "m": 1.0}]}}, "loads.moment[0].side"),
    ({"effects": SHEET, "loads": {"moment": [{"side": "right", "m": "big"}]}}, "loads.moment[0].m"),
    ({"effects": SHEET, "loads": {"moment": {"side": "right", "m": 1.0}}}, "loads.moment"),
    ({"effects": FULL, "loads": {"moment": [{"side": "right", "m": 1.0}]}}, "loads.moment[0]"),
    ({"loads": {"point": [{"fx": 1.0}]}}, "loads.point[0]"),  # in-plane force without membrane
    ({"effects": FULL, "supports": {"right": "clamped_sliding"}}, "supports.right"),
])
def test_nonlinear_scene_errors_name_the_field(data, field):
    assert_names_field(data, field)


def test_plasticity_without_a_curve_says_which_curves():
    with pytest.raises(InputError, match="needs a hardening curve: 'power'.*'swift'"):
        scene.from_dict({"effects": PLASTIC})


def test_elastic_plastic_anisotropic_scene():
    s = scene.from_dict({
        "title": "deep-drawing blank",
        "effects": PLASTIC + ["anisotropy"],
        "geometry": {"region": "quarter"},
        "material": {"E": 2.1e5, "nu": 0.3, "thickness": 0.8, "hardening": "swift", "K": 550.0,
                     "eps0": 0.005, "n": 0.22, "r": 1.8, "m": 6.0},
        "supports": {"left": "symmetry", "bottom": "symmetry", "right": "clamped_sliding", "top": "clamped"},
        "loads": {"pressure": 1.0, "point": [{"x": 0.0, "y": 0.0, "fx": 0.5, "fz": 1.0}],
                  "moment": [{"side": "right", "m": -2.0}]},
        "process": {"thickness_points": 7, "initial_step": 0.05, "path": [1.0, 0.0],
                    "report": [0.5, 1.0, 0.0]},
    })
    assert s.nonlinear
    assert s.loads.moment == [scene.EdgeMoment("right", -2.0)]
    assert s.process.path == [1.0, 0.0] and s.process.thickness_points == 7
    mat = s.hill79().pack()
    import numpy as np

    from shellform.material import A_, B_, C_, COS_, E_, LAW_, NU_, PAR_
    assert (mat[PAR_], mat[PAR_ + 1]) == (1.8, 6.0)  # r and m
    slots = [E_, NU_, PAR_, PAR_ + 1, LAW_, A_, B_, C_]
    assert list(mat[slots]) == [2.1e5, 0.3, 1.8, 6.0, 2.0, 550.0, 0.005, 0.22]  # law 2: Swift
    assert mat[COS_] == 1.0 and np.count_nonzero(np.delete(mat, slots + [COS_])) == 0  # rolling direction along x


def test_linear_scenes_are_not_nonlinear():
    s = scene.from_dict({"effects": FULL, "process": {"path": [0.5]}})  # [process] is allowed, ignored
    assert not s.nonlinear
    from shellform.material import LAW_
    assert s.hill79().pack()[LAW_] == 0.0  # elastic


def test_mesh_that_is_not_triangles():
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2, mesh.CellType.quadrilateral)
    s = scene.from_dict({})
    with pytest.raises(InputError, match="triangles") as err:
        HybridShellForms(msh, HybridElement(("bending",)), parameters(msh, s))
    assert err.value.field == "mesh"


def test_cli_reports_input_errors(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('effects = ["bending"]\n[material]\nthickness = -1.0\n')
    assert cli.main(["run", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "material.thickness: must be > 0" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing computed, nothing written


def test_sheet_model_checks_its_thickness():
    """The nonlinear sheet built from the API (no scene) checks the thickness too."""
    from shellform.material import Hill79Material
    from shellform.nonlinear.model import SheetModel

    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    with pytest.raises(InputError) as err:
        SheetModel(msh, Hill79Material(E=1.0, nu=0.3).pack(), -0.01)
    assert err.value.field == "material.thickness"


# -- [tools]: the square cup's rigid tools (shellform/tools/analytic.py) ------------------------
CONTACT = SHEET + ["contact"]


def cup(effects=CONTACT, tools=None, geometry=None, supports=None, thickness=0.8):
    """A quarter blank of 100 mm x 100 mm on the NUMISHEET'93 tools, with overrides."""
    return {"effects": effects, "geometry": {"lx": 100.0, "ly": 100.0, "region": "quarter", **(geometry or {})},
            "material": {"E": 2.1e5, "thickness": thickness},
            "supports": {"left": "symmetry", "bottom": "symmetry", **(supports or {})}, "tools": tools or {}}


@pytest.mark.parametrize("data, field", [
    ({"effects": CONTACT}, "tools"),  # contact without tools
    ({**cup(), "effects": SHEET}, "effects"),  # tools without contact
    (cup(effects=FULL + ["contact"]), "effects"),  # contact needs geometric_nonlinearity
    (cup(effects=SHEET + ["friction"]), "effects"),  # friction needs contact
    (cup(effects=CONTACT + ["sticking"]), "effects"),
    ({**cup(), "tools": 35.0}, "tools"),
    (cup(tools={"punch_radius": 8.0}), "tools.punch_radius"),
    (cup(tools={"stroke": "deep"}), "tools.stroke"),
    (cup(tools={"holder_spread": "thickest"}), "tools.holder_spread"),
    (cup(tools={"holder_spread": 1.0}), "tools.holder_spread"),
    (cup(tools={"stroke": 0.0}), "tools.stroke"),
    (cup(tools={"stroke": float("inf")}), "tools.stroke"),
    (cup(tools={"punch_half_width": float("nan")}), "tools.punch_half_width"),
    (cup(tools={"punch_half_width": -35.0}), "tools.punch_half_width"),
    (cup(tools={"punch_profile_radius": 0.0}), "tools.punch_profile_radius"),
    (cup(tools={"die_profile_radius": -5.0}), "tools.die_profile_radius"),
    (cup(tools={"die_half_width": 0.0}), "tools.die_half_width"),
    (cup(tools={"punch_corner_radius": -1.0}), "tools.punch_corner_radius"),
    (cup(tools={"punch_corner_radius": 6.0}), "tools.punch_corner_radius"),  # < the nose radius 8
    (cup(tools={"punch_corner_radius": 36.0}), "tools.punch_corner_radius"),  # > the half-width 35
    (cup(tools={"die_corner_radius": -1.0}), "tools.die_corner_radius"),
    (cup(tools={"die_corner_radius": 38.0}), "tools.die_corner_radius"),
    (cup(tools={"blank_holder_force": -1.0}), "tools.blank_holder_force"),
    (cup(tools={"friction": -0.1}), "tools.friction"),
    (cup(tools={"punch_half_width": 38.0}), "tools.punch_half_width"),  # wider than the die opening
    (cup(tools={"punch_half_width": 37.0}), "tools.punch_half_width"),
    (cup(tools={"die_half_width": 35.5}), "tools.die_half_width"),  # clearance 0.5 < thickness 0.8
    (cup(tools={"punch_gap": -0.1}), "tools.punch_gap"),  # the punch overlaps the blank
    (cup(geometry={"lx": 80.0}), "geometry.lx"),  # half of 80 < 37 + 5: short of the blank holder
    (cup(geometry={"ly": 84.0}), "geometry.ly"),  # just at the die's flat top
    (cup(tools={"friction": 0.1}), "tools.friction"),  # friction without the effect
    (cup(effects=CONTACT + ["friction"]), "tools.friction"),  # the effect without friction
    # friction per tool: each tool's own coefficient, where given, finite and >= 0
    *[(cup(effects=CONTACT + ["friction"], tools={"friction": 0.1, f"{tool}_friction": bad}), f"tools.{tool}_friction")
      for tool in ("punch", "die", "holder") for bad in (-0.02, float("inf"), float("nan"), "dry", True)],
    *[(cup(tools={f"{tool}_friction": 0.05}), f"tools.{tool}_friction")  # without the effect
      for tool in ("punch", "die", "holder")],
    # the effect with no tool's coefficient > 0: named tools.friction, or tools.punch_friction where
    # every tool has its own (and friction is no tool's)
    (cup(effects=CONTACT + ["friction"], tools={"punch_friction": 0.0}), "tools.friction"),
    (cup(effects=CONTACT + ["friction"], tools={"friction": 0.1, "punch_friction": 0.0, "die_friction": 0.0,
                                                 "holder_friction": 0.0}), "tools.punch_friction"),
    (cup(supports={"right": "clamped"}), "supports.right"),
    (cup(supports={"top": "simply_supported"}), "supports.top"),
    (cup(geometry={"region": "full"}), "supports.left"),  # every side of a full blank is outer
    # a tool scene steps the punch's travel in mm, a sheet scene its load factor
    ({**cup(), "process": {"max_step": 0.01}}, "process.max_step"),
    ({"process": {"max_step_mm": 0.2}}, "process.max_step_mm"),
    ({**cup(), "process": {"min_step_mm": 0.5, "initial_step_mm": 0.1}}, "process.min_step_mm"),
    ({**cup(), "process": {"initial_step_mm": 0.5, "max_step_mm": 0.25}}, "process.initial_step_mm"),
    ({**cup(), "process": {"min_step_mm": 0.0}}, "process.min_step_mm"),
    ({**cup(), "process": {"max_step_mm": float("inf")}}, "process.max_step_mm"),
])
def test_tools_errors_name_the_field(data, field):
    assert_names_field(data, field)


def test_a_tool_scene_gives_its_steps_in_mm():
    with pytest.raises(InputError, match=r"steps the punch's travel in mm: give process.max_step_mm"):
        scene.from_dict({**cup(), "process": {"max_step": 0.01}})
    with pytest.raises(InputError, match=r"is a key of tool scenes .* process.initial_step$"):
        scene.from_dict({"process": {"initial_step_mm": 0.1}})


def test_tools_error_messages():
    with pytest.raises(InputError, match="must fit in the die opening"):
        scene.from_dict(cup(tools={"punch_half_width": 38.0}))
    with pytest.raises(InputError, match="cannot pass"):
        scene.from_dict(cup(tools={"die_half_width": 35.5}))
    with pytest.raises(InputError, match="overlap the blank"):
        scene.from_dict(cup(tools={"punch_gap": -0.1}))
    with pytest.raises(InputError, match="does not reach the blank holder"):
        scene.from_dict(cup(geometry={"lx": 80.0}))


def test_square_cup_scene():
    from shellform.tools.square import square_cup_tools

    s = scene.from_dict(cup(effects=CONTACT + ["friction"], tools={"friction": 0.144, "stroke": 15}))
    assert s.nonlinear and s.tools.friction == 0.144 and s.tools.stroke == 15.0
    assert s.tools.punch_half_width == 35.0 and s.tools.die_profile_radius == 5.0  # the defaults
    tools = square_cup_tools(s.tools, s.material.thickness)
    assert (tools["punch"].z_face, tools["die"].z_top) == (0.4, -0.4)
    full = scene.from_dict(cup(geometry={"region": "full"}, supports={"left": "free", "bottom": "free"}))
    assert full.tools == scene.ToolsSpec()
    assert scene.from_dict({}).tools is None  # no [tools] table: no tools


def test_a_mesh_too_large_for_the_machine_is_refused_before_it_is_built(monkeypatch):
    """mesh.n = 20000 on the square plate would make 8e8 cells: refused naming mesh.n with its
    estimated cells and memory; under a 1 GB limit even a 400 x 400 quarter is refused."""
    from shellform.mesh import budget

    with pytest.raises(InputError) as err:
        scene.from_dict({"mesh": {"n": 20000}})
    assert err.value.field == "mesh.n" and "800,000,000 cells" in str(err.value) and "GB" in str(err.value)
    scene.from_dict({"mesh": {"n": 400}})  # 320,000 cells: about 2.5 GB, fits
    monkeypatch.setattr(budget, "available_bytes", lambda: 1e9)
    with pytest.raises(InputError) as err:
        scene.from_dict({"mesh": {"n": 400}})
    assert err.value.field == "mesh.n" and "320,000 cells" in str(err.value)


@pytest.mark.parametrize("kind, region, n, refine", [("structured", "quarter", 7, 1), ("structured", "full", 6, 0),
                                                     ("unstructured", "quarter", 8, 0)])
def test_estimated_cells_match_the_built_mesh(kind, region, n, refine):
    from shellform.mesh import budget, rectangle

    built = rectangle(MPI.COMM_WORLD, 2.0, 1.5, region=region, kind=kind, n=n, refine=refine).mesh
    cells = built.topology.index_map(2).size_global
    estimate = budget.estimated_cells(2.0, 1.5, region, kind, n, refine)
    assert estimate == cells if kind == "structured" else abs(estimate - cells) <= 0.2 * cells


def test_cubic_membrane_on_a_supported_curved_edge_names_effects():
    """cubic_membrane holds supports along x and y only: a circle with a supported rim is refused,
    naming `effects`, before the forms are compiled."""
    from shellform import linear

    s = scene.from_dict({"effects": ["bending", "membrane", "cubic_membrane"],
                         "geometry": {"shape": "circle", "radius": 1.0, "region": "quarter"},
                         "mesh": {"kind": "unstructured", "n": 4},
                         "supports": {"rim": "clamped", "left": "symmetry", "bottom": "symmetry"}})
    with pytest.raises(InputError) as err:
        linear.solve(s)
    assert err.value.field == "effects"


# -- issue 30: symmetry lines, the thickness points' memory, non-finite numbers, polygons ------
SQUARE_CUP = Path(__file__).resolve().parents[1] / "demos" / "square_cup.toml"
DISC = {"shape": "circle", "radius": 1.0}


def square_cup(supports=None, process=None) -> dict:
    """demos/square_cup.toml as parsed TOML, with its [supports] (or [process]) replaced."""
    data = tomllib.loads(SQUARE_CUP.read_text())
    if supports is not None:
        data["supports"] = supports
    data["process"] = {**data.get("process", {}), **(process or {})}
    return data


@pytest.mark.parametrize("data, field", [
    (square_cup(supports={}), "supports.left"),  # the quarter cup without its symmetry lines
    (square_cup(supports={"left": "free", "bottom": "free"}), "supports.left"),
    (square_cup(supports={"left": "symmetry"}), "supports.bottom"),
    ({"geometry": {"region": "quarter"}, "supports": {"left": "symmetry", "bottom": "simply_supported"}},
     "supports.bottom"),  # a hinge on the mirror line
    ({"geometry": {**DISC, "region": "half"}, "mesh": {"kind": "unstructured"}, "supports": {"rim": "clamped"}},
     "supports.bottom"),
    ({"geometry": {**DISC, "region": "quarter"}, "mesh": {"kind": "unstructured"},
      "supports": {"rim": "clamped", "bottom": "symmetry"}}, "supports.left"),
])
def test_a_half_or_quarter_needs_its_symmetry_lines(data, field):
    assert_names_field(data, field)
    with pytest.raises(InputError, match="mirrored across this edge.*needs 'symmetry'"):
        scene.from_dict(data)


def test_a_clamped_mirror_line_is_a_symmetric_model():
    """Clamped (or clamped_sliding) holds all a mirror line needs: the whole blank clamped along it."""
    s = scene.from_dict({"geometry": {"region": "quarter"}, "supports": {"left": "clamped", "bottom": "symmetry"}})
    assert s.symmetry_copies == 4
    scene.from_dict({"effects": SHEET, "geometry": {"region": "quarter"},
                     "supports": {"left": "clamped_sliding", "bottom": "symmetry"}})


def test_demo_scenes_still_validate():
    for path in sorted(SQUARE_CUP.parent.glob("*.toml")):
        scene.load(path)


@pytest.mark.parametrize("thickness_points, field", [(1_000_000, "process.thickness_points"), (50, None)])
def test_thickness_points_are_bounded_by_the_memory_budget(thickness_points, field):
    """A million points through the thickness: numpy's Gauss rule alone asks for 7.28 TiB; refused
    before anything is built, naming process.thickness_points; 50 points fit."""
    data = square_cup(process={"thickness_points": thickness_points})
    if field is None:
        assert scene.from_dict(data).process.thickness_points == thickness_points
        return
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert err.value.field == field and "1,000,000 points through the thickness" in err.value.message
    assert "GB" in err.value.message


@pytest.mark.timeout(20)
def test_thickness_points_that_fit_in_memory_are_bounded_in_time():
    """5,000 points fit the memory budget, but numpy's rule of n points costs n^3 (10,000 took
    minutes): refused at once naming process.thickness_points; 1,000 are taken."""
    with pytest.raises(InputError) as err:
        scene.from_dict(square_cup(process={"thickness_points": 5000}))
    assert err.value.field == "process.thickness_points" and "<= 1000" in err.value.message
    assert scene.from_dict(square_cup(process={"thickness_points": 1000})).process.thickness_points == 1000


INF, NAN = float("inf"), float("nan")


@pytest.mark.parametrize("data, field", [
    ({"material": {"thickness": INF}}, "material.thickness"),
    ({"material": {"thickness": NAN}}, "material.thickness"),
    ({"material": {"E": INF}}, "material.E"),
    ({"material": {"nu": NAN}}, "material.nu"),
    ({"material": {"r": INF}}, "material.r"),
    ({"material": {"m": INF}}, "material.m"),
    ({"effects": PLASTIC, "material": {**POWER, "yield_stress": INF}}, "material.yield_stress"),
    ({"geometry": {"lx": INF}}, "geometry.lx"),
    ({"geometry": {**DISC, "radius": INF}, "mesh": {"kind": "unstructured"}}, "geometry.radius"),
    ({"geometry": {"shape": "polygon", "vertices": [[0, 0], [1, 0], [0, INF]]}, "mesh": {"kind": "unstructured"}},
     "geometry.vertices"),
    ({"loads": {"pressure": NAN}}, "loads.pressure"),
    ({"loads": {"point": [{"x": 0.0, "fz": INF}]}}, "loads.point[0].fz"),
    ({"process": {"max_step": INF}}, "process.max_step"),
    ({"process": {"rtol": NAN}}, "process.rtol"),
    ({"process": {"path": [1.0, INF]}}, "process.path"),
    ({"process": {"report": [INF]}}, "process.report"),
    (cup(tools={"stroke": INF}), "tools.stroke"),
])
def test_inf_and_nan_must_be_finite(data, field):
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert (err.value.field, err.value.message.split(",")[0]) == (field, "must be finite")


def test_a_flat_surface_may_have_infinite_radii_but_not_nan():
    assert scene.from_dict({"surface": {"R1": INF, "R2": INF}}).kappa0 == (0.0, 0.0)
    assert_names_field({"surface": {"R1": NAN}}, "surface.R1")


@pytest.mark.parametrize("vertices", [
    [[0, 0], [4, 0], [4, 3], [2, 0], [0, 3]],  # vertex 3 on edge 1: two triangles pinched at a point
    [[0, 0], [2, 0], [2, 2], [1, 0]],  # edge 4 runs back along edge 1
    [[0, 0], [4, 0], [4, 4], [0, 0.0], [-1, 2]],  # vertex 3 repeats vertex 0
])
def test_a_polygon_vertex_on_another_edge_names_geometry_vertices(vertices):
    with pytest.raises(InputError, match="lies on edge") as err:
        scene.from_dict({"geometry": {"shape": "polygon", "vertices": vertices}, "mesh": {"kind": "unstructured"}})
    assert err.value.field == "geometry.vertices"


def test_sheet_model_says_an_infinite_thickness_must_be_finite():
    from shellform.material import Hill79Material
    from shellform.nonlinear.model import SheetModel

    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    with pytest.raises(InputError, match="material.thickness: must be finite, got inf"):
        SheetModel(msh, Hill79Material(E=1.0, nu=0.3).pack(), float("inf"))

@pytest.mark.parametrize("value", [-1.0, float("inf"), float("nan")])
def test_checkpoint_interval_names_its_field(value):
    assert_names_field({"output": {"checkpoint_every": value}}, "output.checkpoint_every")


DEMOS = Path(__file__).resolve().parents[1] / "demos"


def test_friction_per_tool_keys():
    """tools.punch_friction, die_friction and holder_friction: unset (None), each tool carries
    tools.friction; given, its own (0 too: a lubricated punch with a dry binder); the effect
    'friction' with friction 0 but one tool's > 0 is valid. An unset key is not written to the
    resolved TOML, and a change to None unsets it again."""
    s = scene.from_dict(cup(effects=CONTACT + ["friction"], tools={"friction": 0.1}))
    assert (s.tools.punch_friction, s.tools.die_friction, s.tools.holder_friction) == (None, None, None)
    assert s.tools.friction_per_tool() == {"punch": 0.1, "die": 0.1, "holder": 0.1}
    lubricated = s.changed({"tools.punch_friction": 0, "tools.holder_friction": 0.15})
    assert lubricated.tools.friction_per_tool() == {"punch": 0.0, "die": 0.1, "holder": 0.15}
    assert isinstance(lubricated.tools.punch_friction, float)
    only = scene.from_dict(cup(effects=CONTACT + ["friction"], tools={"die_friction": 0.1}))
    assert only.tools.friction_per_tool() == {"punch": 0.0, "die": 0.1, "holder": 0.0}
    text = scene.to_toml(lubricated)
    assert "punch_friction = 0.0" in text and "die_friction" not in text
    assert scene.from_dict(tomllib.loads(text)) == lubricated
    assert lubricated.changed({"tools.punch_friction": None}).tools.punch_friction is None


def test_an_implausible_modulus_is_warned_about_naming_the_field():
    """E in GPa with the stresses in MPa (E = 206 for a steel) is valid input but no metal: a
    warning names material.E with the ratio; the demo scenes' materials give none."""
    import warnings

    from shellform.scene.checks import PlausibilityWarning

    with pytest.warns(PlausibilityWarning, match=r"material\.E: E / initial yield stress = 1\.31, where"):
        scene.load(DEMOS / "square_cup.toml").changed({"material.E": 206.0})
    for name in ("square_cup.toml", "numisheet93_aluminium.toml", "numisheet93_steel.toml", "round_cup.toml"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", PlausibilityWarning)
            scene.load(DEMOS / name)


@pytest.mark.parametrize("changes, match", [
    ({"tools.punch_gap": 40.0}, r"tools\.punch_gap: the punch starts 40 mm above the sheet and travels 30 mm"),
    ({"effects": ["bending", "membrane", "geometric_nonlinearity", "plasticity", "anisotropy", "finite_strain",
                  "contact", "friction", "drawbeads"],
      "tools.drawbead": [{"points": [[200.0, 0.0], [200.0, 75.0]], "restraint": 60.0}]},
     r"tools\.drawbead\[0\]: lies wholly outside the blank"),
    ({"mesh.n": 1}, r"mesh\.n: n = 1"),
    ({"tools.friction": 10.0}, r"tools\.friction: 10 is no friction coefficient of sheet metal"),
    *[({f"tools.{tool}_friction": 10.0}, rf"tools\.{tool}_friction: 10 is no friction coefficient of sheet metal")
      for tool in ("punch", "die", "holder")],
])
def test_valid_but_useless_values_are_warned_about_naming_the_field(changes, match):
    """A punch that never reaches the sheet (a gap larger than the stroke: zero force, exit 0), a
    drawbead wholly outside the blank, one cell per side, a friction coefficient of 10: valid, so
    warned about (PlausibilityWarning naming the field); the demo scene gives none."""
    import warnings

    from shellform.scene.checks import PlausibilityWarning

    s = scene.load(DEMOS / "square_cup.toml")
    with pytest.warns(PlausibilityWarning, match=match):
        s.changed(changes)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        scene.load(DEMOS / "square_cup.toml")
        scene.load(DEMOS / "square_cup_drawbeads.toml")


@pytest.mark.timeout(60)
@pytest.mark.parametrize("field", ["tools.drawbead", "process.report"])
def test_sizes_that_cost_out_of_proportion_are_refused_naming_the_field(field):
    """100,000 drawbead points (over 180 s for the first increment) and 20,000 report stations
    (4.2 GB written in 5 minutes) are refused when the scene is read, naming the field; the
    largest allowed pass."""
    from shellform.scene.checks import MAX_REPORTS
    from shellform.scene.tool_checks import MAX_DRAWBEAD_POINTS

    s = scene.load(DEMOS / "square_cup_drawbeads.toml")

    def asking(count):
        if field == "process.report":
            return {"process.report": [(i + 1) / (count + 1) for i in range(count)]}
        line = [[50.0 + 5.0 * i / count, 75.0 * i / (count - 1)] for i in range(count)]  # 50 to 55 mm from the centre
        return {"tools.drawbead": [{"points": line, "restraint": 40.0, "uplift": 10.0}]}

    limit = MAX_REPORTS if field == "process.report" else MAX_DRAWBEAD_POINTS
    with pytest.raises(InputError) as err:
        s.changed(asking(100_000 if field == "tools.drawbead" else 20_000))
    assert err.value.field == field and f"at most {limit:,}" in err.value.message
    assert s.changed(asking(limit)) is not None


def test_control_characters_in_a_title_are_escaped_in_the_closing_line():
    """A title's control characters (an escape sequence, a carriage return) are printed escaped,
    others as they are; summary.json keeps the title as given."""
    from shellform.results.summary import Summary

    line = Summary({"title": "cup\x1b[2J\r é", "cells": 8}, Path("out")).closing_line()
    assert line == "shellform: cup\\x1b[2J\\r é: 8 cells; results in out"
