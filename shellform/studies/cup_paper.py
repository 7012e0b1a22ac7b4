"""The paper's square-cup figures (the paper's example 2): Figs. 5 to 8.

    shellform study cup-mesh --out docs/results/cup_mesh      # first: Figs. 5, 6 use its meshes
    shellform study cup-hard --out docs/results/cup_hard      # first: Fig. 8 uses its 4 t / 20 mm case
    shellform study cup-paper --out docs/results/cup_paper    # then: the friction runs and the figures

demos/square_cup.toml (BHF 2 t = 19.6 kN, mu 0.1, r 1.5, die radius 5 mm, 30 mm):
- Figs. 5 and 6: the thickness strain along the diagonal and along the transverse centre line
  y = 0 at 30 mm on the 12 x 12, 16 x 16 and 24 x 24 quarter meshes (cup-mesh's runs). The
  lines are measured along the initial blank: a node's distance from the centre before forming.
- Fig. 7: the peak thinning (most negative thickness strain, at the punch's corner) at 30 mm
  against friction 0, 0.05, 0.1, 0.15, 0.2 on 16 x 16 (mu 0.1: cup-mesh's n 16 run; mu 0 runs
  without the effect friction).
- Fig. 8: the diagonal profile with BHF 4 t and die radius 20 mm (cup-hard's run) beside the
  2 t / 5 mm one.
Writes cup_paper.csv (Fig. 7's runs), cup_paper.md (the four figures' tables, which docs/cup.md
includes: `markdown`) and fig5_diagonal.png, fig6_transverse.png, fig7_friction.png,
fig8_diagonal.png.
"""

import csv
import json
from pathlib import Path

from shellform.errors import InputError
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import draw, folder, variant

FRICTION = (0.0, 0.05, 0.1, 0.15, 0.2)
MESHES = ("n 12", "n 16", "n 24")
COLUMNS = ["friction", "stroke_mm", "min_thickness_strain", "where_initial_xy_mm", "punch_force_30_kN",
           "DX", "DD", "increments", "newton_iterations", "wall_s", "stopped", "run"]


def friction_runs() -> dict:
    """(name, scene) of Fig. 7's runs other than the demo's mu 0.1."""
    demo = variant(16)
    without = [e for e in demo.effects if e != "friction"]  # mu 0: no friction, nor its effect
    return {f"mu {mu:g}": variant(16, tools__friction=mu, **({"effects": without} if mu == 0.0 else {}))
            for mu in FRICTION if mu != 0.1}


def run(out: Path, meshes: Path | None = None, hard: Path | None = None):
    """The friction runs into out, then the figures; meshes and hard: the cup-mesh and cup-hard
    studies' folders, by default beside out (as the commands above place them), checked before
    the first run."""
    out = Path(out)
    meshes = Path(out.resolve().parent / "cup_mesh" if meshes is None else meshes)
    hard = Path(out.resolve().parent / "cup_hard" if hard is None else hard)
    needed = [folder(meshes, name) for name in MESHES] + [folder(hard, "BHF 4t, die radius 20 mm")]
    missing = [str(d) for d in needed if not (d / "summary.json").is_file()]
    if missing:
        raise InputError("--out", f"no run in {', '.join(missing)}: run `shellform study cup-mesh --out {meshes}` "
                                  f"and `shellform study cup-hard --out {hard}` first")
    out.mkdir(parents=True, exist_ok=True)
    for name, s in friction_runs().items():
        say(f"cup-paper: {name}")
        draw(name, s, out)
    return figures(out, meshes, hard)


