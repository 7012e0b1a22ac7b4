"""The ESAFORM 2021 cup drawn through: its height profile against the benchmark's measured one.

    shellform study esaform-cup --out docs/results/esaform_cup [--levels 12 16 20 24]

The scene demos/esaform2021_cup.toml (AA6016-T4, 1 mm; the benchmark's tools, blank, Voce curve
and friction; a force-controlled holder of 10 kN) with the effect ``ironing`` added and the
stroke STROKE = 45 mm, long enough that the rim leaves the die's shoulder (the die's top is
0.5 mm below the blank's plane, its shoulder's radius 10 mm; at 45 mm the rim's mid-surface
stands 10.9 to 14.2 mm below the blank's plane on n = 12 and 16, between the punch and the
die's wall, so the flange has been drawn through and the height profile is final). Two yield functions, both
with the Voce curve as the rolling direction's uniaxial curve:

- ``yld2000``: Yld2000-2d (a = 8) as the demo fits it by least squares to the TUAT r values and
  yield stress ratios at 0, 15, ..., 90 degrees, sigma_b/sigma0 = 1, r_b = 1 assumed;
- ``hill48``: Hill 1948 from r0 / r45 / r90 = 0.526 / 0.253 / 0.601 alone (its yield stresses
  are then those the r values imply, not the measured ones).

**Height.** As the benchmark measures a cup standing on its bottom: from the bottom's outer
face to the top of the rim. On the drawn sheet (the last step of cup.pvd: the deformed
mid-surface x, the displacement u, so the initial position X = x - u, and the thickness
strain e33, t = t0 exp(e33) at the nodes):

    z_bottom = min_j (z_j - t_j |n_z(j)| / 2)  over every node j: where the cup stands
    z_top(i) = z_i + t_i |n_z(i)| / 2          i: a rim node, |X_i, Y_i| = the blank's radius
    h(theta_i) = z_top(i) - z_bottom,          theta_i = atan2(Y_i, X_i) (the initial angle)

n is the unit normal of the deformed mid-surface at the node (the area-weighted mean of its
triangles' normals): the point of a face of thickness t whose mid-surface tilts by the angle
arccos|n_z| from the horizontal lies t |n_z| / 2 above (top) or below (bottom) its mid-surface
(a vertical wall's top is its mid-surface's height; a flat flange's is t / 2 above it). The
cup stands on a table on the lowest point of its outer face: the punch pushes on the sheet's
upper face, and the bottom under it need not stay flat on it (on the n = 6 mesh at 4 mm its
centre hangs 0.48 mm below the punch's face; on the drawn-through cups of n = 12 the bottom's
outer face is flat to 0.05 mm, lowest near the punch's nose). Springback is not drawn: the
height is the loaded cup's. h at the ANGLES 0, 15, ..., 90
degrees is interpolated linearly along theta between the rim's nodes. The mean height is the
angle average over the quarter, (2 / pi) int_0^{pi/2} h dtheta, by the trapezoidal rule over
the rim's nodes (the quarter's symmetry makes it the whole rim's). The ears' measures:
d0 = h(0) - h(45) and d90 = h(90) - h(45).

**The measured profile** (MEASURED): the 25 rows (angle in degrees, height in mm) of
CM_Data/AA6016_CupProfiles/AA6016_Experiment_Fig91_CupProfile_angle.txt in
github.com/stefanSCS/PolyN, the paper's Fig. 91 digitised (docs/references.md, section 6). Its
heights at the ANGLES are interpolated linearly, periodic in the angle, between its rows (the
first quadrant's rows lie within 0.5 degrees of 0, 15, ..., 90). The measured mean is the
whole circle's angle average (periodic trapezoidal rule over the 24 distinct rows: the row at
359.95 degrees repeats the one at 0.48), 34.13 mm; the mean of all 25 rows, 34.15 mm, counts
that row twice. The cup is not symmetric in its four quadrants (h(0) 34.52 against h(180)
35.26 mm); the "folded" profile, the mean at theta, 180 - theta, 180 + theta and 360 - theta,
is what a model with the sheet's orthotropic symmetry can match, and the table gives both.

**Errors**: (model - measured) / measured for h at each angle and the mean height, and the same
for d0 and d90 (relative to the measured difference). The goals (issue 45): the ears in the
measured directions (the two highest of h(0), h(45), h(90) at 0 and 90 degrees), the mean
height within 3 %, d0 and d90 within 25 %.

**Meshes**: levels n (the demo's quarter disc with n elements along the radius); where three
levels of a yield function finished, the Richardson estimate of each answer
(shellform.studies.cup_convergence.richardson, h ~ cells^-1/2). A run already in out with the
same scene (run.json's scene hash) and a summary is reused, not redrawn.

Writes esaform_cup.csv (a row per run: counts, the stroke reached, h at the ANGLES, the mean,
d0, d90, their errors), esaform_cup.md (the tables) and esaform_cup.png (h(theta) of each run
over the measured profile). --quick: n = 6 to QUICK_STROKE (the plumbing only).
"""

