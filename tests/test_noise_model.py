"""The noise model per channel and level (issue 21, item 5): the floor's scatter from the one
noise-floor rule, each channel's own repeatability, a fresh simulated measurement as oracle."""

from __future__ import annotations

import numpy as np
import pytest

from powertrain.analysis.noise_floor import floor_scatter_db
from powertrain.diagnosis.data import GapData
from powertrain.diagnosis.noise_model import channel_scatter_db, point_sigma_db


def test_floor_scatter_grows_as_the_level_nears_the_floor():
    s = floor_scatter_db(np.array([3.0, 10.0, 30.0, 0.0, np.nan]), 1.0)
    np.testing.assert_allclose(s[:3], [2.047, 0.614, 0.205], atol=2e-3)
    assert np.isinf(s[3]) and np.isnan(s[4])


def test_floor_scatter_matches_simulated_noise():
    """A level 6 × the floor with complex noise of RMS = floor: the dB scatter of 200000
    seeded draws within 5 % of the first-order formula."""
    seed = 601
    rng = np.random.default_rng(seed)
    n = 200_000
    noise = (rng.normal(size=n) + 1j * rng.normal(size=n)) / np.sqrt(2)
    lev = 20 * np.log10(np.abs(6.0 + noise))
    assert np.std(lev) == pytest.approx(float(floor_scatter_db(6.0, 1.0)), rel=0.05), seed


def _data(sigmas, level=1e-3, floor=1e-6, n_r=60, seed=602):
    """Smooth order curves on four channels, each scattered by its own σ (drawn from
    ``seed``)."""
    rng = np.random.default_rng(seed)
    rpm = np.linspace(1000.0, 6000.0, n_r)
    curve = level * (1 + 0.5 * np.sin(rpm / 900.0))[:, None, None]
    lev = curve * 10 ** (rng.normal(size=(n_r, len(sigmas), 4)) * np.array(sigmas)[None, :, None] / 20)
    ch = [("left", a) for a in "xyz"] + [("right", "x")]
    return GapData(rpm, ch, ["order_1", "order_2", "order_3", "order_4"],
                   np.array([1, 3, 5, 7]), lev, floor)


def test_each_channel_gets_its_own_scatter():
    """Fresh draw: the MAD estimate's relative spread is ~9 % at 60 speeds (2.7 % of draws
    missed 25 % on some channel) and ~5 % at 240, where 25 % is five standard errors."""
    d = _data([0.3, 0.6, 1.0, 1.5], n_r=240)
    est = channel_scatter_db(d)
    np.testing.assert_allclose(est, [0.3, 0.6, 1.0, 1.5], rtol=0.25)


def test_point_sigma_adds_the_floor_in_quadrature():
    d = _data([0.5] * 4)
    d.level[0, 0, 0] = 3 * d.floor
    s = point_sigma_db(d, 0.5)
    assert s[0, 0, 0] == pytest.approx(np.hypot(0.5, float(floor_scatter_db(3.0, 1.0))))
    assert s[5, 1, 1] == pytest.approx(0.5, abs=1e-3)
