"""Blanks of any outline (shellform/mesh/outline.py) and supports on curved and oblique edges
(shellform/edge_frames.py): closed forms of circular and triangular plates, a .msh square
against the built-in rectangle, rotation invariance, and the errors that name the field."""

import math
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from shellform import linear, scene
from shellform.errors import InputError
from shellform.mesh import SIDE_TAG, outline
from shellform.mesh.gmsh_model import gmsh_session
from shellform.material import Hill79Material
from shellform.nonlinear.problem import SheetProblem
from shellform.studies import outlines as outlines_study

NU = 0.3
PLATE = {"effects": ["bending"], "material": {"E": 12 * (1 - NU**2), "nu": NU, "thickness": 1.0},
         "loads": {"pressure": 1.0}}  # D = 1, q = 1


def circle_scene(support, n=4, refine=0, region="quarter", effects=("bending",)):
    sym = {"quarter": {"left": "symmetry", "bottom": "symmetry"}, "half": {"bottom": "symmetry"}, "full": {}}
    return scene.from_dict({**PLATE, "effects": list(effects),
                            "geometry": {"shape": "circle", "radius": 1.0, "region": region},
                            "mesh": {"kind": "unstructured", "n": n, "refine": refine},
                            "supports": {"rim": support, **sym[region]}})


@pytest.mark.parametrize("support, reference", [
    ("clamped", 1 / 64), ("simply_supported", (5 + NU) / (1 + NU) / 64)])
def test_circular_plate_converges_at_second_order_to_timoshenko(support, reference):
    """Nested gmsh meshes of the quarter disc: errors fall by 4 per refinement."""
    errors = [abs(linear.solve(circle_scene(support, 4, k)).value("w") / reference - 1) for k in range(3)]
    rates = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert min(rates) > 1.9, (errors, rates)
    assert errors[-1] < (2e-4 if support == "simply_supported" else 1.2e-3), errors


@pytest.mark.parametrize("region", ["full", "half"])
def test_full_and_half_discs_agree_with_the_quarter(region):
    """The same closed form from the whole disc and from its half (symmetry on y = 0 only)."""
    w = linear.solve(circle_scene("simply_supported", 16, 0, region)).value("w")
    assert w == pytest.approx((5 + NU) / (1 + NU) / 64, rel=2e-3)


def test_simply_supported_triangle_matches_its_closed_form():
    """An equilateral triangle of height a (oblique edges): w_centroid = q a^4 / (972 D)."""
    v = [[-1 / 3, -1 / math.sqrt(3)], [2 / 3, 0.0], [-1 / 3, 1 / math.sqrt(3)]]
    errors = []
    for n in (8, 16, 32):
        s = scene.from_dict({**PLATE, "geometry": {"shape": "polygon", "vertices": v, "edges": ["e"] * 3},
                             "mesh": {"kind": "unstructured", "n": n}, "supports": {"e": "simply_supported"}})
        errors.append(abs(linear.solve(s).value("w") * 972 - 1))
    assert errors[-1] < 1e-3 and errors[0] > 3 * errors[-1], errors


