"""Sensitivities from one run (shellform.nonlinear.sensitivity) against closed forms and
against central finite differences of whole runs.

    shellform study sensitivity --out docs/results/sensitivity

Cases (each sensitivity from the one run that also gives the answer):
- strip, homogeneous: the quarter strip of studies/strip.py pulled to a stretch of 1.5 in ten
  plastic increments, the nominal stress's d/dK, d/dn, d/dE against the implicit derivative of
  tau = sigma_f(ln lambda - tau / E) (swift_derivatives);
- strip, end pulled: its end pulled by 1 on 3 x 1 cells (not homogeneous), the end's force
  and the free corner's v against central differences of two runs at p (1 +- 1e-4);
- cantilever: the clamped, perfectly plastic strip under pressure of the tests' scene
  (tests/plastic_strip.py's), run through `shellform run` with `[output] sensitivities`, the
  largest w (the tip's) and the peak equivalent plastic strain in K, E, the pressure and the
  thickness, against central differences of two runs;
- plate: the simply supported elastic plate in large deflection, whose w(E, P) = W(P / E):
  E dw/dE + P dw/dP = 0 (error: that sum over |w|), and the linear plate's dw/dE = -w / E;
- round cup (demos/round_cup.toml, n 6, 3 mm): frictionless, with friction, with friction and
  its holder (10 kN, closed; 300 N, open: its lift), with friction and ironing (its flange at a
  1.0 mm gap; and a 1.19 mm sheet drawn 25 mm into the 1.2 mm clearance, where the die's
  shoulder and the punch's wall iron it), the punch force and the rim's draw-in (cup); as a scene with the forming-limit
  view and springback, the smallest margin and the flange edge's springback (cup_scene); against
  central differences of two runs at p (1 +- 1e-5);
- aluminium cup (demos/numisheet93_aluminium.toml, n 16, 25 mm, sprung back): the wall's angle
  before and after springback and the flange edge's moves in K and mu (aluminium_springback).

Writes sensitivity.csv (case, answer, parameter, the one run's derivative, the reference, the
reference's kind, the relative error against max(|reference|, the answer's scale / |p|)) and
sensitivity.md, and the wall times with and without the sensitivities (each after a plain run
that compiles what it needs), the cantilever's also on 1,024 cells.
"""

import time
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import NamedTuple

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.material import Hill79Material, flow_stress
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.loads import SheetLoads
from shellform.nonlinear.problem import SheetProblem
from shellform.nonlinear.sensitivity import MaterialParameter, PressureParameter, Sensitivity, scene_parameters
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies import strip

STEEL = strip.mild_steel()
FD_STEP = 1e-4  # the finite differences' step, relative to the parameter
COLUMNS = ["case", "answer", "parameter", "one_run", "reference", "reference_kind", "rel_error"]


def material_parameters(mat, names) -> list[MaterialParameter]:
    """The parameters `names` (fields of the material dataclass `mat`) with its pack at a value."""
    return [MaterialParameter(k, getattr(mat, k), lambda v, k=k: replace(mat, **{k: v}).pack()) for k in names]


def pulled_strip(mat, homogeneous: bool, sensitivities=(), n=3, rtol=1e-10):
    """The quarter strip of shellform.studies.strip pulled to a stretch of 1.5 (homogeneous) or
    its end pulled by 1 (n x 1 cells), in ten increments: (problem, Sensitivity or None)."""
    if homogeneous:
        held = {("all", "u"): lambda x, y: 0.5 * x, ("all", "u_x"): 0.5, ("all", "u_y"): 0.0}
    else:
        held = {("right", "u"): 0.2 * strip.LENGTH, ("right", "u_y"): 0.0}
    p = SheetProblem.on_rectangle(MPI.COMM_WORLD, 2 * strip.LENGTH, 2 * strip.WIDTH, 1 if homogeneous else n, mat,
                                  strip.T0, strip.effects(True), region="quarter",
                                  supports={"left": "symmetry", "bottom": "symmetry"}, prescribed=held,
                                  controls=Controls(initial_step=0.1, max_step=0.1, min_step=1e-4, rtol=rtol))
    s = None
    if sensitivities:
        s = Sensitivity(p.driver, material_parameters(mat, sensitivities))
        p.driver.records.append(s)
    p.driver.run(1.0)
    return p, s