import json
from pathlib import Path

import numpy as np

from shellform.contact.run import run as run_cup
from shellform.results import run_folder
from shellform.results.log import say
from shellform.results.tables import as_written, markdown_table, write_csv
from shellform.results.vtu import last_step, read_vtu
from shellform.studies.cup_convergence import richardson
from shellform.studies.cup_hard import folder, variant

SCENE = "esaform2021_cup.toml"
STROKE = 45.0
LEVELS = (12, 16, 20, 24)
QUICK_LEVELS = (6,)
QUICK_STROKE = 4.0
ANGLES = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)
GOALS = {"mean": 0.03, "d0": 0.25, "d90": 0.25}
GAP = {"tools.holder": "gap", "tools.holder_gap": 1.04}  # the benchmark's holder at its fixed gap
POLY6_KEYS = {"material.yield_function": "poly6", "material.a": 0.0}  # Poly6 on the demo's fit data
# PolyN's own Poly6 of this sheet (stefanSCS/PolyN at 4c62d0af,
# CM_Data/AA6016_Parameters/AA6016T4_P6_deg6_Err_and_Coeff.txt), c1..c16 in poly6's order
POLYN = [1.0, -2.0681520314547837, 6.868121692756133, -10.55917923225223, 7.39574824063295, -2.4963948816328827,
         1.1083550209357307, 14.776642100088036, -2.5895869697823395, 6.271731518600609, -3.255124509890244,
         17.457821116365473, 27.153617310650084, 9.892687851715271, 27.98321894414102, 13.513644513646144]