def _write_msh(blank, path):
    """The mesh and side groups of a BlankMesh as a gmsh .msh file (serial)."""
    msh = blank.mesh
    x = msh.geometry.x
    cells = msh.geometry.dofmaps[0]
    msh.topology.create_connectivity(1, 0)
    c2v = msh.topology.connectivity(2, 0).array.reshape(-1, 3)
    node = np.empty(len(x), dtype=np.int64)
    node[c2v.ravel()] = cells.ravel()  # vertex -> geometry node
    f2v = msh.topology.connectivity(1, 0).array.reshape(-1, 2)
    with gmsh_session() as gmsh:
        gmsh.model.addDiscreteEntity(2, 1)
        gmsh.model.mesh.addNodes(2, 1, np.arange(1, len(x) + 1), x.ravel())
        gmsh.model.mesh.addElementsByType(1, 2, [], (cells + 1).ravel())
        for side, tag in SIDE_TAG.items():
            gmsh.model.addDiscreteEntity(1, tag)
            gmsh.model.mesh.addElementsByType(tag, 1, [], (node[f2v[blank.facets(side)]] + 1).ravel())
            gmsh.model.addPhysicalGroup(1, [tag], tag, name=side)
        gmsh.model.addPhysicalGroup(2, [1], 10, name="blank")
        gmsh.write(str(path))


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="writes the mesh of one rank")
def test_square_from_a_msh_file_equals_the_builtin_rectangle(tmp_path):
    """The built-in 2 x 1 rectangle written to .msh and read back as shape = 'file': the same
    deflections at every vertex to 1e-12, though the file goes through the edge-frame route."""
    base = {**PLATE, "effects": ["bending", "membrane"], "mesh": {"n": 6, "diagonal": "crossed"},
            "supports": {"left": "simply_supported", "right": "clamped", "bottom": "simply_supported"}}
    built_in = scene.from_dict({**base, "geometry": {"lx": 2.0, "ly": 1.0}})
    _write_msh(linear.mesh(built_in), tmp_path / "square.msh")
    from_file = scene.from_dict({**base, "mesh": {"kind": "unstructured"},
                                 "geometry": {"shape": "file", "file": str(tmp_path / "square.msh")}})
    a, b = linear.solve(built_in), linear.solve(from_file)
    assert a.num_cells == b.num_cells == 96
    wa = {tuple(np.round(p, 9)): v for p, v in zip(a.forms.V.tabulate_dof_coordinates()[:, :2],
                                                    a.q.x.array.reshape(-1, 5))}
    xb = b.forms.V.tabulate_dof_coordinates()[:, :2]
    qb = b.q.x.array.reshape(-1, 5)
    scale = np.abs(a.q.x.array).max()
    diff = max(np.abs(wa[tuple(np.round(p, 9))] - v).max() for p, v in zip(xb, qb)) / scale
    assert diff < 1e-12, diff


@pytest.mark.parametrize("support", ["clamped", "simply_supported"])
def test_circular_plate_is_rotation_invariant(support):
    """The full disc's mesh rotated by 0.7 rad: the same centre deflection to 1e-10 (the simply
    supported rim turns every rim vertex into its own frame, which turns with the mesh)."""
    s = circle_scene(support, 6, 0, "full", effects=("bending", "membrane"))
    w = []
    for theta in (0.0, 0.7):
        blank = outline.circle(MPI.COMM_WORLD, 1.0, "full", 6)
        c, sn = math.cos(theta), math.sin(theta)
        x = blank.mesh.geometry.x
        x[:, :2] = x[:, :2] @ np.array([[c, -sn], [sn, c]]).T
        w.append(linear.solve(s, blank_mesh=blank).value("w"))
    assert abs(w[1] / w[0] - 1) < 1e-10, w


def test_geo_file_groups_are_its_physical_curves(tmp_path):
    geo = tmp_path / "strip.geo"
    geo.write_text('Point(1) = {0, 0, 0}; Point(2) = {2, 0, 0}; Point(3) = {2, 1, 0}; Point(4) = {0, 1, 0};\n'
                   'Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n'
                   'Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n'
                   'Physical Curve("clamp") = {4}; Physical Curve("tip") = {2}; Physical Surface("s") = {1};\n')
    s = scene.from_dict({**PLATE, "loads": {}, "geometry": {"shape": "file", "file": str(geo)},
                         "mesh": {"kind": "unstructured", "n": 8}, "supports": {"clamp": "clamped"}})
    blank = linear.mesh(s)
    assert set(blank.groups) == {"clamp", "tip"}
    assert blank.bounds == pytest.approx((0.0, 2.0, 0.0, 1.0))


SHEET = outlines_study.SHEET
T = outlines_study.SHEET_T
clamped_disc = outlines_study.clamped_disc


def test_nonlinear_sheet_clamped_on_a_curved_rim_is_the_plate_at_small_load():
    """At w0 = 1e-3 t the sheet with its rim clamped in the rim's frames gives the linear plate
    on the same mesh to 1e-5 (measured 5e-7), both 5e-3 from q a^4/(64 D) on n = 8."""
    w, p = clamped_disc("quarter", 8, 1e-3)
    plate = linear.solve(circle_scene("clamped", 8)).value("w") * 64
    assert w / 1e-3 == pytest.approx(plate, rel=1e-5)
    assert abs(plate - 1) < 6e-3
    assert p.driver.edge_frames is not None and p.driver.edge_frames.rotated.any()