def swift_derivatives(mat, lam: float):
    """tau and d tau / d(K, n, E) of homogeneous uniaxial tension, tau = sigma_f(p),
    p = ln lam - tau / E, sigma_f = K (eps0 + p)^n: implicitly, with H = d sigma_f / dp,
    d tau = (d sigma_f / d(K, n) - H p_E) / (1 + H / E)."""
    tau = strip.uniaxial_kirchhoff(mat, lam)
    p = np.log(lam) - tau / mat.E
    sigma, H = flow_stress(p, mat.pack())[:2]
    g = 1.0 + H / mat.E
    return tau, {"K": (mat.eps0 + p) ** mat.n / g, "n": sigma * np.log(mat.eps0 + p) / g,
                 "E": H * tau / mat.E**2 / g}


def plate(E: float, pressure: float, effects, sensitivities=False):
    """A simply supported quarter plate 20 x 20 x 0.5 under pressure, 6 x 6 cells, four
    increments: (problem, Sensitivity to E and the pressure, or None)."""
    mat = Hill79Material(E=E, nu=0.3)
    p = SheetProblem.on_rectangle(MPI.COMM_WORLD, 20.0, 20.0, 6, mat, 0.5, effects, region="quarter",
                                  supports={"left": "symmetry", "bottom": "symmetry", "right": "simply_supported",
                                            "top": "simply_supported"},
                                  loads=SheetLoads(pressure=pressure),
                                  controls=Controls(initial_step=0.25, max_step=0.25, rtol=1e-11))
    s = None
    if sensitivities:
        s = Sensitivity(p.driver, material_parameters(mat, ("E",)) + [PressureParameter("pressure", pressure)])
        p.driver.records.append(s)
    p.driver.run(1.0)
    return p, s


def value_of(p, s, name: str, comp: str, x: float, y: float) -> float:
    """d(comp at (x, y)) / d(name) from the sensitivity s of problem p."""
    f = fem.Function(p.model.V)
    f.x.array[:] = s.carrier(name)
    return p.value(comp, x, y, of=f)


def _row(case, answer, name, one, ref, kind, scale=0.0):
    return {"case": case, "answer": answer, "parameter": name, "one_run": one, "reference": ref,
            "reference_kind": kind, "rel_error": abs(one - ref) / max(abs(ref), scale)}


def _timed(run):
    t0 = time.perf_counter()
    out = run()
    return out, time.perf_counter() - t0


def _costs(plain, with_sensitivities):
    """(with's output, its wall time, plain's wall time), each run after one plain run that
    compiles what the case needs, so that neither time holds a compilation."""
    plain()
    _, without = _timed(plain)
    out, with_s = _timed(with_sensitivities)
    return out, with_s, without


def homogeneous_strip() -> tuple[list[dict], dict]:
    (p, s), with_s, without = _costs(lambda: pulled_strip(STEEL, True), lambda: pulled_strip(STEEL, True, ("K", "n", "E")))
    _, exact = swift_derivatives(STEEL, 1.5)
    area = strip.WIDTH * strip.T0
    rows = [_row("strip, homogeneous", "nominal stress", k, p.reaction("right", "u", residual=s.residual(k)) / area,
                 d / 1.5, "closed form") for k, d in exact.items()]
    return rows, {"case": "strip, homogeneous", "with_s": with_s, "without_s": without, "parameters": 3}