def _shown(d: Path) -> str:
    """A run's folder as the table shows it: from the working folder when it lies inside (the
    clone's root, where the commands above run)."""
    try:
        return str(Path(d).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(d)


def _line(run_dir: Path, which: str):
    with open(run_dir / f"thickness_{which}.csv") as f:
        rows = list(csv.DictReader(f))
    return [float(r["initial_position_mm"]) for r in rows], [float(r["thickness_strain"]) for r in rows]


def figures(out: Path, meshes: Path, hard: Path) -> list[dict]:
    demo = folder(meshes, "n 16")
    rows = []
    for mu in FRICTION:
        d = demo if mu == 0.1 else folder(out, f"mu {mu:g}")
        s = json.loads((d / "summary.json").read_text())
        rows.append({"friction": mu, "stroke_mm": s["stroke_mm"], "min_thickness_strain": s["min_thickness_strain"],
                     "where_initial_xy_mm": " ".join(f"{v:.1f}" for v in s["where_initial_xy_mm"]),
                     "punch_force_30_kN": s["punch_force_kN"][-1]["force"], "DX": s["draw_in_mm"][-1]["DX"],
                     "DD": s["draw_in_mm"][-1]["DD"], "increments": s["increments"],
                     "newton_iterations": s["newton_iterations"], "wall_s": s["wall_time_s"]["total"],
                     "stopped": s["stopped"] or "", "run": _shown(d)})
    write_csv(out / "cup_paper.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (out / "cup_paper.md").write_text(markdown(as_written, meshes, hard))  # the CSV's digits, as a test reads them
    _plots(out, meshes, hard, rows)
    return rows


def _profile(run_dir: Path) -> dict:
    """What the tables show of one run: per line its strain at the centre, its most negative and
    its largest strain with their initial positions, its strain at the blank's edge; and the peak
    punch force (force_stroke.csv)."""
    out = {}
    for which in ("diagonal", "transverse"):
        x, e = _line(run_dir, which)
        low, high = min(range(len(e)), key=e.__getitem__), max(range(len(e)), key=e.__getitem__)
        out[which] = {"centre": e[0], "thinning": f"{e[low]:.3f} at {x[low]:.0f} mm",
                      "thickening": f"{e[high]:+.3f} at {x[high]:.0f} mm", "edge": e[-1]}
    with open(run_dir / "force_stroke.csv") as f:
        out["peak_force"] = max(float(r["punch_force_kN"]) for r in csv.DictReader(f))
    return out


def markdown(rows: list[dict], meshes: Path, hard: Path) -> str:
    """The four figures' tables (cup_paper.md, included by docs/cup.md), one section each: Figs. 5
    and 6 from the meshes' thickness lines, Fig. 7 from the friction runs' rows (cup_paper.csv),
    Fig. 8 from the 2 t / 5 mm and 4 t / 20 mm runs' diagonals."""
    runs = {name: _profile(folder(meshes, name)) for name in MESHES}
    label = {name: f"{name.split()[1]} x {name.split()[1]}" for name in MESHES}
    fig5 = ("| mesh | bottom centre | peak thinning, at | peak thickening (flange), at |\n" + "|---" * 4 + "|\n"
            + "".join(f"| {label[n]} | {p['diagonal']['centre']:.3f} | {p['diagonal']['thinning']} | "
                      f"{p['diagonal']['thickening']} |\n" for n, p in runs.items()))
    fig6 = ("| mesh | peak thinning, at | flange edge (75 mm) |\n" + "|---" * 3 + "|\n"
            + "".join(f"| {label[n]} | {p['transverse']['thinning']} | {p['transverse']['edge']:+.3f} |\n"
                      for n, p in runs.items()))
    fig7 = ("| friction | " + " | ".join(format(r["friction"], "g") for r in rows) + " |\n" + "|---" * (len(rows) + 1) + "|\n"
            + "| peak thickness strain | " + " | ".join(f"{r['min_thickness_strain']:.3f}" for r in rows) + " |\n"
            + "| where (initial x, y mm) | " + " | ".join(", ".join(str(r["where_initial_xy_mm"]).split()) for r in rows) + " |\n"
            + "| punch force at 30 mm | " + " | ".join(f"{r['punch_force_30_kN']:.1f} kN" for r in rows) + " |\n"
            + "| draw-in DX, DD | " + " | ".join(f"{r['DX']:.2f}, {r['DD']:.2f} mm" for r in rows) + " |\n")
    fig8 = ("| | bottom centre | peak thinning, at | peak thickening (flange), at | punch force, peak |\n" + "|---" * 5 + "|\n"
            + "".join(f"| {name} | {p['diagonal']['centre']:.3f} | {p['diagonal']['thinning']} | "
                      f"{p['diagonal']['thickening']} | {p['peak_force']:.1f} kN |\n"
                      for name, p in (("BHF 2 t, die radius 5 mm", runs["n 16"]),
                                      ("BHF 4 t, die radius 20 mm", _profile(folder(hard, "BHF 4t, die radius 20 mm"))))))
    return "".join(f"### {name}\n\n{table}\n" for name, table in (
        ("fig5_diagonal", fig5), ("fig6_transverse", fig6), ("fig7_friction", fig7), ("fig8_diagonal", fig8))).rstrip("\n") + "\n"


def _plots(out: Path, meshes: Path, hard: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    title = "Square cup, BHF 2 t, mu 0.1, r 1.5, die radius 5 mm, 30 mm"
    for fig_name, which, label in (("fig5_diagonal", "diagonal", "along the diagonal"),
                                   ("fig6_transverse", "transverse", "along the transverse centre line")):
        fig, ax = plt.subplots(figsize=(7, 4.2))
        for name in MESHES:
            d = folder(meshes, name)
            stroke = json.loads((d / "summary.json").read_text())["stroke_mm"]
            ax.plot(*_line(d, which), "o-", ms=3, label=f"{name} x {name.split()[1]} quarter mesh"
                    + ("" if abs(stroke - 30) < 1e-9 else f" (stopped at {stroke:.1f} mm)"))
        ax.set_xlabel("initial distance from the centre (mm)")
        ax.set_ylabel("thickness strain ln(t/t0)")
        ax.set_title(f"{title}: thickness strain {label}", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / f"{fig_name}.png", dpi=120)
        plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r["friction"] for r in rows], [r["min_thickness_strain"] for r in rows], "o-")
    ax.set_xlabel("Coulomb friction coefficient")
    ax.set_ylabel("peak thinning at 30 mm (thickness strain)")
    ax.set_title("Peak thickness strain (punch corner) against friction, 16 x 16", fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "fig7_friction.png", dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(*_line(folder(meshes, "n 16"), "diagonal"), "o-", ms=3, label="BHF 2 t, die radius 5 mm")
    ax.plot(*_line(folder(hard, "BHF 4t, die radius 20 mm"), "diagonal"), "s-", ms=3,
            label="BHF 4 t, die radius 20 mm")
    ax.set_xlabel("initial distance from the centre along the diagonal (mm)")
    ax.set_ylabel("thickness strain ln(t/t0)")
    ax.set_title("Diagonal thickness strain at 30 mm, 16 x 16 (Fig. 8)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "fig8_diagonal.png", dpi=120)
    plt.close(fig)