def test_nonlinear_clamped_disc_is_rotation_invariant_at_large_deflection():
    """w0 about one thickness (membrane and bending both carry the load): the disc's mesh turned
    by 0.7 rad gives the same w0 to 1e-10 (measured 1e-14)."""
    w = [clamped_disc("full", 8, 1.488, theta)[0] for theta in (0.0, 0.7)]
    assert 0.9 < w[0] < 1.0
    assert abs(w[1] / w[0] - 1) < 1e-10, w


def test_nonlinear_sheet_simply_supported_on_a_curved_rim_converges_to_the_circular_plate():
    """The rim held in its frames, w = 0 and w,s = 0 with w,n free: at w0 = 1e-3 t the sheet
    converges at second order to Timoshenko's q a^4 / (64 D) (5 + nu) / (1 + nu) (measured
    -0.72 % and -0.19 % on n = 8 and 16), the curved plate's and not the inscribed polygon's. A rim
    held at its polygon's vertices with both slopes fixed would be the clamped plate, 4.1 times
    stiffer."""
    closed_form = (5 + NU) / (1 + NU)
    errors = [abs(clamped_disc("quarter", n, 1e-3, rim="simply_supported")[0] / 1e-3 / closed_form - 1)
              for n in (8, 16)]
    assert errors[0] / errors[1] > 3.5 and errors[1] < 2.5e-3, errors


def test_nonlinear_sheet_rims_at_large_deflection_hold_what_they_say():
    """At P = 1.488 (the clamped disc's w0 about t): the simply supported rim is movable (u_n
    free: the membrane pulls it in, the same at every vertex) and turns (w,n free); the sliding
    rim holds u_n = 0 and grad w = 0 and, the disc being axisymmetric, deflects as the clamped one
    (measured 0.97052 against 0.97049); the simply supported disc deflects 2.4 times as much."""
    rims = {}
    for rim in ("simply_supported", "clamped_sliding", "clamped"):
        w, p = clamped_disc("quarter", 8, 1.488, rim=rim)
        q = p.driver.q.x.array.reshape(-1, 9)
        X = p.model.V.tabulate_dof_coordinates()
        r = np.hypot(X[:, 0], X[:, 1])
        on = np.abs(r - 1) < 1e-9
        n = X[on, :2] / r[on, None]
        rims[rim] = (w, (q[on, :2] * n).sum(axis=1), (q[on, 7:9] * n).sum(axis=1), np.abs(q[on, 2]).max())
    w, un, wn, rim_w = rims["simply_supported"]
    assert rim_w == 0.0 and un.max() < -1e-4 and np.ptp(un) < 1e-2 * abs(un).max()
    assert wn.max() < -0.01 and np.ptp(wn) < 2e-2 * abs(wn).max()
    w_s, un_s, wn_s, _ = rims["clamped_sliding"]
    assert np.abs(un_s).max() < 1e-15 and np.abs(wn_s).max() < 1e-15  # held (turned back: round-off)
    assert w_s == pytest.approx(rims["clamped"][0], rel=1e-3)
    assert w > 2 * w_s


def test_nonlinear_sheet_refuses_symmetry_on_a_curved_edge():
    blank = outline.circle(MPI.COMM_WORLD, 1.0, "quarter", 4)
    with pytest.raises(InputError) as err:
        SheetProblem.on_blank(blank, Hill79Material(E=1.0, nu=NU), T, SHEET, {"rim": "symmetry"})
    assert err.value.field == "supports.rim" and "straight" in str(err.value)


def _names_field(data, field):
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert err.value.field == field, str(err.value)


CIRCLE = {"shape": "circle", "radius": 1.0}
GEO = Path(__file__).resolve().parents[1] / "demos" / "meshes" / "quarter_disc.geo"
UNSTRUCTURED = {"kind": "unstructured"}