MODELS = {  # name: (label, the scene's material changes)
    "yld2000": ("Yld2000-2d, least squares (the demo)", {}),
    "hill48": ("Hill 1948, r0 / r45 / r90", {
        "material.yield_function": "hill48", "material.r0": 0.526, "material.r45": 0.253, "material.r90": 0.601,
        "material.fit_angles": [], "material.fit_r": [], "material.fit_sigma": [],
        "material.sigma_b": 0.0, "material.r_b": 0.0, "material.a": 0.0}),
    # the two assumptions docs/cup.md suspects, one at a time on the demo's Yld2000-2d
    "yld2000-wide-die": ("Yld2000-2d, die radius 31.6 mm (1.6 mm clearance: the rim not ironed)",
                         {"tools.die_radius": 31.6}),
    "yld2000-gap-holder": ("Yld2000-2d, the holder at the benchmark's 1.04 mm gap", GAP),
    # suspect (b) of the gap holder's d0: the fit's biaxial strain ratio left free (r_b = 1 assumed)
    "yld2000-gap-holder-free-rb": ("Yld2000-2d fitted without r_b, the holder at the 1.04 mm gap",
                                   {**GAP, "material.r_b": 0.0}),
    # and the two assumptions left for its d0: the wall's ironing, the fit's exponent
    "yld2000-gap-holder-wide-die": (
        "Yld2000-2d, the holder at the 1.04 mm gap, die radius 31.6 mm (no ironing at the wall)",
        {**GAP, "tools.die_radius": 31.6}),
    "yld2000-gap-holder-a6": ("Yld2000-2d with a = 6 (fitted again), the holder at the 1.04 mm gap",
                              {**GAP, "material.a": 6.0}),
    # the criterion: Poly6, 16 coefficients fitted to the same data (Yld2000-2d's 8 leave errors that
    # alternate in sign along the angle)
    "poly6-gap-holder": ("Poly6 fitted to the same data, the holder at the 1.04 mm gap", {**GAP, **POLY6_KEYS}),
    # and the part of the yield locus the data leave free: PolyN's own coefficients instead of the fit
    "poly6-polyn-gap-holder": ("Poly6 with PolyN's coefficients, the holder at the 1.04 mm gap", {
        **GAP, **POLY6_KEYS, "material.fit_angles": [], "material.fit_r": [], "material.fit_sigma": [],
        "material.sigma_b": 0.0, "material.r_b": 0.0, "material.coefficients": POLYN}),
    # and the data: Poly6 fitted to the other laboratory's (UA) r values and stresses of the same
    # sheet (docs/references.md section 6; its biaxial stress 0.975, r_b = 1 assumed as above)
    "poly6-ua-gap-holder": ("Poly6 fitted to the UA data, the holder at the 1.04 mm gap", {
        **GAP, **POLY6_KEYS, "material.fit_r": [0.525, 0.359, 0.303, 0.248, 0.297, 0.387, 0.429],
        "material.fit_sigma": [1.000, 0.963, 0.904, 0.867, 0.919, 0.948, 0.926], "material.sigma_b": 0.975}),
}
HYPOTHESES = ("yld2000-wide-die", "yld2000-gap-holder")  # run apart: `hypotheses`'s docstring
GAP_HOLDER = ("yld2000-gap-holder", "yld2000-gap-holder-free-rb")  # drawn through on n >= 16: `gap_holder`
GAP_HOLDER_SUSPECTS = ("yld2000-gap-holder-wide-die", "yld2000-gap-holder-a6")  # on the first level only
POLY6 = ("poly6-gap-holder", "poly6-polyn-gap-holder", "poly6-ua-gap-holder")  # more coefficients: `poly6`
# github.com/stefanSCS/PolyN, CM_Data/AA6016_CupProfiles/AA6016_Experiment_Fig91_CupProfile_angle.txt:
# (angle in degrees, measured cup height in mm)
MEASURED = np.array([
    (0.480331, 34.515), (14.8128, 33.8929), (30.3073, 33.5364), (45.0271, 33.131), (60.1343, 33.5434),
    (75.2415, 34.2704), (89.9613, 34.9135), (105.068, 34.557), (120.176, 34.0117), (135.283, 33.5294),
    (150.39, 34.3333), (165.11, 34.9414), (180.217, 35.256), (195.324, 34.6478), (210.044, 34.4871),
    (224.764, 34.0467), (239.871, 33.7252), (255.365, 34.2284), (269.698, 34.7177), (285.192, 34.7038),
    (299.912, 33.83), (315.019, 33.152), (330.127, 33.2009), (344.846, 33.9698), (359.954, 34.515)])

