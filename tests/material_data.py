"""The material data the anisotropy tests share: Barlat et al. 2003's AA2090-T3 (alphas and the
eight experimental data) and the ESAFORM 2021 AA6016-T4 directional data, read from the demo
that draws it (demos/esaform2021_cup.toml), so that the tests and the demo cannot drift apart."""

from pathlib import Path

from shellform import scene

ROOT = Path(__file__).resolve().parents[1]

# Barlat et al. 2003, AA2090-T3: the published alpha1..alpha8 (a = 8; as JANCAE's UMMDp and
# youngung/abaqusPy quote them) and the eight experimental data (sigma over sigma0; r_b =
# dep22/dep11 in balanced biaxial tension) as stefanSCS/Poly6 matAA2090T3.txt and
# yossy11/Subroutines Datas/AA2090-T3.csv tabulate them
AA2090 = [0.4865, 1.3783, 0.7536, 1.0246, 1.0363, 0.9036, 1.2321, 1.4858]
AA2090_DATA = {"sigma0": 1.0, "sigma45": 0.8114, "sigma90": 0.9102, "sigma_b": 1.0350,
               "r0": 0.2115, "r45": 1.5769, "r90": 0.6923, "r_b": 0.6700}


def esaform_data() -> dict:
    """The ESAFORM 2021 AA6016-T4 data (TUAT) as the demo gives them: fit_angles, fit_r,
    fit_sigma, sigma_b, r_b."""
    m = scene.load(ROOT / "demos" / "esaform2021_cup.toml").material
    return {"fit_angles": list(m.fit_angles), "fit_r": list(m.fit_r), "fit_sigma": list(m.fit_sigma),
            "sigma_b": m.sigma_b, "r_b": m.r_b}