@pytest.mark.parametrize("data, field", [
    ({"geometry": {"shape": "ellipse"}}, "geometry.shape"),
    ({"geometry": {"shape": "circle", "radius": -1.0}, "mesh": UNSTRUCTURED}, "geometry.radius"),
    ({"geometry": CIRCLE}, "mesh.kind"),  # gmsh meshes outlines
    ({"geometry": {**CIRCLE, "region": "eighth"}, "mesh": UNSTRUCTURED}, "geometry.region"),
    ({"geometry": {"radius": 2.0}}, "geometry.radius"),  # a circle's key on a rectangle
    ({"geometry": CIRCLE, "mesh": UNSTRUCTURED, "supports": {"left": "clamped"}}, "supports.left"),  # no such group
    ({"geometry": {"shape": "polygon", "vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "mesh": UNSTRUCTURED},
     "geometry.vertices"),  # self-intersecting
    ({"geometry": {"shape": "polygon", "vertices": [[0, 0], [1, 0]]}, "mesh": UNSTRUCTURED}, "geometry.vertices"),
    ({"geometry": {"shape": "polygon", "vertices": [[0, 0], [1, 0], [0, 1]], "edges": ["a", "b"]},
      "mesh": UNSTRUCTURED}, "geometry.edges"),
    ({"geometry": {"shape": "polygon", "vertices": [[0, 0], [1, 0], "x"]}, "mesh": UNSTRUCTURED}, "geometry.vertices"),
    ({"geometry": {"shape": "file", "file": "/no/such/blank.msh"}, "mesh": UNSTRUCTURED}, "geometry.file"),
    ({"geometry": {"shape": "file", "file": "blank.stl"}, "mesh": UNSTRUCTURED}, "geometry.file"),
    ({"geometry": CIRCLE, "mesh": {"kind": "unstructured", "n": 10**6}}, "mesh.n"),  # too large for the machine
    ({"geometry": {"shape": "file", "file": str(GEO)}, "mesh": {"kind": "unstructured", "refine": 12}}, "mesh.n"),
    ({"supports": {"left": 3}}, "supports.left"),
])
def test_outline_errors_name_the_field(data, field):
    _names_field({"effects": ["bending"], **data}, field)


def test_a_file_gmsh_cannot_read_is_an_error(tmp_path):
    bad = tmp_path / "bad.geo"
    bad.write_text("Point(1) = {0, 0, 0;\n")
    _names_field({"effects": ["bending"], "geometry": {"shape": "file", "file": str(bad)}, "mesh": UNSTRUCTURED},
                 "geometry.file")


def test_a_symmetry_line_the_blank_crosses_is_an_error():
    """An L-shaped polygon: the line of its inner edge 'notch' cuts through the blank."""
    v = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    s = scene.from_dict({**PLATE, "geometry": {"shape": "polygon", "vertices": v,
                                               "edges": ["b", "r", "notch", "notch2", "t", "l"]},
                         "mesh": UNSTRUCTURED, "supports": {"notch": "symmetry"}})
    with pytest.raises(InputError) as err:
        linear.mesh(s)
    assert err.value.field == "supports.notch" and "crosses" in str(err.value)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial file writing")
def test_a_mesh_of_quadrilaterals_is_an_error(tmp_path):
    path = tmp_path / "quads.msh"
    with gmsh_session() as gmsh:
        gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    s = scene.from_dict({**PLATE, "geometry": {"shape": "file", "file": str(path)}, "mesh": UNSTRUCTURED})
    with pytest.raises(InputError) as err:
        linear.mesh(s)
    assert err.value.field == "geometry.file" and "Quadrilateral" in str(err.value)


# -- reference surfaces z0(x, y) (forms/reference_surface.py) ---------------------------------
def test_z0_of_a_paraboloid_equals_its_radii():
    """surface.z0 = -(x^2 + y^2)/(2 R) and R1 = R2 = R: the same kernels' answer (UFL
    differentiates z0; the linear and the nonlinear route alike)."""
    import tomllib

    data = tomllib.loads((Path(__file__).resolve().parents[1] / "demos" / "shallow_shell.toml").read_text())
    from shellform.nonlinear.problem import SheetProblem

    data["mesh"]["n"] = 6
    w, sheet = [], []
    for surface in ({"R1": 5.0, "R2": 5.0}, {"z0": "-(x**2 + y**2)/(2*5.0)"}):
        w.append(linear.solve(scene.from_dict({**data, "surface": surface})).value("w"))
        nonlinear = {**data, "surface": surface, "effects": data["effects"] + ["geometric_nonlinearity"],
                     "loads": {"pressure": 1e-3}}
        p = SheetProblem.from_scene(scene.from_dict(nonlinear))
        p.driver.run(1.0)
        sheet.append(p.value("w", 0.0, 0.0))
    assert w[1] == pytest.approx(w[0], rel=1e-12)
    assert sheet[1] == pytest.approx(sheet[0], rel=1e-12) and sheet[0] > 0.1


def test_hypar_carries_its_load_in_shear():
    """demos/hypar_shell.toml: membrane theory's N_xy = -q/(2c), N_x = N_y = 0 at the centre."""
    s = scene.load(Path(__file__).resolve().parents[1] / "demos" / "hypar_shell.toml")
    r = linear.solve(s)
    f = r.cell_fields()["membrane_force"]
    x = f.function_space.tabulate_dof_coordinates()
    i = int(np.argmin(np.hypot(x[:, 0], x[:, 1])))
    nx, ny, nxy = f.x.array.reshape(-1, 3)[i]
    assert nxy == pytest.approx(-0.5, rel=0.01)
    assert max(abs(nx), abs(ny)) < 2e-3 * abs(nxy)


def test_twisted_surface_is_rotation_invariant():
    """A cylindrical z0 whose axis turns with the mesh: z0 = -(x cos t + y sin t)^2/(2R) on the
    disc rotated by t equals z0 = -x^2/(2R) on the disc itself (kappa0 with an xy part)."""
    w = []
    for theta in (0.0, 0.7):
        c, sn = math.cos(theta), math.sin(theta)
        s = scene.from_dict({**PLATE, "effects": ["bending", "membrane", "shallow_curvature"],
                             "geometry": {"shape": "circle", "radius": 1.0}, "mesh": {"kind": "unstructured", "n": 6},
                             "surface": {"z0": f"-(x*{c!r} + y*{sn!r})**2/(2*3.0)"}, "supports": {"rim": "clamped"}})
        blank = outline.circle(MPI.COMM_WORLD, 1.0, "full", 6)
        xg = blank.mesh.geometry.x
        xg[:, :2] = xg[:, :2] @ np.array([[c, -sn], [sn, c]]).T
        w.append(linear.solve(s, blank_mesh=blank).value("w"))
    assert abs(w[1] / w[0] - 1) < 1e-10, w


SHELL = ["bending", "membrane", "shallow_curvature"]


@pytest.mark.parametrize("surface, effects", [
    ({"z0": "x*"}, SHELL),  # not an expression
    ({"z0": "z*x"}, SHELL),  # unknown name
    ({"z0": "__import__('os')"}, SHELL),  # no calls but the listed functions
    ({"z0": "x.real"}, SHELL),
    ({"z0": "1/(x - 0.123)"}, SHELL),  # division by zero where it is checked
    ({"z0": "x*y"}, ["bending", "membrane"]),  # a curved surface needs shallow_curvature
    ({"z0": "x*y", "R1": 2.0}, SHELL),  # not both
])
def test_surface_errors_name_the_field(surface, effects):
    field = "surface.R1" if "R1" in surface else "surface.z0"
    _names_field({"effects": effects, "surface": surface}, field)


def test_outlines_study_writes_its_table(tmp_path):
    """`shellform study outlines --quick`: three cases, second order, CSV and plot."""
    from shellform.studies import outlines

    rows = outlines.run(tmp_path, levels=outlines.QUICK_LEVELS)
    assert {r["case"] for r in rows} == {"simply_supported", "clamped", "triangle"}
    disc = [r for r in rows if r["case"] != "triangle"]
    assert all(r["rate"] > 1.9 for r in disc if not math.isnan(r["rate"])), disc
    assert (tmp_path / "outlines.csv").is_file() and (tmp_path / "outlines_error_time.png").is_file()
    assert (tmp_path / "outlines.md").read_text().startswith("| case | cells | w_center |")  # docs/outlines.md's table
    assert (tmp_path / "outlines_nonlinear.csv").read_text().count("\n") == 3  # P = 1.488, 4.904 on n = 8
