"""Meshes of the blank (shellform.mesh.rectangle) and the distorted patch."""

import itertools

import numpy as np
import pytest

import shellform  # noqa: F401  (before dolfinx / mpi4py)
import dolfinx.mesh
from mpi4py import MPI

from shellform.errors import InputError
from shellform.mesh import SIDE_TAG, SIDES, distorted_patch, rectangle

COMM = MPI.COMM_SELF


def cells_xy(msh):
    x = msh.geometry.x[:, :2]
    return x[msh.geometry.dofmaps[0]]  # (cells, 3, 2)


def signed_areas(msh):
    c = cells_xy(msh)
    a, b = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def num_cells(msh):
    return msh.topology.index_map(msh.topology.dim).size_local


def is_vertex(msh, p):
    return np.min(np.linalg.norm(msh.geometry.x[:, :2] - np.asarray(p), axis=1)) < 1e-12


def side_counts(rm):
    return {s: int(np.sum(rm.facet_tags.values == SIDE_TAG[s])) for s in SIDES}


def test_structured_full():
    rm = rectangle(COMM, 1.0, 1.0, n=4)
    assert num_cells(rm.mesh) == 32
    assert rm.mesh.topology.index_map(0).size_local == 25
    assert rm.mesh.geometry.dim == 2
    assert is_vertex(rm.mesh, (0.0, 0.0))
    assert rm.bounds == (-0.5, 0.5, -0.5, 0.5)
    assert side_counts(rm) == {"left": 4, "right": 4, "bottom": 4, "top": 4}
    assert np.sum(np.abs(signed_areas(rm.mesh))) == pytest.approx(1.0, abs=1e-12)


def test_structured_quarter_and_sides():
    rm = rectangle(COMM, 2.0, 1.0, region="quarter", n=6, diagonal="crossed")
    assert rm.bounds == (0.0, 1.0, 0.0, 0.5)
    assert side_counts(rm) == {"left": 3, "right": 3, "bottom": 6, "top": 6}
    assert num_cells(rm.mesh) == 4 * 6 * 3
    assert is_vertex(rm.mesh, (0.0, 0.0))
    # tagged facets lie on their side
    x = rm.mesh.geometry.x
    f2v = rm.mesh.topology.connectivity(1, 0)
    for facet, tag in zip(rm.facet_tags.indices, rm.facet_tags.values):
        xs = x[f2v.links(facet)]
        axis, value = {1: (0, 0.0), 2: (0, 1.0), 3: (1, 0.0), 4: (1, 0.5)}[tag]
        assert np.allclose(xs[:, axis], value)


def test_structured_full_even_n_keeps_centre_vertex():
    rm = rectangle(COMM, 1.0, 0.75, n=4)  # round(3) y divisions would miss the centre
    assert is_vertex(rm.mesh, (0.0, 0.0))
    assert side_counts(rm) == {"left": 4, "right": 4, "bottom": 4, "top": 4}


@pytest.mark.parametrize("region, area", [("full", 2.0), ("quarter", 0.5)])
def test_unstructured(region, area):
    p = (0.31, 0.17)
    rm = rectangle(COMM, 2.0, 1.0, region=region, kind="unstructured", n=10, points=[p])
    s = signed_areas(rm.mesh)
    assert np.sum(s) == pytest.approx(area, abs=1e-12)
    assert np.min(s) > 1e-3 * area / len(s)
    assert is_vertex(rm.mesh, (0.0, 0.0))
    assert is_vertex(rm.mesh, p)
    counts = side_counts(rm)
    assert all(c > 0 for c in counts.values())
    exterior = dolfinx.mesh.exterior_facet_indices(rm.mesh.topology)
    assert np.array_equal(np.sort(rm.facet_tags.indices), exterior)


def test_unstructured_boundary_point_and_refinement():
    p = (0.0, 0.23)  # on the symmetry side x = 0 of the quarter
    coarse = rectangle(COMM, 1.0, 1.0, region="quarter", kind="unstructured", n=8, points=[p])
    fine = rectangle(COMM, 1.0, 1.0, region="quarter", kind="unstructured", n=16, points=[p])
    assert is_vertex(coarse.mesh, p) and is_vertex(fine.mesh, p)
    assert 3.0 < num_cells(fine.mesh) / num_cells(coarse.mesh) < 5.0
    again = rectangle(COMM, 1.0, 1.0, region="quarter", kind="unstructured", n=8, points=[p])
    assert np.array_equal(again.mesh.geometry.x, coarse.mesh.geometry.x)
    assert np.array_equal(again.mesh.geometry.dofmaps[0], coarse.mesh.geometry.dofmaps[0])


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(lx=0.0), "geometry.lx"),
        (dict(lx="1"), "geometry.lx"),
        (dict(ly=-1.0), "geometry.ly"),
        (dict(region="half"), "geometry.region"),
        (dict(kind="quad"), "mesh.kind"),
        (dict(n=0), "mesh.n"),
        (dict(n=2.5), "mesh.n"),
        (dict(n=True), "mesh.n"),
        (dict(diagonal="up"), "mesh.diagonal"),
        (dict(region="quarter", kind="unstructured", points=[(-0.1, 0.1)]), "loads.points"),
        (dict(points=[(0.1,)]), "loads.points"),
    ],
)
def test_bad_input(kwargs, field):
    args = dict(lx=1.0, ly=1.0) | kwargs
    with pytest.raises(InputError) as err:
        rectangle(COMM, **args)
    assert err.value.field == field


def test_distorted_patch():
    msh = distorted_patch(COMM)
    assert num_cells(msh) == 10
    s = signed_areas(msh)
    assert np.all(s > 0.01)
    assert np.sum(s) == pytest.approx(1.0, abs=1e-14)

    x = msh.geometry.x[:, :2]
    cells = msh.geometry.dofmaps[0]
    edges = {tuple(sorted(e)) for c in cells for e in itertools.combinations(c, 2)}
    assert len(edges) == 17

    def on_side(e):
        a, b = x[list(e)]
        return any(np.isclose(a[k], v) and np.isclose(b[k], v) for k in (0, 1) for v in (0.0, 1.0))

    interior = [e for e in edges if not on_side(e)]
    assert len(interior) == 13
    dirs = [(x[j] - x[i]) / np.linalg.norm(x[j] - x[i]) for i, j in interior]
    dirs += [np.array([1.0, 0.0]), np.array([0.0, 1.0])]  # the sides
    for u, v in itertools.combinations(dirs, 2):
        assert abs(u[0] * v[1] - u[1] * v[0]) > np.sin(np.radians(5.0))
