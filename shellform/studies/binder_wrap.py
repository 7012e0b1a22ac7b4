"""Binder wrap: a strip closed onto a cylindrical binder, and its springback.

A flat strip rests on the crown of a die whose binder face is the outside of a cylinder of
radius R (shellform.tools.cylinder). It is wrapped onto it in one of two ways:

- "holder": the holder's face, the inside of the concentric cylinder of radius R + g, comes down
  until the two faces are g = 1.02 t apart (the blank is not ironed: a strip that does not
  thicken needs no bound on its thickness). It touches the strip's ends first.
- "pressed": a dead pressure p on the strip's upper face presses it onto the die alone, p chosen
  so that the wrap reaches 0.8 of the half length (p (L/5)^2 / 2 = 1.5 M): a load under which, in
  a continuum, the contact front moves outward and every section reaches the die's curvature
  once and keeps it.

The strip ends bent to the die's radius, its mid-surface curvature kappa = 1 / (R + t/2).
Released (shellform.contact.springback) it springs back to

    kappa_f = kappa - M(kappa) / D,     D = E t^3 / (12 (1 - nu^2)),

M the section's moment per unit width at that curvature, unloaded elastically: the closed form
of an elastic-plastic bend whose every section is bent monotonically to kappa. The strip is wide
(symmetry on both long sides: plane strain, eps_y = 0) and the bend pure (no friction, the
strip's end free), so a layer at height z carries eps_x = kappa z, eps_y = 0, sigma_z = 0. For
an R that bends it elastically M = D kappa and the strip springs back flat; for one that yields
it,

    M(kappa) = 2 int_0^(t/2) sigma_x(kappa z) z dz,

sigma_x(eps_x) the von Mises layer with the sheet's Swift hardening K (eps0 + p)^n strained
along that path (`section_moment`): 4,000 strain steps per layer, each an implicit return to
the yield surface (a plane-stress Newton on sigma_x, sigma_y and dp), over 400 Gauss points
through the half thickness. This integration is the study's own, not the sheet's return
mapping. The unloading is checked to stay elastic (the residual stresses inside the yield
surface), the closed form's assumption.

The springback depends on the path, not only on the end: a section bent beyond kappa and back
unloads elastically by D (kappa_max - kappa), and its moment drops by that much, where the
monotone bend's M(kappa) lies on the flat plastic part of the moment-curvature curve. At
R = 100 mm, M is a quarter of D kappa, so an overbend of 1 % of kappa lowers the springback by
about 4 %. The study reports the path: on the strip's centre line, each segment's curvature at
every converged increment, and the largest ratio of a segment's largest curvature over the run
to its final one (`overbend`, 1 for a monotone wrap).

Measured on the deformed centre line (y = 0), over its inner half X <= L/2 (inside the wrap for
both ways): the loaded curvature by the circle fitted to its points (`curvature`: robust to the
nodes' scatter within the faces' clearance, which the tangents are not); the springback as the
change of the tangent's turn over that arc, divided by its length (`turn`): the mean of M / D
over it, the elastic unloading's own measure; the curvature after release is their difference.

    shellform study binder-wrap --out docs/results/binder_wrap

writes binder_wrap.csv and binder_wrap.md.
"""

import functools
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform import supports as named_supports
from shellform.assembly.sheet_element import BS, COMPONENTS
from shellform.contact.semi_inverse import ContactControls, SemiInverseDriver
from shellform.contact.springback import release
from shellform.mesh import rectangle
from shellform.nonlinear.driver import Controls, ConvergenceFailure
from shellform.nonlinear.model import SheetModel
from shellform.results.log import say
from shellform.results.tables import as_written, markdown_table, write_csv
from shellform.studies.strip import mild_steel
from shellform.tools.cylinder import Cylinder

T = 1.0  # the strip's thickness (mm)
HALF_LENGTH = 40.0  # the half strip along x (mm)
GAP = 1.02 * T  # the closed holder's face from the die's
EFFECTS = ("bending", "membrane", "geometric_nonlinearity", "plasticity", "finite_strain", "contact")
SUPPORTS = {"left": "symmetry", "bottom": "symmetry", "top": "symmetry"}  # a half strip, plane strain
ELASTIC_R, YIELDING_R = 1500.0, 100.0  # the die's binder face (mm): 0.43 and 6.4 times first yield's curvature
LEVELS = (16, 32, 64, 128)  # cells along the half length
QUICK_LEVELS = (16,)
LAYERS = 9  # thickness points of the sheet
PENETRATION = 1e-4  # the contact's tolerance, in thicknesses (module docstring of the study's table)
CLEARANCE = 0.05  # the holder starts this many thicknesses above the flat strip's ends
STEPS = 32  # increments of the closing (fewer let the first contact at the strip's end fail to settle on 64 cells)
U, W, U_X, W_X = (COMPONENTS.index(c) for c in ("u", "w", "u_x", "w_x"))


