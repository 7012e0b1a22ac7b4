"""The answers' sensitivities at a report, their first-order uncertainty, the table and the
tornado chart (the derivatives themselves: shellform.nonlinear.sensitivity).

At each report of a sheet scene with `[output] sensitivities`, every answer a of the report
gets da/dp for every parameter p:

    u, v, w                  at the origin, and "<probe>.u" ... at each [[output.probe]]: from dq/dp
    extreme_u, _v, _w        the largest-magnitude displacement's derivative at its vertex (the
                             place held: where the extreme jumps to another vertex, so does this)
    max_equivalent_plastic_strain   at the cell holding the maximum: the mean over its points
                             of dp/dp in the layer holding each point's maximum
    min_thickness_strain     (finite strains) at the cell holding the minimum: its mean
                             d ln lambda3 / dp

With a scatter s_p per parameter (`[output] scatter`, standard deviations, the parameters taken
as independent), the first-order standard deviation of an answer is
sd(a) = sqrt(sum_p (da/dp s_p)^2), and a parameter's share of the variance
(da/dp s_p)^2 / sd(a)^2.

Written into the output folder:
    sensitivities.csv   per report, answer and parameter: the parameter's value, da/dp, the
                        stated change (the scatter's s_p, else a tenth of the value) and
                        da/dp times it
    tornado.png         ([output] png) at the last report: each answer's change for each parameter's stated
                        change, largest first (an answer whose changes are all at round-off
                        beside the largest of its units, a zero displacement's, is left out)
summary.json: "sensitivities" in each report, {parameter: {answer: da/dp}}; "uncertainty" (with
a scatter) at the last report, {answer: {"sd", "shares": {parameter: share}}}.

A drawn cup's answers (a tool scene whose parts have derivatives: docs/sensitivity.md, Tool
scenes) are its report's: DX, DY, DD, the punch force (kN) and the peak thinning
min_thickness_strain at its node (results/cup.py, derivatives), and with the forming-limit view
the smallest margin to its curve, min_margin, at its cell (cup.margin_derivative); the CSV's first
column is then stroke_mm.
"""

import math
from pathlib import Path

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.results.tables import write_csv, write_figure

ROUND_OFF = 1e-9  # the chart leaves out an answer whose changes are below this share of the largest of its units
COLUMNS = ["load_factor", "answer", "parameter", "value", "derivative", "change", "answer_change"]


def answers(p, sens, record: dict, probes) -> dict:
    """{parameter: {answer: d answer / d parameter}} at the current (reported) state of the
    sheet problem p; record: the report (its extremes' places), probes: the scene's."""
    comm = p.model.mesh.comm
    f = fem.Function(p.model.V)
    out = {}
    for par in sens.parameters:
        f.x.array[:] = sens.carrier(par.name)
        d = {k: p.value(k, 0.0, 0.0, of=f) for k in ("u", "v", "w")}
        for probe in probes:
            d.update({f"{probe.name}.{k}": p.value(k, probe.x, probe.y, of=f) for k in ("u", "v", "w")})
        for k, extreme in record["extremes"].items():
            d[f"extreme_{k}"] = p.value(k, *extreme["at_initial_xy"], of=f)
        d["max_equivalent_plastic_strain"] = at_extreme(comm, *_peak_plastic_strain(p.model, sens.state(par.name)["p"]))
        if p.model.finite:
            e33 = p.model.thickness_strain()
            d["min_thickness_strain"] = at_extreme(comm, -e33, sens.thickness_strain(par.name))
        out[par.name] = d
    return out


def _peak_plastic_strain(model, dp):
    """Per owned cell the equivalent plastic strain of cell_fields (the layers' maximum, the
    points' mean) and its derivative along dp (the layer holding each point's maximum)."""
    p = model.history()["p"]
    k = np.argmax(p, axis=2)[..., None]
    return p.max(axis=2).mean(axis=1), np.take_along_axis(dp, k, axis=2)[..., 0].mean(axis=1)


def at_extreme(comm, values, derivatives) -> float:
    """The derivative at the cell where `values` is largest, over all ranks."""
    i = int(np.argmax(values)) if values.size else -1
    mine = (float(values[i]), float(derivatives[i])) if i >= 0 else (-math.inf, 0.0)
    return max(comm.allgather(mine), key=lambda c: c[0])[1]


