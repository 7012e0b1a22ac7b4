"""A sheet strip pulled to a stretch of 1.5, and an equibiaxial stretch: finite-strain plasticity
against its closed forms (issue 10).

Quarter strip 10 x 2 x 1 (symmetry on the left and bottom), pulled along x:

- homogeneous: u = a x (and u_x = a, u_y = 0) held at every vertex, the rest free. Uniaxial
  stress without a neck, a material test on the structural model. The force on the end gives
  the nominal stress F / (w0 t0) = tau / lambda (tau the Kirchhoff stress, conjugate to the
  logarithmic strain); the closed form is sigma_f(p) / lambda, p = ln lambda - tau / E.
- free: only the end is pulled (u = a L, u_y = 0). The force peaks at Considere's strain, where
  d sigma / d eps = sigma (Swift: eps = n - eps0; power law eps/eps_y = (sigma/sigma_y)^N:
  eps = 1/N); past it the strip necks. With the elastic strain the force peaks a little later
  (force_maximum_strain: 0.2532 for the mild steel, 0.25 for the power law, whose strain is the
  total one). A NeckWatch given to `strip` finds the neck's onset there from the sections'
  membrane stability (shellform.results.neck), held homogeneous or free.
- equibiaxial: a quarter square 1 x 1 with u = a x, v = a y held everywhere. Hill 1979 gives
  tau = sigma_f(p) (2 (1 + r))^(1/m) / 2, p = (2 (1 + r))^(1/m) (ln lambda - (1 - nu) tau / E).

    shellform study strip --out docs/results/strip

writes strip.csv (nominal stress and thickness strain against stretch: closed form, finite
strain, the small-strain model of issue 3, the free strip) and strip.png.
"""

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.material import Hill79Material, flow_stress
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.problem import SheetProblem
from shellform.results.log import say
from shellform.results.neck import NeckWatch
from shellform.results.tables import write_csv

LENGTH, WIDTH, T0 = 5.0, 1.0, 1.0  # the quarter strip
SHEET = ("bending", "membrane", "geometric_nonlinearity", "plasticity", "anisotropy")


def mild_steel(r=1.0, m=2.0):
    """The demo's mild steel: Swift 565.32 (0.007117 + p)^0.2589 MPa."""
    return Hill79Material(E=206e3, nu=0.3, r=r, m=m, hardening="swift", K=565.32, eps0=0.007117, n=0.2589)


def power_law(r=1.0, m=2.0):
    """eps / eps_y = (sigma / sigma_y)^4 above sigma_y = 200 MPa (Considere at eps = 1/4)."""
    return Hill79Material(E=206e3, nu=0.3, r=r, m=m, hardening="power", yield_stress=200.0, n=4.0)


def effects(finite=True):
    return SHEET + (("finite_strain",) if finite else ())


def considere_strain(mat) -> float:
    """The true strain at the force maximum of a uniaxial bar (rigid-plastic)."""
    if mat.hardening == "swift":
        return mat.n - mat.eps0
    return 1.0 / mat.n


def force_maximum_strain(mat) -> float:
    """The true strain ln lambda at the maximum of the nominal stress tau(lambda) / lambda of
    uniaxial_kirchhoff (its elastic part included): where d tau / d eps = tau."""
    from scipy.optimize import minimize_scalar

    e = considere_strain(mat)
    found = minimize_scalar(lambda x: -uniaxial_kirchhoff(mat, np.exp(x)) / np.exp(x), bounds=(0.5 * e, 1.5 * e),
                            method="bounded", options={"xatol": 1e-9})
    return float(found.x)


def uniaxial_kirchhoff(mat, lam: float) -> float:
    """tau with tau = sigma_f(ln lambda - tau / E) (Swift), or sigma(ln lambda) of the power
    law, whose strain is the total one."""
    packed, e = mat.pack(), np.log(lam)
    if mat.hardening == "power":  # eps = eps_y (sigma/sigma_y)^N above yield
        return mat.yield_stress * max(e * mat.E / mat.yield_stress, 1.0) ** (1.0 / mat.n)
    tau = flow_stress(e, packed)[0]
    for _ in range(100):
        tau = flow_stress(e - tau / mat.E, packed)[0]
    return tau


