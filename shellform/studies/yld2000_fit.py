"""Yld2000-2d and Poly6 fitted by least squares to the ESAFORM 2021 AA6016-T4 data: the errors
per angle.

    shellform study yld2000-fit --out docs/results/yld2000_fit        # about 20 s

The data and the exponent are those of demos/esaform2021_cup.toml's [material] (r values and
yield stresses at 0, 15, ..., 90 degrees to the rolling direction, sigma_b, r_b; their sources
are in docs/references.md); shellform.material.yld2000_fit states the fit and its weights.
Writes residuals.csv (quantity, angle, measured, fitted, error: one row per datum) and
residuals.md (the table docs/material.md includes), alphas.csv, the same of Poly6 fitted to the same data (poly6_residuals.csv,
poly6_residuals.md, poly6_coefficients.csv; shellform.material.poly6) and fit.png (r and sigma/sigma0 against the
angle, measured and both fits on a 1-degree grid). tests/test_yld2000_fit.py and
tests/test_poly6.py check the tables against new fits.
"""

from pathlib import Path

import numpy as np

from shellform import demos, scene
from shellform.material import poly6, yld2000, yld2000_fit
from shellform.results.log import say
from shellform.results.tables import as_written, markdown_table, write_csv

SCENE = demos.path("esaform2021_cup.toml")


def fit_of(path=SCENE) -> yld2000_fit.Fit:
    """The least-squares fit of a scene's [material] (its yield_parameters as the run takes them)."""
    values = scene.load(path).hill79().yield_parameters
    return yld2000.least_squares(values, values["a"])


def poly6_fit_of(path=SCENE) -> yld2000_fit.Fit:
    """Poly6 fitted to the same data (the scene's fit lists, sigma_b and r_b)."""
    values = scene.load(path).hill79().yield_parameters
    return poly6.least_squares({k: v for k, v in values.items() if k in poly6.PARAMETERS})


def run(outdir, path=SCENE) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    fit = fit_of(path)
    rows = list(fit.rows)
    write_csv(outdir / "residuals.csv", rows, yld2000_fit.COLUMNS)
    write_csv(outdir / "alphas.csv", [{"name": f"alpha{i + 1}", "value": x} for i, x in enumerate(fit.alpha)]
              + [{"name": "a", "value": fit.a}], ["name", "value"])
    for r in rows:
        angle = f"{r['angle_deg']:4.0f}" if r["angle_deg"] != "" else "    "
        say(f"{r['quantity']:>15s} {angle}  measured {r['measured']:.4f}  fitted {r['fitted']:.4f}  "
            f"error {r['error']:+.4f}")
    say(fit.text)
    (outdir / "residuals.md").write_text(markdown(fit, "Yld2000-2d"))
    other = poly6_fit_of(path)
    write_csv(outdir / "poly6_residuals.csv", list(other.rows), yld2000_fit.COLUMNS)
    (outdir / "poly6_residuals.md").write_text(markdown(other, "Poly6"))
    write_csv(outdir / "poly6_coefficients.csv", [{"name": f"c{i + 1}", "value": x} for i, x in enumerate(other.alpha)],
              ["name", "value"])
    say("poly6: " + other.text)
    plot(outdir / "fit.png", fit, other)
    return rows


def markdown(fit: yld2000_fit.Fit, name: str) -> str:
    """The fit's errors as docs/material.md shows them (the CSV's own digits): per angle r and
    sigma/sigma0 measured, fitted and the error, then the biaxial data."""
    rows = as_written(list(fit.rows))
    at = {(r["quantity"], r["angle_deg"]): r for r in rows}
    cells = []
    for r in (r for r in rows if r["quantity"] == "r"):
        s = at["sigma/sigma0", r["angle_deg"]]
        cells.append([f"{r['angle_deg']:g}", f"{r['measured']:g}", f"{r['fitted']:.4f}", f"{r['error']:+.4f}",
                      f"{s['measured']:g}", f"{s['fitted']:.4f}", f"{s['error']:+.4f}"])
    b, rb = at["sigma_b/sigma0", ""], at.get(("r_b", ""))
    cells.append(["biaxial", f"r_b {rb['measured']:g}" if rb else "r_b not given",
                  f"{rb['fitted']:.4f}" if rb else "", f"{rb['error']:+.4f}" if rb else "",
                  f"sigma_b/sigma0 {b['measured']:g}", f"{b['fitted']:.4f}", f"{b['error']:+.4f}"])
    return markdown_table(["theta (deg)", "r measured", f"{name} r", "error", "sigma/sigma0 measured", name, "error"],
                          cells)


def plot(path: Path, fit: yld2000_fit.Fit, other: yld2000_fit.Fit) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    theta = np.linspace(0.0, 90.0, 91)
    sigma, r, _, _ = yld2000.predicted(fit.alpha, fit.a, theta)
    sigma6, r6, _, _ = poly6.predicted(other.alpha, other.a, theta)
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.6))
    for ax, quantity, curve, curve6, label in ((axes[0], "r", r, r6, "r value"),
                                               (axes[1], "sigma/sigma0", sigma / sigma[0], sigma6 / sigma6[0],
                                                "sigma / sigma0")):
        data = [row for row in fit.rows if row["quantity"] == quantity]
        ax.plot([row["angle_deg"] for row in data], [row["measured"] for row in data], "ko", label="measured")
        ax.plot(theta, curve, "C0-", label=f"Yld2000-2d, a = {fit.a:g}, least squares")
        ax.plot(theta, curve6, "C1--", label="Poly6, least squares, convex")
        ax.set_xlabel("angle to the rolling direction (degrees)")
        ax.set_ylabel(label)
        ax.set_xticks(range(0, 91, 15))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
