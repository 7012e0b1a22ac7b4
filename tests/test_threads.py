"""The element and material loops on threads (shellform._jit.over_threads): every cell done
once, the answers the same bit for bit on any number of threads, a share's error raised."""

import numba
import numpy as np
import pytest

from shellform import _jit as jit


@numba.njit(nogil=True)
def _mark(counter, seen, fail_at):
    n = seen.size
    start = jit.next_chunk(counter)
    while start < n:
        for k in range(start, min(start + jit.CHUNK, n)):
            if k == fail_at:
                raise ValueError("a share failed")
            seen[k] += 1
        start = jit.next_chunk(counter)
    return 1


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_every_item_is_done_once(threads):
    for n in (0, 1, jit.CHUNK, 10 * jit.CHUNK + 3):
        seen = np.zeros(n, dtype=np.int64)
        assert jit.over_threads(_mark, threads, seen, -1) == [1] * threads
        assert np.all(seen == 1)


def test_an_error_of_a_share_is_raised_after_every_share_ended():
    seen = np.zeros(40 * jit.CHUNK, dtype=np.int64)
    with pytest.raises(ValueError, match="a share failed"):
        jit.over_threads(_mark, 2, seen, 5)
    assert seen.max() <= 1


def test_the_sheet_evaluates_the_same_on_one_and_two_threads():
    from dolfinx import fem
    from mpi4py import MPI

    from shellform.material import Hill79Material
    from shellform.mesh import rectangle
    from shellform.nonlinear.model import SheetModel

    rect = rectangle(MPI.COMM_WORLD, 100.0, 100.0, region="quarter", n=8)
    material = Hill79Material(E=70000.0, nu=0.33, hardening="swift", K=500.0, eps0=0.01, n=0.25).pack()
    effects = ("bending", "membrane", "geometric_nonlinearity", "plasticity", "finite_strain", "assumed_membrane")
    m = SheetModel(rect.mesh, material, 0.8, effects)
    q = fem.Function(m.V)
    q.x.array[:] = 5e-2 * np.random.default_rng(0).standard_normal(q.x.array.size)
    out = []
    for threads in (1, 2):
        m.threads = threads
        m.ep[...], m.p[...] = m.ep_n, m.p_n
        ev = m.evaluate(q)
        m.commit()
        out.append((ev.plastic_layers, ev.failures, ev.guard, m.strain.copy(), m.resultants.copy(),
                    m.tangents.copy(), m.forms.vectors.copy(), m.forms.matrices.copy(), m.stability_n.copy()))
        m.ep_n[...], m.p_n[...], m.stretch_n[...] = 0.0, 0.0, 1.0
    one, two = out
    assert one[0] > 0  # plastic layers: the return map ran
    assert one[:3] == two[:3]
    for a, b in zip(one[3:], two[3:]):
        np.testing.assert_array_equal(a, b)