def end_pulled_strip() -> tuple[list[dict], dict]:
    names = ("K", "n", "nu", "E")
    (p, s), with_s, without = _costs(lambda: pulled_strip(STEEL, False), lambda: pulled_strip(STEEL, False, names))
    F = p.reaction("right", "u")
    rows = []
    for k in names:
        value = getattr(STEEL, k)
        h = FD_STEP * value
        plus, _ = pulled_strip(replace(STEEL, **{k: value + h}), False)
        minus, _ = pulled_strip(replace(STEEL, **{k: value - h}), False)
        fd_force = (plus.reaction("right", "u") - minus.reaction("right", "u")) / (2 * h)
        corner = (strip.LENGTH, strip.WIDTH)
        fd_v = (plus.value("v", *corner) - minus.value("v", *corner)) / (2 * h)
        rows.append(_row("strip, end pulled", "end force", k, p.reaction("right", "u", residual=s.residual(k)),
                         fd_force, "central differences", abs(F / value)))
        rows.append(_row("strip, end pulled", "corner v", k, value_of(p, s, k, "v", *corner), fd_v,
                         "central differences", abs(p.value("v", *corner) / value)))
    return rows, {"case": "strip, end pulled", "with_s": with_s, "without_s": without, "parameters": len(names)}


CANTILEVER = {"material.K": 1.0, "material.E": 1000.0, "loads.pressure": 2.0e-4, "material.thickness": 0.02}


def cantilever_scene(sensitivities: bool):
    """The tests' perfectly plastic clamped strip under pressure (8 cells, rtol 1e-10), as a scene."""
    from shellform.scene import from_dict

    data = {"title": "perfectly plastic cantilever", "effects": ["bending", "membrane", "plasticity"],
            "geometry": {"lx": 1.0, "ly": 0.125}, "mesh": {"n": 8},
            "material": {"E": 1000.0, "nu": 0.3, "thickness": 0.02, "hardening": "swift", "K": 1.0, "eps0": 1.0,
                         "n": 0.0},
            "supports": {"left": "clamped", "top": "symmetry", "bottom": "symmetry"},
            "loads": {"pressure": 2.0e-4},
            "process": {"initial_step": 0.1, "max_step": 0.1, "rtol": 1e-10},
            "output": {"vtx": False, "vtu": False, "png": False}}
    if sensitivities:
        data["output"]["sensitivities"] = list(CANTILEVER)
    return from_dict(data)


def cantilever(folder: Path) -> tuple[list[dict], dict]:
    from shellform.run import run

    def answers(report):
        return {"largest w": report["extremes"]["w"]["value"],
                "max equivalent plastic strain": report["max_equivalent_plastic_strain"]}

    summary, with_s, without = _costs(lambda: run(cantilever_scene(False), folder / "plain"),
                                      lambda: run(cantilever_scene(True), folder / "one_run"))
    report = summary["reports"][-1]
    got = {"largest w": "extreme_w", "max equivalent plastic strain": "max_equivalent_plastic_strain"}
    rows = []
    base = cantilever_scene(False)
    for i, (key, value) in enumerate(CANTILEVER.items()):
        h = FD_STEP * value
        ends = [answers(run(base.changed({key: value + sign * h}), folder / f"fd{i}{sign:+d}")["reports"][-1])
                for sign in (1, -1)]
        for answer, name in got.items():
            fd = (ends[0][answer] - ends[1][answer]) / (2 * h)
            rows.append(_row("cantilever (scene)", answer, key, report["sensitivities"][key][name], fd,
                             "central differences", abs(answers(report)[answer] / value)))
    return rows, {"case": "cantilever (scene)", "with_s": with_s, "without_s": without, "parameters": len(CANTILEVER)}


CUP_STEP = 1e-5  # the drawn cup's differences: at 1e-4 layers yield between p - h and p + h (docs/sensitivity.md)


class CupCase(NamedTuple):
    """A round cup of the study (cup): its name in the tables, its parameters, drawn_cup's
    switches and scene changes, its stroke (mm), and whether its holder opens."""

    case: str
    parameters: tuple
    friction: bool = False
    holder: bool = False
    ironing: bool = False
    changes: dict = {}
    stroke: float = 3.0
    opens: bool = False


