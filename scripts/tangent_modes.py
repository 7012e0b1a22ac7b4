"""The tangent's softest modes at a tool run's last converged state.

    python scripts/tangent_modes.py SCENE OUT [--set key=value ...] [-k K] [--shift S] [--unsymmetric]

OUT: a `shellform run` folder with its checkpoint (the scene and the --set values it was run
with). The tangent on the free rows (System.free_tangent, their count in each row) at the
checkpoint's state; the K
smallest eigenvalues of its symmetric part (shift-invert about 0, so a negative one is found
first: a tangent that is not positive definite, an unstable equilibrium), and for each mode the
nodes that carry 90 % of it, its dominant unknown (0, 1, 2: x, y, z of a free node) and the
mode's values there, largest first, beside the nodes' initial and current places. A spurious
mode of an element alternates in sign from node to node; a physical one (a wrinkle, a drum
mode of a stretched bottom) keeps its sign over many nodes. One rank. docs/performance.md
("The soft modes of the fine cups") has what it found.

--shift S: the shift-invert's shift in N/mm (default -1e-6 of the median diagonal): the K
eigenvalues nearest it are found. --unsymmetric: first a line with K's own K eigenvalues
nearest the shift (scipy's eigs; K is unsymmetric where friction slips), its symmetric part's
and the asymmetry |K - K^T| / |K| (sums of magnitudes): a symmetric part that is indefinite
while K is not says the energy slope of a Newton step may lose its sign without the
equilibrium being unstable.
"""

import argparse
import json

import numpy as np
import scipy.sparse.linalg as sla
from mpi4py import MPI

from shellform import scene
from shellform.assembly.sheet_element import BS
from shellform.contact.problem import DrawingProblem
from shellform.nonlinear import checkpoint


def modes(s, out, k: int, shift: float | None = None, unsymmetric: bool = False) -> list[dict]:
    p = DrawingProblem.from_scene(s, MPI.COMM_SELF)
    d = p.driver
    d.resume(checkpoint.read(out, MPI.COMM_SELF))
    K, free = d.free_tangent(d.lam)
    S = ((K + K.T) / 2).tocsc()
    scale = float(np.median(np.abs(S.diagonal())))
    sigma = -1e-6 * scale if shift is None else shift
    values, vectors = sla.eigsh(S, k=k, sigma=sigma, which="LM")
    rows = []
    if unsymmetric:
        own = sla.eigs(K.tocsc(), k=k, sigma=sigma, which="LM", return_eigenvectors=False)
        rows.append({"stroke_mm": p.stroke, "free_rows": len(free),
                     "asymmetry": float(abs(K - K.T).sum() / abs(K).sum()),
                     "K_eigenvalues": [[float(z.real), float(z.imag)] for z in np.sort_complex(own)],
                     "symmetric_part_eigenvalues": sorted(float(v) for v in values)})
    x0 = p.initial_positions()
    x = x0 + p.displacements()[: len(x0)]
    for i in np.argsort(values):
        v = np.zeros(d.q.x.array.size)
        v[free] = vectors[:, i]
        V = v.reshape(-1, BS)[: len(x0)]
        amp = np.linalg.norm(V, axis=1)
        order = np.argsort(amp)[::-1]
        top = order[0]
        c = int(np.argmax(np.abs(V[top])))
        share = np.cumsum(amp[order] ** 2) / np.sum(amp ** 2)
        rows.append({"stroke_mm": p.stroke, "free_rows": len(free), "eigenvalue": float(values[i]), "of_the_median_diagonal": float(values[i] / scale),
                     "nodes_for_90_percent": int(np.searchsorted(share, 0.9) + 1), "dominant_unknown": c,
                     "largest": [{"initial_xy": x0[j, :2].round(2).tolist(), "current_xyz": x[j].round(2).tolist(),
                                  "value": round(float(V[j, c] / V[top, c]), 3)} for j in order[:8]]})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("out")
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("-k", type=int, default=8)
    parser.add_argument("--shift", type=float, default=None)
    parser.add_argument("--unsymmetric", action="store_true")
    args = parser.parse_args()
    s = scene.load(args.scene)
    if args.settings:
        s = s.changed(scene.settings(args.settings))
    for row in modes(s, args.out, args.k, args.shift, args.unsymmetric):
        print(json.dumps(row))


if __name__ == "__main__":
    main()