def equibiaxial_kirchhoff(mat, lam: float, elastic=True) -> float:
    """tau of Hill 1979 in equibiaxial flow at the in-plane stretch lambda (elastic=False: the
    rigid-plastic estimate at the true strain)."""
    c = (2.0 * (1.0 + mat.r)) ** (1.0 / mat.m)
    packed, e = mat.pack(), np.log(lam)
    tau = flow_stress(c * e, packed)[0] * c / 2.0
    for _ in range(100 if elastic else 0):
        tau = flow_stress(c * (e - (1.0 - mat.nu) * tau / mat.E), packed)[0] * c / 2.0
    return tau


def strip(mat, stretch: float, homogeneous=True, finite=True, steps=10, n=1, comm=MPI.COMM_WORLD, watch=None):
    """Pull the quarter strip to `stretch`; returns (problem, rows) with a row per increment:
    stretch, nominal stress, thickness strain ln(t/t0), width strain ln(w/w0) and the least
    membrane stability of the cells (shellform.material.stability). watch: a NeckWatch
    (shellform.results.neck) told the stretch and the cells' state after every increment."""
    a = stretch - 1.0
    if homogeneous:
        held = {("all", "u"): lambda x, y: a * x, ("all", "u_x"): a, ("all", "u_y"): 0.0}
    else:
        held = {("right", "u"): a * LENGTH, ("right", "u_y"): 0.0}
    p = SheetProblem.on_rectangle(
        comm, 2 * LENGTH, 2 * WIDTH, n, mat, T0, effects(finite), region="quarter",
        supports={"left": "symmetry", "bottom": "symmetry"}, prescribed=held,
        controls=Controls(initial_step=1.0 / steps, max_step=1.0 / steps, min_step=1e-4))
    rows = []

    def record(d):
        f = p.model.cell_fields()
        e33 = comm.allreduce(float(f["thickness_strain"].sum()), op=MPI.SUM) / comm.allreduce(
            f["thickness_strain"].size, op=MPI.SUM)
        stability = p.model.membrane_stability()
        rows.append({"stretch": 1.0 + d.lam * a, "nominal_stress": p.reaction("right", "u") / (WIDTH * T0),
                     "thickness_strain": e33,
                     "width_strain": float(np.log(1.0 + p.value("v", LENGTH, WIDTH) / WIDTH)),
                     "stability": comm.allreduce(float(stability.min(initial=np.inf)), op=MPI.MIN)})
        if watch is not None:
            watch.reached(1.0 + d.lam * a, stability, f["thickness_strain"], p.model.cell_centres(), f["major_strain"])

    p.driver.run(1.0, on_increment=record)
    return p, rows


def equibiaxial(mat, stretch: float, steps=5, comm=MPI.COMM_WORLD):
    """The quarter square stretched by `stretch` both ways; returns (tau, thickness strain)."""
    a = stretch - 1.0
    held = {("all", "u"): lambda x, y: a * x, ("all", "v"): lambda x, y: a * y, ("all", "u_x"): a,
            ("all", "v_y"): a, ("all", "u_y"): 0.0, ("all", "v_x"): 0.0}
    p = SheetProblem.on_rectangle(
        comm, 2.0, 2.0, 1, mat, T0, effects(True), region="quarter",
        supports={"left": "symmetry", "bottom": "symmetry"}, prescribed=held,
        controls=Controls(initial_step=1.0 / steps, max_step=1.0 / steps))
    p.driver.run(1.0)
    e33 = float(p.model.cell_fields()["thickness_strain"].mean())
    return stretch * p.reaction("right", "u") / (1.0 * T0), e33


COLUMNS = ["model", "stretch", "nominal_stress", "closed_form", "rel_error", "thickness_strain",
           "thickness_closed_form", "seconds"]