def section_moment(mat, kappa: float, t: float = T, points: int = 400, steps: int = 4000):
    """(M, the residual stresses' largest ratio to the yield stress after elastic unloading) of
    the plane-strain bend to curvature kappa (module docstring): M per unit width (N mm / mm).
    Computed once per material and curvature (every row of one radius asks for the same)."""
    return _section_moment(mat.E, mat.nu, mat.K, mat.eps0, mat.n, float(kappa), t, points, steps)


@functools.lru_cache(maxsize=None)
def _section_moment(E, nu, K, eps0, n_swift, kappa, t, points, steps):
    C = E / (1 - nu * nu) * np.array([[1.0, nu], [nu, 1.0]])
    P = np.array([[1.0, -0.5], [-0.5, 1.0]])
    zeta, w = np.polynomial.legendre.leggauss(points)
    z, w = (zeta + 1.0) * t / 4.0, w * t / 4.0  # Gauss points on [0, t/2]
    s, p = np.zeros((points, 2)), np.zeros(points)

    def flow(p):  # Swift: (sigma, dsigma/dp)
        return K * (eps0 + p) ** n_swift, n_swift * K * (eps0 + p) ** (n_swift - 1)

    def equivalent(s):
        return np.sqrt(np.einsum("ni,ij,nj->n", s, P, s))

    for _ in range(steps):
        trial = s + (kappa * z / steps)[:, None] * C[:, 0]  # d eps = (kappa z / steps, 0)
        yielding = equivalent(trial) > flow(p)[0] * (1 + 1e-12)
        x, dp = trial[yielding].copy(), np.zeros(int(yielding.sum()))
        for _ in range(30):  # r = (s - trial + dp C n, sigma_eq(s) - sigma(p + dp)), n = P s / sigma_eq
            eq = equivalent(x)
            n = x @ P / eq[:, None]
            sig, dsig = flow(p[yielding] + dp)
            r = np.column_stack([x - trial[yielding] + dp[:, None] * (n @ C), eq - sig])
            J = np.zeros((len(x), 3, 3))
            J[:, :2, :2] = np.eye(2) + dp[:, None, None] * np.einsum(
                "ij,njk->nik", C, (P[None] - n[:, :, None] * n[:, None, :]) / eq[:, None, None])
            J[:, :2, 2] = n @ C
            J[:, 2, :2] = n
            J[:, 2, 2] = -dsig
            delta = np.linalg.solve(J, -r[:, :, None])[:, :, 0]
            x, dp = x + delta[:, :2], dp + delta[:, 2]
            if np.abs(r).max(initial=0.0) < 1e-10 * E:
                break
        s[yielding], p[yielding] = x, p[yielding] + dp
        s[~yielding] = trial[~yielding]
    M = 2.0 * float(np.sum(w * s[:, 0] * z))
    unloaded = s - (M / _plate_stiffness(E, nu, t) * z)[:, None] * C[:, 0]  # unloaded by dkappa = M / D
    return M, float((equivalent(unloaded) / flow(p)[0]).max())


def bending_stiffness(mat, t: float = T) -> float:
    """D = E t^3 / (12 (1 - nu^2)), the plane-strain section's elastic moment per curvature."""
    return _plate_stiffness(mat.E, mat.nu, t)


def _plate_stiffness(E, nu, t):
    return E * t**3 / (12 * (1 - nu * nu))


