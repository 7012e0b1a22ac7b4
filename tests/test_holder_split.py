"""The closed holder's split (shellform/contact/holder_split.py) apart from any cup: the holder
force's total, each pinched node's two faces against its net normal force, the spread rules and
the edge's band, on a handful of nodes."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from mpi4py import MPI

from shellform.contact.holder_split import SPREAD_RULES, HolderSplit, holder_height
from shellform.scene import SPREADS

F = 1000.0
AREA = np.array([1.0, 2.0, 3.0, 4.0, 2.0, 1.0])
K = 7.0e4 * AREA  # E A / t, E 70 GPa, t 1 mm
PINCHED = np.array([True, True, True, True, True, False])
NET = np.array([30.0, -20.0, 5.0, -50.0, 0.0, 70.0])  # die minus holder
TOPS = np.array([1.02, 1.05, 1.01, 1.00, 1.04, 1.10])
NO_BAND = np.zeros(6, dtype=bool)


def _split(spread):
    return HolderSplit(F, AREA, K, MPI.COMM_WORLD, spread)


def test_the_scene_names_every_spread_rule_and_a_wrong_one_is_refused():
    assert tuple(SPREAD_RULES) == SPREADS
    with pytest.raises(ValueError, match="holder spread"):
        _split("thickest")


@pytest.mark.parametrize("spread", SPREADS)
def test_the_holder_carries_its_force_and_each_node_its_net_force(spread):
    """sum h_i = F; off the band d_i - h_i = R0_i with both faces >= 0; nothing off the pinch."""
    d, h = _split(spread).forces(PINCHED, NET, TOPS, np.zeros(6), NO_BAND)
    assert h.sum() == pytest.approx(F, rel=1e-13)
    assert np.allclose((d - h)[PINCHED], NET[PINCHED], rtol=0, atol=1e-12 * F)
    assert d.min() >= 0.0 and h.min() >= 0.0 and d[~PINCHED].max() == 0.0 == h[~PINCHED].max()


def test_the_area_rule_spreads_the_squeeze_by_tributary_area():
    """s_i = S A_i / sum A, S = F - sum max(-R0, 0): h_i - max(-R0_i, 0) = S A_i / sum A."""
    d, h = _split("area").forces(PINCHED, NET, TOPS, np.zeros(6), NO_BAND)
    S = F - np.maximum(-NET[PINCHED], 0.0).sum()
    s = h[PINCHED] - np.maximum(-NET[PINCHED], 0.0)
    assert np.allclose(s, S * AREA[PINCHED] / AREA[PINCHED].sum(), rtol=1e-13, atol=0)


def test_the_rigid_rule_rests_on_the_thickest_nodes():
    """s_i = k_i max(top_i - Z, 0), sum s_i = S: the face's height Z solves the sum exactly, and
    the nodes below it carry only their holding-down."""
    S = F - np.maximum(-NET[PINCHED], 0.0).sum()
    Z = holder_height(TOPS[PINCHED], K[PINCHED], S)
    assert (K[PINCHED] * np.maximum(TOPS[PINCHED] - Z, 0.0)).sum() == pytest.approx(S, rel=1e-12)
    d, h = _split("rigid").forces(PINCHED, NET, TOPS, np.zeros(6), NO_BAND)
    s = h[PINCHED] - np.maximum(-NET[PINCHED], 0.0)
    assert np.allclose(s, K[PINCHED] * np.maximum(TOPS[PINCHED] - Z, 0.0), rtol=1e-13, atol=1e-12)
    assert (s == 0.0).sum() >= 1 and s[np.argmax(TOPS[PINCHED])] == s.max()
    assert holder_height(TOPS[PINCHED], K[PINCHED], 0.0) == TOPS[PINCHED].max()


def test_the_band_takes_the_edge_load_and_the_die_its_equilibrium():
    """On the band h_i = s_i + f e_i and d_i = h_i D / H, D = max(H + sum R0, 0); while the
    holding-down and the edge load exceed F the holder rides (f < 1) and squeezes nothing."""
    band = np.array([True, True, False, False, False, False])
    split = _split("area")
    edge = np.where(band, 200.0, 0.0)
    d, h = split.forces(PINCHED, NET, TOPS, edge, band)
    H = h[band].sum()
    assert h.sum() == pytest.approx(F, rel=1e-13)
    assert d[band].sum() == pytest.approx(max(H + NET[band].sum(), 0.0), rel=1e-13)
    assert np.ptp(d[band] / h[band]) <= 1e-15
    riding = np.where(band, 600.0, 0.0)  # E_in 50 + E_e 1200 > F
    d, h = split.forces(PINCHED, NET, TOPS, riding, band)
    f = split.edge_share(50.0, 1200.0)
    assert f == pytest.approx(950.0 / 1200.0, rel=1e-15)
    assert np.allclose(h[band], f * 600.0, rtol=1e-15) and np.allclose(h[PINCHED & ~band], np.maximum(-NET, 0.0)[PINCHED & ~band])
    assert split.held_down(PINCHED, NET, riding, band) == pytest.approx((1.0, 1.2, 0.05), rel=1e-13)


def test_the_faces_slopes_are_the_split_s_derivatives_at_a_fixed_spread():
    """Off the band (dd/dR0, dh/dR0) = (1, 0) where R0 > 0 and (0, -1) where R0 < 0; on the band
    the die's h_i / H and the holder's 0."""
    band = np.array([True, True, False, False, False, False])
    split = _split("area")
    d, h = split.forces(PINCHED, NET, TOPS, np.where(band, 200.0, 0.0), band)
    dd, dh = split.face_slopes(NET, h, band)
    off = ~band
    assert np.array_equal(dd[off], (NET[off] > 0).astype(float)) and np.array_equal(dh[off], -(NET[off] < 0).astype(float))
    assert np.allclose(dd[band], h[band] / h[band].sum(), rtol=1e-15) and not dh[band].any()