def run(outdir: Path, stretch=1.5, steps=20) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    mat = mild_steel()
    rows = []
    for name, homogeneous, finite in (("finite strain, homogeneous", True, True),
                                      ("small strain (issue 3), homogeneous", True, False),
                                      ("finite strain, free end", False, True)):
        t0 = time.perf_counter()
        watch = NeckWatch(MPI.COMM_WORLD, "stretch", "initial_xy")
        _, path = strip(mat, stretch, homogeneous, finite, steps, n=1 if homogeneous else 4, watch=watch)
        seconds = time.perf_counter() - t0
        for r in path:
            closed = uniaxial_kirchhoff(mat, r["stretch"]) / r["stretch"]
            rows.append({"model": name, **{k: r[k] for k in ("stretch", "nominal_stress", "thickness_strain")},
                         "closed_form": closed, "rel_error": r["nominal_stress"] / closed - 1,
                         "thickness_closed_form": -np.log(r["stretch"]) / 2, "seconds": seconds})
        necked = f", neck from ln(stretch) {np.log(watch.onset['stretch']):.4f}" if watch.onset else ""
        say(f"strip: {name}: {path[-1]['nominal_stress']:.1f} MPa at stretch {stretch}{necked} ({seconds:.1f} s)")
    write_csv(outdir / "strip.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "strip.md").write_text(markdown(as_written))  # the CSV's digits, as docs/material.md includes it
    _plot(outdir / "strip.png", rows, mat)
    return rows


def markdown(rows: list[dict], stretches=(1.1, 1.3, 1.5)) -> str:
    """The table docs/material.md includes (strip.md): the homogeneous strip's nominal stress and
    thickness strain at three stretches, finite against small strains and the closed form."""
    at = {(r["model"], round(float(r["stretch"]), 6)): r for r in rows}
    finite, small = "finite strain, homogeneous", "small strain (issue 3), homogeneous"
    out = ("| stretch | closed form tau/lambda | finite strain | small strain (before) "
           "| thickness strain: -(ln lambda)/2, finite, small |\n" + "|---" * 5 + "|\n")
    for x in (x for x in stretches if (finite, x) in at and (small, x) in at):  # the stretches the runs reached
        f, s = at[finite, x], at[small, x]
        out += (f"| {x:g} | {f['closed_form']:.1f} MPa | {f['nominal_stress']:.1f} MPa | "
                f"{s['nominal_stress']:.1f} MPa ({100 * s['rel_error']:+.0f} %) | "
                f"{f['thickness_closed_form']:.3f}, {f['thickness_strain']:.3f}, {s['thickness_strain']:.3f} |\n")
    return out


def _plot(path, rows, mat):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    lam = np.linspace(1.0 + 1e-3, max(r["stretch"] for r in rows), 200)
    a.plot(lam, [uniaxial_kirchhoff(mat, x) / x for x in lam], "k-", label="closed form sigma(ln lambda)/lambda")
    b.plot(lam, -np.log(lam) / 2, "k-", label="closed form -ln(lambda)/2")
    for name, marker in zip(dict.fromkeys(r["model"] for r in rows), "os^"):
        sel = [r for r in rows if r["model"] == name]
        a.plot([r["stretch"] for r in sel], [r["nominal_stress"] for r in sel], marker, ms=4, label=name)
        b.plot([r["stretch"] for r in sel], [r["thickness_strain"] for r in sel], marker, ms=4, label=name)
    e = considere_strain(mat)
    a.axvline(np.exp(e), color="grey", ls=":", label=f"Considere, ln lambda = n - eps0 = {e:.3f}")
    a.set_xlabel("stretch")
    a.set_ylabel("nominal stress (MPa)")
    b.set_xlabel("stretch")
    b.set_ylabel("thickness strain ln(t/t0)")
    a.legend(fontsize=7)
    b.legend(fontsize=7)
    fig.suptitle("Mild-steel strip (Swift), von Mises, quarter 10 x 2 x 1")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