# Published profiles of peers' Poly6 models of this cup (first quadrant, angle in degrees, height
# in mm; the peers mirror it), from github.com/stefanSCS/PolyN at commit 4c62d0af,
# CM_Data/AA6016_CupProfiles: references, not the truth (docs/cup.md).
PEERS = {
    # AA6016T4_P6_deg6_FEdata_cpdrwPROFILE_angle.txt: PolyN's own Abaqus run of its Poly6 (the
    # coefficients of model poly6-polyn-gap-holder, the holder at 1.04 mm); every second point
    "PolyN's Abaqus run of its Poly6": np.array([
    (0.0000, 34.2081), (3.8298, 34.0980), (7.6596, 33.7956), (11.4894, 33.3697), (15.3191, 32.9052),
    (19.1489, 32.4689), (22.9787, 32.0898), (26.8085, 31.7664), (30.6383, 31.4915), (34.4681, 31.2656),
    (38.2979, 31.0983), (42.1277, 31.0052), (45.9574, 30.9993), (49.7872, 31.0791), (53.6170, 31.2282),
    (57.4468, 31.4273), (61.2766, 31.6677), (65.1064, 31.9555), (68.9362, 32.3104), (72.7660, 32.7515),
    (76.5957, 33.2685), (80.4255, 33.7990), (84.2553, 34.2405), (88.0851, 34.4914), (90.0000, 34.5245)
    ]),
    # AA6016T4_Poly6_Dig_Profile_Fig103_angle.txt: the benchmark paper's Fig. 103, a participant's
    # Poly6 profile, digitised
    "the benchmark's Poly6 participant (Fig. 103)": np.array([
    (0.0000, 34.0919), (3.0042, 34.1155), (6.8963, 34.1527), (11.0998, 34.1257), (14.0578, 34.0210),
    (16.3931, 33.8892), (18.8841, 33.7102), (20.5966, 33.4941), (22.1534, 33.3016), (24.0216, 33.0955),
    (26.0455, 32.8591), (28.0694, 32.6531), (30.8718, 32.4673), (33.6741, 32.3255), (36.4764, 32.2478),
    (44.4163, 32.2208), (51.7335, 32.2174), (55.1585, 32.2647), (57.9609, 32.3896), (59.9848, 32.5653),
    (62.6314, 32.7747), (65.1224, 33.0280), (66.9906, 33.2374), (68.5474, 33.4569), (70.5713, 33.6461),
    (72.5952, 33.8352), (74.9305, 33.9838), (77.2658, 34.0818), (79.7567, 34.1155), (83.1818, 34.0953),
    (86.2955, 34.0480), (90.0000, 34.0176)
    ]),
}

def _periodic(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows over one period (the last repeats the first), sorted."""
    a, h = rows[:-1, 0] % 360.0, rows[:-1, 1]
    order = np.argsort(a)
    return a[order], h[order]


def measured_at(angles, rows: np.ndarray = MEASURED) -> np.ndarray:
    a, h = _periodic(rows)
    return np.interp(np.asarray(angles, dtype=float), a, h, period=360.0)


def measured(rows: np.ndarray = MEASURED, angles=ANGLES) -> dict:
    """The measured profile's answers: h at the angles (first quadrant) and folded (the mean of
    the four quadrants' mirror angles), the whole circle's mean, d0 and d90 of both."""
    a, h = _periodic(rows)
    closed_a, closed_h = np.append(a, a[0] + 360.0), np.append(h, h[0])
    mean = float(np.trapezoid(closed_h, closed_a) / 360.0)
    first = measured_at(angles, rows)
    th = np.asarray(angles, dtype=float)
    folded = np.mean([measured_at(m, rows) for m in (th, 180.0 - th, 180.0 + th, 360.0 - th)], axis=0)
    out = {"mean": mean}
    for name, prof in (("first", first), ("folded", folded)):
        out[name] = {f"h{t:g}": float(v) for t, v in zip(angles, prof)}
        out[name]["d0"] = out[name]["h0"] - out[name]["h45"]
        out[name]["d90"] = out[name]["h90"] - out[name]["h45"]
    return out


def vertex_normals(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Unit normals at the points: the area-weighted mean of their triangles' normals (the
    triangles' orientation need not agree: each is turned to +z first, or to the first
    triangle's side where it is vertical, so that a node's normals do not cancel)."""
    p = points[triangles]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])  # length: twice the area
    n[n[:, 2] < 0] *= -1.0
    out = np.zeros_like(points)
    for k in range(3):
        np.add.at(out, triangles[:, k], n)
    length = np.linalg.norm(out, axis=1)
    return out / np.where(length > 0, length, 1.0)[:, None]