CUPS = (
    CupCase("round cup, frictionless", ("material.K", "material.n")),
    CupCase("round cup, friction 0.07", ("material.K", "tools.friction"), friction=True),
    CupCase("round cup, holder 10 kN, friction 0.07", ("material.K", "tools.friction", "tools.blank_holder_force"),
            friction=True, holder=True),
    CupCase("round cup, holder 300 N (open), friction 0.07",
            ("material.K", "tools.friction", "tools.blank_holder_force"), friction=True, holder=True,
            changes={"tools.blank_holder_force": 300.0}, opens=True),
    CupCase("round cup ironed at a 1.0 mm gap, friction 0.07", ("material.K", "material.E", "tools.friction"),
            friction=True, ironing=True, changes={"tools.holder": "gap", "tools.holder_gap": 1.0}),
    CupCase("round cup, 1.19 mm ironed in the 1.2 mm clearance, 25 mm, friction 0.07", ("material.K",),
            friction=True, ironing=True,
            changes={"tools.holder": "gap", "tools.holder_gap": 1.3, "material.thickness": 1.19}, stroke=25.0),
)


def drawn_cup(changes: dict | None = None, sensitivities=(), n: int = 6, stroke: float = 3.0, scene_only=False,
              friction: bool = False, holder: bool = False, ironing: bool = False):
    """demos/round_cup.toml with its rigid punch and die, with `holder` its force-controlled
    holder (10 kN), else none, with `friction` its Coulomb friction (0.07), else none, and with
    `ironing` its ironing, else none; n = n, `stroke` mm in steps of 0.1 mm, rtol 1e-10,
    with `changes` {scene key: value}: (problem, Sensitivity of the scene keys `sensitivities`
    or None); with scene_only, (the scene, None), not run."""
    from shellform import demos, scene
    from shellform.contact.problem import DrawingProblem

    base = scene.load(demos.path("round_cup.toml"))
    keep = {"ironing": ironing, "friction": friction}
    s = base.changed({"mesh.n": n, "tools.stroke": stroke,
                      **({} if holder else {"tools.blank_holder_force": 0.0}),
                      **({} if friction else {"tools.friction": 0.0}),
                      "effects": [e for e in base.effects if keep.get(e, True)],
                      "process.report": [], "process.initial_step_mm": 0.1, "process.max_step_mm": 0.1,
                      "process.min_step_mm": 0.001, "process.rtol": 1e-10, **(changes or {})})
    if scene_only:
        return s, None
    p = DrawingProblem.from_scene(s, verbose=False)
    sens = None
    if sensitivities:
        sens = Sensitivity(p.driver, scene_parameters(s.changed({"output.sensitivities": list(sensitivities)})))
        p.driver.records.append(sens)
    p.driver.run(1.0)
    return p, sens


def rim_node(p) -> int:
    """The owned node of the blank's edge on y = 0 (its radial draw-in: -dx)."""
    X = p.driver.model.mesh.geometry.x[: p.driver.n_owned]
    return int(np.argmax(np.where(np.abs(X[:, 1]) < 1e-9, X[:, 0], -np.inf)))


def cup(c: CupCase) -> tuple[list[dict], dict]:
    """The round cup `c` (CUPS: frictionless, with its friction, with its holder at 10 kN,
    closed, or 300 N, which opens and rides on the flange (its lift's derivative), ironed at a
    gap or on its wall; drawn_cup): the punch force and the rim's draw-in on y = 0, in each
    parameter against central differences of two runs at p (1 +- CUP_STEP)."""
    draw = partial(drawn_cup, friction=c.friction, holder=c.holder, ironing=c.ironing, stroke=c.stroke)
    (p, s), with_s, without = _costs(lambda: draw(c.changes), lambda: draw(c.changes, sensitivities=c.parameters))
    if c.opens and not p.driver.holder.is_open:
        raise RuntimeError(f"the holder of '{c.case}' was to be open at the end of its stroke")
    i = rim_node(p)
    rows = []
    for par in s.parameters:
        k, value = par.name, par.value
        h = CUP_STEP * value
        plus, minus = (draw({**c.changes, k: value + sign * h})[0] for sign in (1, -1))
        steps = [len(r.driver.history) for r in (p, plus, minus)]
        if len(set(steps)) > 1:
            say(f"sensitivity: {c.case}, {k}: the runs took {steps} increments (a step decision between p - h and "
                "p + h)")
        fd_force = (plus.punch_force() - minus.punch_force()) / (2 * h)
        fd_draw = -(plus.driver.positions()[i, 0] - minus.driver.positions()[i, 0]) / (2 * h)
        rows.append(_row(c.case, "punch force", k, p.punch_force(residual=s.residual(k)), fd_force,
                         "central differences", abs(p.punch_force() / value)))
        rows.append(_row(c.case, "rim draw-in (y = 0)", k, -float(s.carrier(k).reshape(-1, BS)[i, 0]), fd_draw,
                         "central differences"))
    return rows, {"case": c.case, "with_s": with_s, "without_s": without, "parameters": len(c.parameters)}


