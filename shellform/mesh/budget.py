"""Will the mesh fit? The cells a [mesh] section makes and the memory a run on them needs,
estimated before anything is built, so that a mesh too large for the machine is an input error
naming mesh.n instead of an allocation failure deep inside DOLFINx.

Bytes per cell, measured on the 2-core machine (peak resident memory, `shellform run`):
- linear plate or shell: 5.4 kB per cell (square plate, 320k -> 1.28M cells: 1.8 -> 7.0 GB);
- nonlinear sheet (layers, tangents, contact): about 50 kB per cell (square cup, 4,608 cells:
  0.82 GB with a base of about 0.6 GB);
- a process's base (Python, DOLFINx, PETSc, the compiled kernels): 0.6 GB;
- each point through the thickness of a plastic section (process.thickness_points): its plastic
  strain and p, committed and trial, 2 x (3 + 1) doubles at 6 quadrature points per cell (384 B),
  and numpy's Gauss-Legendre rule of n points, which builds an n x n companion matrix and the
  eigensolver's copy of it (16 n^2 bytes measured; 24 n^2 counted).
The estimate is rounded up (6 and 60 kB) and meant to catch meshes that are orders of
magnitude too large, not to predict a run's memory.
"""

import math
import os

LINEAR_BYTES_PER_CELL = 6e3
NONLINEAR_BYTES_PER_CELL = 60e3
BASE_BYTES = 0.6e9
LAYER_BYTES_PER_CELL = 384
RULE_BYTES_PER_POINT_SQUARED = 24


def state_bytes(cells: int, layers: int = 0) -> float:
    """The most a run's state on that many cells may take (its memory less the base): a
    checkpoint larger than this is not the state of such a run (shellform.nonlinear.checkpoint)."""
    return cells * (NONLINEAR_BYTES_PER_CELL + layers * LAYER_BYTES_PER_CELL)


def structured_ny(lx: float, ly: float, region: str, n: int) -> int:
    """Divisions along y of the structured mesh with n along x (even on a full blank with even n,
    so that the centre is a vertex)."""
    ny = max(1, round(n * ly / lx))
    if region == "full" and n % 2 == 0 and ny % 2 == 1:
        ny = max(2, 2 * round(n * ly / lx / 2))
    return ny


def estimated_cells(lx: float, ly: float, region: str, kind: str, n: int, refine: int) -> int:
    """Triangles of the rectangle() mesh (structured: exact; gmsh: about 2.31 per h^2 of area)."""
    w, h = (lx, ly) if region == "full" else (lx / 2, ly / 2)
    if kind == "structured":
        base = 2 * n * structured_ny(lx, ly, region, n)
    else:
        return gmsh_cells(w * h, w / n, refine)
    return int(base * 4**refine)


def gmsh_cells(area: float, size: float, refine: int) -> int:
    """Triangles gmsh makes of that area at that size: equilateral, sqrt(3)/4 size^2 each."""
    return int(math.ceil(area / (math.sqrt(3) / 4 * size**2)) * 4**refine)


def available_bytes() -> float:
    """The memory this process may use: the least of the machine's RAM, the cgroup's limit and the
    address-space and data limits (ulimit -v, -d)."""
    import resource

    limits = [os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")]
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as f:
                text = f.read().strip()
        except OSError:
            continue
        if text.isdigit():
            limits.append(float(text))
    for which in (resource.RLIMIT_AS, resource.RLIMIT_DATA):
        soft, _ = resource.getrlimit(which)
        if soft != resource.RLIM_INFINITY:
            limits.append(float(soft))
    return float(min(limits))


def estimated_bytes(cells: int, nonlinear: bool, ranks: int = 1, layers: int = 0) -> float:
    """Peak memory of a run on that many cells; layers: the points through the thickness of a
    plastic section (0: an elastic section, no layers)."""
    per_cell = NONLINEAR_BYTES_PER_CELL if nonlinear else LINEAR_BYTES_PER_CELL
    return (cells * (per_cell + layers * LAYER_BYTES_PER_CELL) + RULE_BYTES_PER_POINT_SQUARED * float(layers) ** 2
            + ranks * BASE_BYTES)
