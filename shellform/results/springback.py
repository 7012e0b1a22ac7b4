"""The drawn cup's springback in results: its profiles before and after the tools withdraw
(shellform.contact.springback releases them), the wall angle, the flange edge's move, the
residual resultants; springback.csv and springback.png.

A profile is taken along the transverse line y = 0 and the diagonal x = y (the square kind's
LINES): per node on it its initial distance from the centre, its current distance along the
line (x, or the radius on the diagonal) and its height z.
"""

from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.results.tables import write_csv, write_figure
from shellform.tools import square


def _gather(comm, *arrays):
    return [np.concatenate(comm.allgather(a)) for a in arrays]


def profile(X, u, comm, diagonal=False):
    """(initial distance, x or r, z) of the owned nodes (initial positions X, displacements u)
    on the line y = 0 (or x = y), by initial distance from the centre, gathered on every rank."""
    n = len(u)
    x = X[:n] + u
    on = square.LINES["diagonal" if diagonal else "transverse"](X[:n], 1e-6 * max(np.abs(X[:, :2]).max(), 1.0))
    r = np.hypot(x[on, 0], x[on, 1]) if diagonal else x[on, 0]
    rows, = _gather(comm, np.column_stack([np.hypot(X[:n, 0], X[:n, 1])[on], r, x[on, 2]]))
    return rows[np.argsort(rows[:, 0])]


def wall_angle(rows, depth: float) -> float:
    """The wall's angle from the horizontal (degrees, 90: vertical): a line x(z) fitted to the
    profile's points between 30 % and 70 % of the depth."""
    z = rows[:, 2]
    wall = (z < -0.3 * depth) & (z > -0.7 * depth)
    if wall.sum() < 2:
        return float("nan")
    dxdz = np.polyfit(rows[wall, 2], rows[wall, 1], 1)[0]
    return float(90.0 - np.degrees(np.arctan(abs(dxdz))))


SPRINGBACK_LINES = {"transverse": False, "diagonal": True}


def profiles(X, u, comm) -> dict:
    """The transverse and diagonal profiles of a state (before or after springback): X the
    owned nodes' initial positions, u their displacements."""
    return {k: profile(X, u, comm, diagonal=v) for k, v in SPRINGBACK_LINES.items()}


def changes(before: dict, after: dict) -> dict:
    """What springback changed (profiles() before and after): the wall's angle along the
    transverse line before and after, and per line the flange edge's move (its last node's) in
    z and in the distance from the centre."""
    depth = float(-before["transverse"][:, 2].min())
    edge = {k: (before[k][-1], after[k][-1]) for k in SPRINGBACK_LINES}
    return {"wall_angle_deg": {"before": wall_angle(before["transverse"], depth),
                               "after": wall_angle(after["transverse"], depth)},
            "flange_edge_dz_mm": {k: float(a[2] - b[2]) for k, (b, a) in edge.items()},
            "flange_edge_dr_mm": {k: float(a[1] - b[1]) for k, (b, a) in edge.items()}}


def derivatives(X, drawn_u, sprung_u, drawn, sprung, comm) -> dict:
    """{parameter: d/dp of changes()' numbers}, with the drawing's and the springback's
    Sensitivity (`drawn`, `sprung`: nonlinear/sensitivity.py) at the displacements drawn_u and
    sprung_u of the owned nodes (initial positions X): central differences of changes() with the
    sensitivities' step along the displacements' derivatives before and after. The wall's angle
    is a line fitted to the points within a band of depth, and the flange edge a node: where a
    point enters or leaves the band, the angle's derivative is the mean of the two sides'."""
    n = len(drawn_u)
    out = {}
    for par in drawn.parameters:
        step = drawn.step(par.name)
        du = [s.carrier(par.name).reshape(-1, BS)[:n, :3] for s in (drawn, sprung)]
        ends = [changes(profiles(X, drawn_u + sign * step * du[0], comm), profiles(X, sprung_u + sign * step * du[1], comm))
                for sign in (1.0, -1.0)]
        out[par.name] = {key: {k: (ends[0][key][k] - ends[1][key][k]) / (2.0 * step) for k in ends[0][key]}
                         for key in ends[0]}
    return out


def write(outdir: Path, p, title: str, before: dict, released, sensitivities: dict | None = None) -> dict:
    """What springback changed (shellform.contact.springback released the tools' forces into
    `released`): wall angle and flange edge along the transverse line, the diagonal's corner (changes()),
    the unloading's plastic layers, the residual resultants, and their `sensitivities` where
    given (derivatives(); also springback_sensitivities.csv: answer, parameter, derivative);
    springback.csv (both profiles) and
    springback.png (the change along each line: sprung back minus drawn, in z and in the distance
    from the centre, against the node's initial distance from the centre, which runs along the
    wall where the drawn distance folds back on itself)."""
    lines = SPRINGBACK_LINES
    after = profiles(p.initial_positions(), released.displacements(), p.comm)
    rows = [{"line": k, "initial_position_mm": b[0], "before_r_mm": b[1], "before_z_mm": b[2],
             "after_r_mm": a[1], "after_z_mm": a[2]} for k in lines for b, a in zip(before[k], after[k])]
    write_csv(outdir / "springback.csv", rows, list(rows[0]))
    if sensitivities is not None:
        write_csv(outdir / "springback_sensitivities.csv",
                  [{"answer": f"{key}.{k}", "parameter": name, "derivative": d} for name, per in sensitivities.items()
                   for key, values in per.items() for k, d in values.items()], ["answer", "parameter", "derivative"])
    resultants = p.resultants()
    N, M = resultants[..., :3], resultants[..., 3:]
    comm = p.comm
    out = {
        "stopped": None,
        **changes(before, after),
        "unloading_increments": len(released.history),
        "plastic_layers_on_unloading": int(sum(h.plastic_layers for h in released.history)),
        "residual_max_N_per_mm": comm.allreduce(float(np.abs(N[..., :2]).max(initial=0.0)), op=MPI.MAX),
        "residual_max_M_N": comm.allreduce(float(np.abs(M[..., :2]).max(initial=0.0)), op=MPI.MAX),
        **({"sensitivities": sensitivities} if sensitivities is not None else {}),
    }
    if comm.rank == 0:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
        for ax, k in zip(axes, lines):  # the change: on the profiles' scale it does not show
            s0, r = before[k][:, 0], before[k][:, 1]
            ax.plot(s0, after[k][:, 2] - before[k][:, 2], "b-", label="z: vertical")
            ax.plot(s0, after[k][:, 1] - r, "r--", label="r: away from the centre")
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_xlabel("initial distance from the centre (mm)")
            ax.set_ylabel("sprung back minus drawn (mm)")
            ax.set_title(f"{k} line", fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.suptitle(f"{title}: springback", fontsize=10)
        fig.tight_layout()
        write_figure(outdir / "springback.png", fig, dpi=120)
        plt.close(fig)
    return out