SCENE_PARAMETERS = ("material.K", "material.n", "material.r")
SCENE_HOLDER_PARAMETERS = ("material.r", "tools.friction")
ALUMINIUM_SPRINGBACK = ("material.K", "tools.friction")


def _springback(answer: str, line: str) -> tuple:
    """(label, its value in a run's summary, its derivative in the one run's) of a springback answer
    (results/springback.changes) on one line."""
    return (f"springback {answer} ({line})", lambda s: s["springback"][answer][line],
            lambda s, name: s["springback"]["sensitivities"][name][answer][line])


MARGIN = ("smallest FLD margin", lambda s: s["min_margin"],
          lambda s, name: s["reports"][-1]["sensitivities"][name]["min_margin"])


def _against_two_runs(case: str, base, names, folder: Path, answers) -> tuple[list[dict], dict]:
    """The scene `base` run plain and with `[output] sensitivities` = names, and for each name twice
    more at p (1 +- CUP_STEP): per name and answer ((label, value of a summary, derivative of the one
    run's summary and a name)) the one run's derivative against the central difference."""
    from shellform.contact.run import run as run_scene

    plain = run_scene(base, folder / "plain")
    one = run_scene(base.changed({"output.sensitivities": list(names)}), folder / "one_run")
    rows = []
    for name in names:
        section, _, key = name.partition(".")
        value = float(getattr(getattr(base, section), key))
        h = CUP_STEP * value
        ends = [run_scene(base.changed({name: value + sign * h}), folder / f"{key}_{sign:+d}") for sign in (1, -1)]
        for label, value_of, derivative_of in answers:
            rows.append(_row(case, label, name, derivative_of(one, name),
                             (value_of(ends[0]) - value_of(ends[1])) / (2 * h), "central differences"))
    return rows, {"case": case, "with_s": one["wall_time_s"]["total"], "without_s": plain["wall_time_s"]["total"],
                  "parameters": len(names)}


def cup_scene(folder: Path, holder: bool = False) -> tuple[list[dict], dict]:
    """The round cup of drawn_cup as a scene with its forming-limit view and springback,
    frictionless or with its friction and holder: the smallest margin to the forming-limit curve
    at the end of the stroke and the flange edge's springback on the transverse line (its move
    in z and in the distance from the centre), in each parameter against central differences of
    two whole runs at p (1 +- CUP_STEP)."""
    case = "round cup scene, holder 10 kN, friction 0.07" if holder else "round cup scene, frictionless"
    scene_, _ = drawn_cup(scene_only=True, friction=holder, holder=holder)
    base = scene_.changed({"process.springback": True, "output.png": False, "output.vtx": False, "output.vtu": False,
                           "output.fld": True})
    answers = [MARGIN, _springback("flange_edge_dz_mm", "transverse"), _springback("flange_edge_dr_mm", "transverse")]
    return _against_two_runs(case, base, SCENE_HOLDER_PARAMETERS if holder else SCENE_PARAMETERS, folder, answers)


