"""The pinch's edge resolved well below the sheet's thickness: a plane-strain strip (issue 32).

    shellform study pinch-edge --out docs/results/pinch_edge        # about 10 s

The strip of the NUMISHEET'93 aluminium cup's side (demos/numisheet93_aluminium.toml), per unit
width, near the holder's inner edge x = 0: the flat flange x < 0 between the die's flat top and
the holder, the die's shoulder (radius R_d, the sheet's mid-surface on R_d + t/2) for x > 0. The
sheet is a plane-strain beam-column:

    Pi(w) = int W(w'') dx + int T/2 w'^2 dx
            + int k/2 [(z_d + d0 - w)_+^2 + (w + d0)_+^2 (x < 0)] dx

W(kappa) = int M dkappa with M(kappa) the plane-strain moment of the scene's sheet (the material
point driven in plane strain: the loading branch; the tension's reduction of M is left out), T
the drawing tension (its geometric stiffness), each face a Winkler foundation k per unit area,
d0 = p0 / k the pre-squeeze of the holder's mean pressure p0. Ends: the flange clamped at
x = -L, the sheet wrapped on the shoulder at x = X (w and w' of the circle). Finite differences
on a uniform grid of spacing h, Newton with a backtracking line search on the convex energy.

Two foundations: the sheet's own compliance, each face on half the thickness, k = 2 E' / t
(E' = E / (1 - nu^2)); and one 10^4 times stiffer, the rigid pinch's limit. For each and each h,
the holder's force beyond its pre-squeeze V_h (N/mm), the moment at the edge M_0 and V_h t / M_0,
which pinch_edge.C_EDGE (the elastic plate on the foundation, closed form) predicts once h
resolves the foundation's length t / 12^(1/4). Writes pinch_edge.csv and pinch_edge.png.
"""

from pathlib import Path

from shellform.contact.pinch_edge import C_EDGE, Strip
from shellform.results.log import say
from shellform.results.tables import write_csv

SPACINGS = (0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125)
QUICK_SPACINGS = (0.4, 0.1, 0.025)
TENSIONS = (0.0, 100.0)  # N/mm
STIFFER = 1e4
COLUMNS = ["foundation", "tension_N_per_mm", "h_mm", "Vh_N_per_mm", "M0_Nmm_per_mm", "Vh_t_over_M0", "C_EDGE",
           "peak_holder_MPa", "newton"]


def aluminium_strip() -> Strip:
    """The strip of demos/numisheet93_aluminium.toml: its sheet, die radius and holder pressure
    (the quarter's force over the quarter's flange outside the holder's edge)."""
    from shellform.studies.cup_hard import variant

    s = variant(16, "numisheet93_aluminium.toml")
    edge = s.tools.die_half_width + s.tools.die_profile_radius
    flange = (s.geometry.lx / 2) * (s.geometry.ly / 2) - edge**2
    return Strip(s.hill79().pack(), s.material.thickness, s.tools.die_profile_radius,
                 s.tools.blank_holder_force / 4 / flange)


def run(outdir, spacings=SPACINGS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    strip = aluminium_strip()
    k_sheet = 2 * strip.E_ps / strip.t
    rows = []
    for name, k in (("sheet 2E'/t", k_sheet), ("stiffer x 1e4", STIFFER * k_sheet)):
        for T in TENSIONS:
            for h in spacings:
                r = {"foundation": name, "tension_N_per_mm": T, **strip.solve(h, k, T)}
                rows.append(r)
                say(f"{name:14s} T {T:5.0f}  h {h:7.4f}  V_h {r['Vh_N_per_mm']:8.2f} N/mm  M0 {r['M0_Nmm_per_mm']:6.2f}"
                    f"  V_h t/M0 {r['Vh_t_over_M0']:6.3f} (C_EDGE {C_EDGE:.3f})")
    write_csv(outdir / "pinch_edge.csv", rows, COLUMNS)
    plot(outdir / "pinch_edge.png", rows, strip.t)
    return rows


def plot(path: Path, rows: list[dict], t: float) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for name in dict.fromkeys(r["foundation"] for r in rows):
        part = [r for r in rows if r["foundation"] == name and r["tension_N_per_mm"] == 0.0]
        ax.loglog([r["h_mm"] / t for r in part], [r["Vh_t_over_M0"] for r in part], "o-", label=name)
    ax.axhline(C_EDGE, color="k", lw=0.8, ls="--", label=f"C_EDGE = {C_EDGE:.3f}")
    ax.set_xlabel("grid spacing h / t")
    ax.set_ylabel("holder's edge force V_h t / M_0")
    ax.set_title("The pinch's edge, plane-strain strip (aluminium, T = 0)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