def rim_and_bottom(points, triangles, displacement, thickness_strain, t0: float, radius: float,
                   tol: float = 1e-3) -> tuple[np.ndarray, float]:
    """The rim's rows (theta_deg, z_top, z_mid, t, |n_z|) by angle, and z_bottom (the lowest
    point of the sheet's outer face: where the cup stands), from the deformed sheet as the module's docstring defines them:
    the rim is the nodes whose initial radius is within tol of `radius`."""
    x = np.asarray(points, dtype=float)
    X = x - np.asarray(displacement, dtype=float)[:, :3]
    t = t0 * np.exp(np.asarray(thickness_strain, dtype=float))
    nz = np.abs(vertex_normals(x, np.asarray(triangles))[:, 2])
    R = np.hypot(X[:, 0], X[:, 1])
    on = R > radius - tol
    if not on.any():
        raise ValueError(f"no node at the initial radius {radius} (the largest is {R.max():.6g})")
    theta = np.degrees(np.arctan2(X[on, 1], X[on, 0]))
    rows = np.column_stack([theta, x[on, 2] + 0.5 * t[on] * nz[on], x[on, 2], t[on], nz[on]])
    return rows[np.argsort(theta, kind="stable")], float((x[:, 2] - 0.5 * t * nz).min())


def heights(rim_rows: np.ndarray, z_bottom: float, angles=ANGLES) -> dict:
    """h at the angles (linear along theta between the rim's nodes; rim_rows: theta_deg, z_top
    first), the quarter's mean height (trapezoidal over the nodes, over the span they cover),
    d0 = h(0) - h(45) and d90 = h(90) - h(45)."""
    th, h = rim_rows[:, 0], rim_rows[:, 1] - z_bottom
    out = {f"h{a:g}": float(np.interp(a, th, h)) for a in angles}
    out["mean"] = float(np.trapezoid(h, th) / (th[-1] - th[0]))
    out["d0"] = out["h0"] - out["h45"]
    out["d90"] = out["h90"] - out["h45"]
    return out


def scene_of(model: str, n: int, stroke: float = STROKE):
    s = variant(n, SCENE, tools__stroke=stroke)
    return s.changed({"effects": [*s.effects, "ironing"], **MODELS[model][1]})


def run_name(model: str, n: int) -> str:
    return f"{model} n {n}"


def _finished_here(d: Path, s) -> bool:
    """Whether d holds a run of scene s by this code (run.json's scene hash and code version),
    finished or stopped, with its results: a run of other code is drawn again, its numbers may
    not be this code's."""
    m = run_folder.read_manifest(d)
    return bool(m) and m.get("scene_hash") == run_folder.scene_hash(s) \
        and m.get("code_version") == run_folder.code_version() and (d / "summary.json").exists() \
        and (d / "cup.pvd").exists()


def row(model: str, n: int, out: Path) -> dict:
    """A run's row: its counts from summary.json, the heights from cup.pvd's last step."""
    s = scene_of(model, n)
    d = folder(out, run_name(model, n))
    summary = json.loads((d / "summary.json").read_text())
    stroke, vtu = last_step(d / "cup.pvd")
    points, triangles, pdata, _ = read_vtu(vtu)
    rim, z_bottom = rim_and_bottom(points, triangles, pdata["displacement"], pdata["thickness_strain"],
                                   s.material.thickness, s.geometry.radius)
    r = {"model": model, "n": n, "cells": summary["cells"], "stroke_mm": stroke,
         "finished": summary["stopped"] is None, "increments": summary["increments"],
         "newton_iterations": summary["newton_iterations"], "cutbacks": summary["cutbacks"],
         "wall_s": summary["wall_time_s"]["total"], "rim_nodes": len(rim), "z_bottom_mm": z_bottom,
         "rim_nz_max": float(rim[:, 4].max()), "rim_t_min_mm": float(rim[:, 3].min()),
         "rim_t_max_mm": float(rim[:, 3].max()), **heights(rim, z_bottom)}
    write_csv(d / "rim_height.csv", [dict(zip(("angle_deg", "z_top_mm", "z_mid_mm", "thickness_mm", "abs_nz"), v))
                                     for v in rim], ["angle_deg", "z_top_mm", "z_mid_mm", "thickness_mm", "abs_nz"])
    return with_errors(r)