def aluminium_springback(folder: Path, n: int = 16, stroke: float = 25.0) -> tuple[list[dict], dict]:
    """demos/numisheet93_aluminium.toml on n = 16 drawn 25 mm (a wall to measure) and sprung back:
    the wall's angle before and after springback and the flange edge's moves, in K and mu
    against central differences of two whole runs at p (1 +- CUP_STEP)."""
    from shellform import demos, scene

    base = scene.load(demos.path("numisheet93_aluminium.toml")).changed({
        "mesh.n": n, "tools.stroke": stroke, "process.report": [1.0], "process.springback": True, "process.rtol": 1e-10,
        "output.png": False, "output.vtx": False, "output.vtu": False, "output.fld": False})
    answers = [_springback("wall_angle_deg", "before"), _springback("wall_angle_deg", "after"),
               _springback("flange_edge_dr_mm", "transverse"), _springback("flange_edge_dz_mm", "diagonal")]
    return _against_two_runs(f"aluminium cup n {n}, {stroke:g} mm, springback", base, ALUMINIUM_SPRINGBACK, folder,
                             answers)


def plates() -> tuple[list[dict], dict]:
    E, P = 70e3, 5.0
    effects = ("bending", "membrane", "geometric_nonlinearity")
    (p, s), with_s, without = _costs(lambda: plate(E, P, effects), lambda: plate(E, P, effects, True))
    w = p.value("w", 0.0, 0.0)
    dE, dP = value_of(p, s, "E", "w", 0.0, 0.0), value_of(p, s, "pressure", "w", 0.0, 0.0)
    rows = [_row("plate, large deflection", "E dw/dE + P dw/dP (centre)", "E, pressure", E * dE + P * dP, 0.0,
                 "identity w(E, P) = W(P / E)", abs(w))]
    lin, s_lin = plate(E, 1e-4, ("bending",), True)
    w_lin = lin.value("w", 0.0, 0.0)
    rows.append(_row("plate, linear", "centre w", "E", value_of(lin, s_lin, "E", "w", 0.0, 0.0), -w_lin / E,
                     "closed form -w / E"))
    return rows, {"case": "plate, large deflection", "with_s": with_s, "without_s": without, "parameters": 2}


def cantilever_cost(folder: Path, n: int = 64) -> dict:
    """The cantilever with mesh.n = n: the wall time with its four sensitivities and without (no
    references)."""
    from shellform.run import run

    summary, with_s, without = _costs(lambda: run(cantilever_scene(False).changed({"mesh.n": n}), folder / "plain"),
                                      lambda: run(cantilever_scene(True).changed({"mesh.n": n}), folder / "one_run"))
    return {"case": f"cantilever (scene), {summary['cells']} cells", "with_s": with_s, "without_s": without,
            "parameters": len(CANTILEVER)}


def markdown(rows: list[dict], times: list[dict]) -> str:
    lines = ["| case | answer | parameter | one run | reference | kind | rel. error |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['answer']} | {r['parameter']} | {r['one_run']:.10g} | {r['reference']:.10g} | "
                     f"{r['reference_kind']} | {r['rel_error']:.1e} |")
    lines += ["", "| case | parameters | wall with sensitivities (s) | without (s) |", "|---|---|---|---|"]
    for t in times:
        lines.append(f"| {t['case']} | {t['parameters']} | {t['with_s']:.2f} | {t['without_s']:.2f} |")
    return "\n".join(lines) + "\n"


def run(outdir) -> list[dict]:
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows, times = [], []
    for case in (homogeneous_strip, end_pulled_strip, lambda: cantilever(out / "runs"), plates,
                 *(partial(cup, c) for c in CUPS),
                 lambda: cup_scene(out / "runs" / "cup"), lambda: cup_scene(out / "runs" / "cup_holder", holder=True),
                 lambda: aluminium_springback(out / "runs" / "aluminium")):
        r, t = case()
        rows += r
        times.append(t)
        say(f"sensitivity: {t['case']}: largest error {max(x['rel_error'] for x in r):.1e} "
            f"({t['with_s']:.2f} s with, {t['without_s']:.2f} s without)")
    times.append(cantilever_cost(out / "runs" / "cost"))
    write_csv(out / "sensitivity.csv", rows, COLUMNS)
    write_csv(out / "sensitivity_times.csv", times, ["case", "parameters", "with_s", "without_s"])
    if MPI.COMM_WORLD.rank == 0:
        (out / "sensitivity.md").write_text(markdown(rows, times))
    return rows