def centre_line(X: np.ndarray, q: np.ndarray, comm):
    """(X_1, the tangent's turn from the x axis (> 0 bending down), the arc length from X_1 = 0)
    at the nodes of the strip's centre line y = 0, all ranks: X the owned nodes' initial
    positions, q their carrier rows (n, BS)."""
    line = np.abs(X[:, 1]) < 1e-9
    gather = comm.allgather((X[line, 0], q[line]))
    x = np.concatenate([g[0] for g in gather])
    rows = np.concatenate([g[1] for g in gather])
    order = np.argsort(x)
    x, rows = x[order], rows[order]
    dx, dz = 1.0 + rows[:, U_X], rows[:, W_X]
    stretch = np.hypot(dx, dz)
    return x, np.arctan2(-dz, dx), np.concatenate([[0.0], np.cumsum(0.5 * (stretch[1:] + stretch[:-1]) * np.diff(x))])


def curvature(X: np.ndarray, q: np.ndarray, comm, reach: float = 0.5 * HALF_LENGTH) -> float:
    """The curvature of the circle through the centre line's point at X_1 = 0, (0, z0), fitted
    by least squares to its points with X_1 <= reach: k (x^2 + (z - z0)^2) = 2 (z0 - z) (k = 0
    for a straight line)."""
    line = (np.abs(X[:, 1]) < 1e-9) & (X[:, 0] <= reach + 1e-9)
    x = X[line, 0] + q[line, U]
    z = X[line, 2] + q[line, W]
    centre = np.abs(X[line, 0]) < 1e-9
    z0 = comm.allreduce(float(z[centre].sum()), op=MPI.SUM) / comm.allreduce(int(centre.sum()), op=MPI.SUM)
    a, b = x * x + (z - z0) ** 2, 2.0 * (z0 - z)
    return comm.allreduce(float(a @ b), op=MPI.SUM) / comm.allreduce(float(a @ a), op=MPI.SUM)


def turn(X: np.ndarray, q: np.ndarray, comm, reach: float = 0.5 * HALF_LENGTH) -> tuple[float, float]:
    """(the centre line's tangent's turn from X_1 = 0 to reach, the arc's length there),
    interpolated linearly between its nodes."""
    x, angle, s = centre_line(X, q, comm)
    return float(np.interp(reach, x, angle)), float(np.interp(reach, x, s))


def segments(X: np.ndarray, q: np.ndarray, comm) -> tuple[np.ndarray, np.ndarray]:
    """(the segments' left ends X_1, their curvatures) along the centre line."""
    x, angle, s = centre_line(X, q, comm)
    return x[:-1], np.diff(angle) / np.diff(s)


def wrapped(radius: float, n: int, closing: str = "holder", mat=None, comm=MPI.COMM_WORLD) -> tuple[dict, object]:
    """The strip (n cells along its half length) wrapped onto the binder of radius `radius` by
    `closing` ("holder" or "pressed") and released: (a row of the study's table, the driver)."""
    mat = mat or mild_steel()
    rect = rectangle(comm, 2 * HALF_LENGTH, 2 * HALF_LENGTH / n, region="quarter", n=n)  # one row of cells
    model = SheetModel(rect.mesh, mat.pack(), T, EFFECTS, LAYERS)
    bcs = named_supports.boundary_conditions(model.V, model.components, rect, SUPPORTS,
                                             fixed=named_supports.sheet_fixed_components)
    z_axis = -T / 2 - radius  # the die's crown touches the flat strip's lower face at x = 0
    die = Cylinder(radius, z_axis)
    pressure = 0.0
    if closing == "holder":  # it starts above the flat strip's upper face, lowest over its end
        rise = T / 2 + CLEARANCE * T - (z_axis + np.sqrt((radius + GAP) ** 2 - HALF_LENGTH**2))
        tools, travel = [Cylinder(radius + GAP, z_axis + rise, inside=True), die], [-rise, 0.0]
    elif closing == "pressed":
        tools, travel = [die], [0.0]
        pressure = 1.5 * 2.0 * section_moment(mat, 1.0 / (radius + T / 2))[0] / (HALF_LENGTH / 5) ** 2
    else:
        raise ValueError(f"closing: 'holder' or 'pressed', got {closing!r}")
    driver = SemiInverseDriver(
        model, bcs, tools, travel, pressure=-pressure, verbose=False, contact=ContactControls(PENETRATION * T),
        controls=Controls(initial_step=1.0 / STEPS, max_step=2.0 / STEPS, max_iterations=25, rtol=1e-8))
    X, owned = driver.nodes.X, driver.n_owned
    path = []

    def record(d):
        path.append(segments(X[:owned], d.q.x.array.reshape(-1, BS)[:owned], comm)[1])

    t0 = time.perf_counter()
    driver.run(1.0, on_increment=record)
    rows = driver.q.x.array.reshape(-1, BS)[:owned]
    loaded, (turned, arc) = curvature(X[:owned], rows, comm), turn(X[:owned], rows, comm)
    left, final = segments(X[:owned], rows, comm)
    inner = left < 0.5 * HALF_LENGTH
    sprung = release(driver)
    springback = (turned - turn(X[:owned], sprung.q.x.array.reshape(-1, BS)[:owned], comm)[0]) / arc
    return {"closing": closing, "R_mm": radius, "n": n, "pressure_MPa": pressure, "kappa_loaded": loaded,
            "springback": springback, "kappa_sprung": loaded - springback,
            "overbend": float((np.max(path, axis=0)[inner] / final[inner]).max()),
            "segment_spread": float(final[inner].max() / final[inner].min()),
            "increments": len(driver.history), "iterations": sum(h.iterations for h in driver.history),
            "unloading_plastic_layers": int(sum(h.plastic_layers for h in sprung.history)),
            "seconds": time.perf_counter() - t0}, driver