def with_errors(r: dict, ref: dict | None = None) -> dict:
    """r with its errors against the measured first-quadrant profile (and folded d0, d90) and
    whether each goal is met."""
    ref = ref or measured()
    first, folded = ref["first"], ref["folded"]
    for a in ANGLES:
        r[f"err_h{a:g}"] = (r[f"h{a:g}"] - first[f"h{a:g}"]) / first[f"h{a:g}"]
    r["err_mean"] = (r["mean"] - ref["mean"]) / ref["mean"]
    for k in ("d0", "d90"):
        r[f"err_{k}"] = (r[k] - first[k]) / first[k]
        r[f"err_{k}_folded"] = (r[k] - folded[k]) / folded[k]
    r["ears_right"] = bool(min(r["h0"], r["h90"]) > r["h45"])
    r["goals_met"] = bool(r["ears_right"] and all(abs(r[f"err_{k}"]) <= g for k, g in GOALS.items()))
    return r


def estimates(rows: list[dict]) -> list[dict]:
    """Per yield function with three finished levels, the Richardson estimate of each answer."""
    out = []
    for model in dict.fromkeys(r["model"] for r in rows):
        done = [r for r in rows if r["model"] == model and r["finished"]]
        if len(done) < 3:
            continue
        last = done[-3:]
        for key in ("mean", "h0", "h45", "h90", "d0", "d90"):
            e = richardson([r["cells"] ** -0.5 for r in last], [r[key] for r in last])
            out.append({"model": model, "answer": key, "values": " ".join(f"{r[key]:.4f}" for r in last), **e})
    return out


def _pct(x) -> str:
    return f"{100 * x:+.1f} %"


def markdown(rows: list[dict], ests: list[dict], ref: dict | None = None) -> str:
    ref = ref or measured()
    first, folded = ref["first"], ref["folded"]
    heads = " | ".join(f"h({a:g})" for a in ANGLES)
    text = ["| run | " + heads + " | mean | d0 = h(0) - h(45) | d90 = h(90) - h(45) |",
            "|---|" + "---|" * (len(ANGLES) + 3),
            "| measured, first quadrant | " + " | ".join(f"{first[f'h{a:g}']:.2f}" for a in ANGLES)
            + f" | {ref['mean']:.2f} (whole circle) | {first['d0']:.2f} | {first['d90']:.2f} |",
            "| measured, four quadrants folded | " + " | ".join(f"{folded[f'h{a:g}']:.2f}" for a in ANGLES)
            + f" | {ref['mean']:.2f} | {folded['d0']:.2f} | {folded['d90']:.2f} |"]
    for r in rows:
        end = "" if r["finished"] else f", stopped at {r['stroke_mm']:.1f} mm"
        text.append(f"| {r['model']} n {r['n']} ({r['cells']} cells{end}) | "
                    + " | ".join(f"{r[f'h{a:g}']:.2f}" for a in ANGLES)
                    + f" | {r['mean']:.2f} | {r['d0']:.2f} | {r['d90']:.2f} |")
    text += ["", "| run | error of h at 0, 15, ..., 90 | mean | d0 (folded) | d90 (folded) | h(0), h(90) > h(45) "
             "| goals (mean 3 %, d 25 %) | increments, iterations, cut-backs | wall (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        text.append(f"| {r['model']} n {r['n']} | " + ", ".join(f"{100 * r[f'err_h{a:g}']:+.1f}" for a in ANGLES)
                    + f" % | {_pct(r['err_mean'])} | {_pct(r['err_d0'])} ({_pct(r['err_d0_folded'])}) "
                    f"| {_pct(r['err_d90'])} ({_pct(r['err_d90_folded'])}) | {'yes' if r['ears_right'] else 'no'} "
                    f"| {'met' if r['goals_met'] else 'missed'} | {r['increments']}, {r['newton_iterations']}, "
                    f"{r['cutbacks']} | {r['wall_s']:.0f} |")
    if ests:
        text += ["", "| yield function | answer | values (3 finest) | p | estimate +- uncertainty |", "|---|---|---|---|---|"]
        for e in ests:
            p = "none" if not np.isfinite(e["p"]) else f"{e['p']:.2f}"
            est = "none" if not np.isfinite(e["estimate"]) else f"{e['estimate']:.3f}"
            text.append(f"| {e['model']} | {e['answer']} | {e['values']} | {p} | {est} +- {e['uncertainty']:.3f} |")
    return "\n".join(text) + "\n"