def changes(parameters, scatter) -> dict:
    """The stated change of each parameter: its scatter (standard deviation) where given, else a
    tenth of its value."""
    return {par.name: (scatter[i] if scatter else 0.1 * abs(par.value)) for i, par in enumerate(parameters)}


def uncertainty(derivatives: dict, scatter: dict) -> dict:
    """{answer: {"sd", "shares": {parameter: share of the variance}}} (module docstring)."""
    out = {}
    for answer in next(iter(derivatives.values())):
        terms = {name: (d[answer] * scatter[name]) ** 2 for name, d in derivatives.items()}
        var = sum(terms.values())
        out[answer] = {"sd": math.sqrt(var), "shares": {k: (t / var if var > 0 else 0.0) for k, t in terms.items()}}
    return out


def summary(sens, rows: list[dict], scatter) -> dict:
    """summary.json's "sensitivity_checks" (where the derivatives are one-sided means, the free
    rows' check and the corrections its solves took: nonlinear/sensitivity.py) and, with a
    scatter, "uncertainty" at the last report (`rows`: the reports, their "sensitivities")."""
    out = {"sensitivity_checks": {
        "increments_with_switching_layers": [i + 1 for i, k in enumerate(sens.switches) if k],
        "largest_free_residual": max(sens.free_residual, default=0.0),
        "corrections": int(sum(sens.corrections)),
        "increments_corrected": int(sum(1 for k in sens.corrections if k))}}
    if scatter and rows and "sensitivities" in rows[-1]:
        out["uncertainty"] = uncertainty(rows[-1]["sensitivities"], changes(sens.parameters, scatter))
    return out


def write(outdir: Path, reports: list[dict], parameters, scatter, title: str, picture: bool = True,
          at: str = "load_factor") -> None:
    """sensitivities.csv and (with `picture`) tornado.png from the reports' "sensitivities"
    (rank 0 writes); `at`: the reports' key of where they were taken (a cup's "stroke_mm"), the
    CSV's first column."""
    stated = changes(parameters, scatter)
    values = {par.name: par.value for par in parameters}
    rows = [{at: r[at], "answer": answer, "parameter": name, "value": values[name],
             "derivative": d, "change": stated[name], "answer_change": d * stated[name]}
            for r in reports if "sensitivities" in r
            for name, ds in r["sensitivities"].items() for answer, d in ds.items()]
    write_csv(Path(outdir) / "sensitivities.csv", rows, [at] + COLUMNS[1:])
    if picture and MPI.COMM_WORLD.rank == 0 and rows:
        where = "load factor" if at == "load_factor" else at.replace("_mm", " (mm)")
        _tornado(Path(outdir) / "tornado.png", reports[-1], stated, f"{title}: sensitivities at {where} "
                 f"{reports[-1][at]:.4g}")


def _tornado(path: Path, report: dict, stated: dict, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sens = report["sensitivities"]
    names = list(sens)
    largest = {a: max(abs(sens[n][a] * stated[n]) for n in names) for a in next(iter(sens.values()))}
    kind = lambda a: "strain" in a  # noqa: E731  the answers' units: strains, or lengths
    top = {k: max([c for a, c in largest.items() if kind(a) == k], default=0.0) for k in (True, False)}
    answers_ = [a for a, c in largest.items() if c > ROUND_OFF * top[kind(a)]]  # not those at round-off
    fig, axes = plt.subplots(len(answers_), 1, figsize=(7, 1.0 + 0.45 * len(names) * len(answers_)), squeeze=False)
    for ax, answer in zip(axes[:, 0], answers_):
        bars = sorted(((sens[n][answer] * stated[n], n) for n in names), key=lambda b: abs(b[0]))
        ax.barh([f"{n} {stated[n]:+.3g}" for _, n in bars], [b for b, _ in bars],
                color=["#0072b2" if b >= 0 else "#d55e00" for b, _ in bars])
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_title(answer, fontsize=9, loc="left")
        ax.tick_params(labelsize=8)
    axes[-1, 0].set_xlabel("change of the answer for the stated change of each parameter")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    write_figure(path, fig)
    plt.close(fig)