def with_closed_form(r: dict, mat=None) -> dict:
    """r with the closed forms (module docstring) and the errors: the loaded curvature against
    1 / (R + t/2), the springback kappa - kappa_f against M / D."""
    mat = mat or mild_steel()
    kappa = 1.0 / (r["R_mm"] + T / 2)
    M, unloaded = section_moment(mat, kappa)
    D = bending_stiffness(mat)
    return {**r, "kappa_closed": kappa, "M_over_D_kappa": M / (D * kappa), "springback_closed": M / D,
            "err_loaded": r["kappa_loaded"] / kappa - 1.0, "err_springback": r["springback"] / (M / D) - 1.0,
            "unloaded_over_yield": unloaded}


COLUMNS = ["closing", "R_mm", "n", "pressure_MPa", "kappa_closed", "kappa_loaded", "err_loaded", "M_over_D_kappa",
           "springback_closed", "springback", "err_springback", "kappa_sprung", "overbend", "segment_spread",
           "unloaded_over_yield", "unloading_plastic_layers", "increments", "iterations", "seconds"]


def markdown(rows: list[dict]) -> str:
    return markdown_table(
        ["wrapped by", "R (mm)", "cells along", "loaded curvature, error",
         "springback: closed form M / D, measured, error", "curvature after release",
         "largest overbend, spread of the segments", "increments, iterations", "s"],
        [[r["closing"], f"{r['R_mm']:g}", f"{r['n']}", f"{r['kappa_loaded']:.6g}, {100 * r['err_loaded']:+.2f} %",
          f"{r['springback_closed']:.6g}, {r['springback']:.6g}, {100 * r['err_springback']:+.1f} %",
          f"{r['kappa_sprung']:.4g}", f"{r['overbend']:.3f}, {r['segment_spread']:.3f}",
          f"{r['increments']}, {r['iterations']}", f"{r['seconds']:.0f}"] for r in rows])


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    """The elastic R wrapped by the holder on the first level; the yielding R by the holder and
    pressed, on every level."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    cases = [("holder", ELASTIC_R, levels[0])] + [(c, YIELDING_R, n) for c in ("holder", "pressed") for n in levels]
    rows, stopped = [], []
    for closing, R, n in cases:
        try:
            rows.append(with_closed_form(wrapped(R, n, closing)[0]))
        except ConvergenceFailure as err:  # a wrap that stops is a row of its own, with its cause
            stopped.append({"closing": closing, "R_mm": R, "n": n, "stopped": str(err)})
            say(f"binder wrap, {closing}, R {R:g} mm, n {n}: stopped: {err}")
            continue
        r = rows[-1]
        say(f"binder wrap, {closing}, R {R:g} mm, n {n}: loaded {r['kappa_loaded']:.6g} "
            f"({100 * r['err_loaded']:+.2f} %), springback {r['springback']:.6g} "
            f"({100 * r['err_springback']:+.1f} %), overbend {r['overbend']:.3f}")
    write_csv(outdir / "binder_wrap.csv", rows, COLUMNS)
    (outdir / "binder_wrap.md").write_text(markdown(as_written(rows)) + "".join(
        f"\n{r['closing']}, R {r['R_mm']:g} mm, {r['n']} cells along: stopped ({r['stopped']})\n" for r in stopped))
    return rows