def plot(path: Path, rows: list[dict], out: Path) -> None:
    """Each run's h(theta) at its rim nodes over the measured profile (first quadrant and
    folded)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    a, h = _periodic(MEASURED)
    first = a <= 90.5
    ax.plot(a[first], h[first], "ks-", label="measured (Fig. 91, PolyN), 0 to 90 deg")
    th = np.linspace(0.0, 90.0, 91)
    folded = np.mean([measured_at(m) for m in (th, 180 - th, 180 + th, 360 - th)], axis=0)
    ax.plot(th, folded, "k--", lw=1, label="measured, four quadrants folded")
    for r in rows:
        rim = np.loadtxt(folder(out, run_name(r["model"], r["n"])) / "rim_height.csv", delimiter=",", skiprows=1)
        ax.plot(rim[:, 0], rim[:, 1] - r["z_bottom_mm"], "o-", ms=3,
                label=f"{MODELS[r['model']][0]}, n {r['n']}" + ("" if r["finished"] else " (stopped)"))
    ax.set_xlabel("angle to the rolling direction (degrees)")
    ax.set_ylabel("cup height (mm): bottom's outer face to the rim's top")
    ax.set_xticks(ANGLES)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("ESAFORM 2021 cup, AA6016-T4: the height profile", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def draw(out: Path, levels, models, stroke=None) -> None:
    """Draw each model on each level into out (a run of the same scene by the same code there is
    reused)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stroke = stroke or (QUICK_STROKE if tuple(levels) == QUICK_LEVELS else STROKE)
    for model in models:
        for n in levels:
            s, d = scene_of(model, n, stroke), folder(out, run_name(model, n))
            if _finished_here(d, s):
                say(f"esaform-cup: {run_name(model, n)}: reusing the run in {d}")
                continue
            say(f"esaform-cup: {run_name(model, n)}")
            run_cup(s, d)


def run(out: Path, levels=LEVELS, models=("yld2000", "hill48"), stroke=None) -> list[dict]:
    """Draw each model on each level into out (``draw``), then the tables and the plot."""
    draw(out, levels, models, stroke)
    return tables(out, {m: levels for m in models})


def hypotheses(out: Path, n: int = 12) -> list[dict]:
    """The demo's Yld2000-2d drawn through on n with each assumption of docs/cup.md changed in
    turn (HYPOTHESES), into their own folder:

        python -c "from shellform.studies import esaform_cup as e; e.hypotheses('docs/results/esaform_hypotheses')"
    """
    return run(out, levels=(n,), models=HYPOTHESES)


def gap_holder(out: Path, levels=(16, 20, 24)) -> list[dict]:
    """Yld2000-2d with the holder at the benchmark's gap, with the fit's r_b assumed (1) and left
    free (GAP_HOLDER), on the levels where it draws through, and on the first of them each
    assumption left for its d0 changed in turn (GAP_HOLDER_SUSPECTS), into their own folder:

        python -c "from shellform.studies import esaform_cup as e; e.gap_holder('docs/results/esaform_gap_holder')"
    """
    draw(out, levels, GAP_HOLDER)
    draw(out, levels[:1], GAP_HOLDER_SUSPECTS)
    return tables(out, {**{m: levels for m in GAP_HOLDER}, **{m: levels[:1] for m in GAP_HOLDER_SUSPECTS}})


def lever(out: Path) -> list[dict]:
    """The runs that stopped while the layers' lever arm lagged an increment (docs/cup.md, "The
    lever follows the iterate"): Yld2000-2d with the holder at the gap on n = 12, 16 and 24 (it
    stopped on 12), and Poly6 fitted to either laboratory's data on n = 16 (both stopped), into
    their own folder:

        python -c "from shellform.studies import esaform_cup as e; e.lever('docs/results/esaform_lever')"
    """
    levels = {"yld2000-gap-holder": (12, 16, 24), "poly6-gap-holder": (16,), "poly6-ua-gap-holder": (16,)}
    for model, ns in levels.items():
        draw(out, ns, (model,))
    return tables(out, levels)


def circle(quadrant: np.ndarray) -> np.ndarray:
    """A profile over the circle (the last row repeating the first, as MEASURED) from its first
    quadrant mirrored about 90, 180 and 270 degrees."""
    a, h = quadrant[:, 0], quadrant[:, 1]
    angles = np.concatenate([a, 180.0 - a[::-1][1:], 180.0 + a[1:], 360.0 - a[::-1][1:]])
    return np.column_stack([angles, np.concatenate([h, h[::-1][1:], h[1:], h[::-1][1:]])])


def peers(out: Path) -> list[dict]:
    """The peers' published profiles (PEERS) as rows of the runs' table: h at the angles, the mean,
    d0, d90 and their errors against the measured profile; written to peers.csv and peers.md."""
    rows = []
    for name, quadrant in PEERS.items():
        ref = measured(circle(quadrant))
        rows.append(with_errors({"peer": name, **ref["first"], "mean": ref["mean"]}))
    write_csv(Path(out) / "peers.csv", rows, list(rows[0]))
    (Path(out) / "peers.md").write_text(markdown_table(  # the CSV's own digits
        ["peer's published profile", *(f"h({a:g})" for a in ANGLES), "mean", "d0 (error)", "d90 (error)"],
        [[r["peer"], *(f"{r[f'h{a:g}']:.2f}" for a in ANGLES), f"{r['mean']:.2f} ({_pct(r['err_mean'])})",
          f"{r['d0']:.2f} ({_pct(r['err_d0'])})", f"{r['d90']:.2f} ({_pct(r['err_d90'])})"] for r in as_written(rows)]))
    return rows


def poly6(out: Path, levels=(16, 20, 24)) -> list[dict]:
    """The gap holder's cup with Poly6 (shellform.material.poly6) fitted to the demo's data, with
    PolyN's own Poly6 of the sheet, and fitted to the other laboratory's data (POLY6), into their
    own folder, and the peers' published profiles of their Poly6 (peers.csv, peers.md):

        python -c "from shellform.studies import esaform_cup as e; e.poly6('docs/results/esaform_poly6')"
    """
    draw(out, levels, POLY6)
    peers(out)
    return tables(out, {m: levels for m in POLY6})


def tables(out: Path, levels: dict) -> list[dict]:
    """The tables and the plot of the runs in out (levels: per yield function its levels; runs
    missing there are left out)."""
    out = Path(out)
    rows = []
    for model, ns in levels.items():
        for n in ns:
            if (folder(out, run_name(model, n)) / "summary.json").exists():
                rows.append(row(model, n, out))
    ests = estimates(rows)
    write_csv(out / "esaform_cup.csv", rows, list(dict.fromkeys(k for r in rows for k in r)))
    if ests:
        write_csv(out / "esaform_cup_estimates.csv", ests, ["model", "answer", "values", "p", "estimate", "uncertainty"])
    (out / "esaform_cup.md").write_text(markdown(as_written(rows), as_written(ests)))  # the CSVs' own digits
    plot(out / "esaform_cup.png", rows, out)
    return rows

