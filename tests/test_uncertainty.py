"""The parameter uncertainty of the diagnosis fits (powertrain.diagnosis.uncertainty) on
synthetic least-squares problems with a known answer."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from powertrain.diagnosis.uncertainty import (
    Z_95,
    cluster_ids,
    intervals,
    parameter_sd,
    with_model_floor,
)


def _line_fit(rng, n_clusters=30, per=20, tau=0.0, sigma=1.0):
    """Least squares of y = a + b t with noise ``sigma`` and, per cluster, a random slope
    of scatter ``tau`` (residuals correlated within a cluster): ``(b_hat, sd, sd_gn)``."""
    t = rng.uniform(-1.0, 1.0, (n_clusters, per))
    y = 1.0 + 2.0 * t + rng.normal(0.0, tau, (n_clusters, 1)) * t \
        + rng.normal(0.0, sigma, t.shape)
    J = np.stack([np.ones(t.size), t.ravel()], axis=1)
    coef, *_ = np.linalg.lstsq(J, y.ravel(), rcond=None)
    r = J @ coef - y.ravel()
    s2 = float(r @ r) / (r.size - 2)
    ids = np.repeat(np.arange(n_clusters), per)
    return coef[1], parameter_sd(J, r, r.size, ids, s2), parameter_sd(J, r, r.size, None, s2)


def test_independent_residuals_keep_gauss_newton():
    """Independent residuals: the reported 1σ is the Gauss–Newton one or a little more."""
    rng = np.random.default_rng(1)
    _, sd, sd_gn = _line_fit(rng)
    assert np.all(sd >= sd_gn) and np.all(sd < 1.5 * sd_gn)
    assert math.isclose(sd_gn[1], 1.0 / math.sqrt(600 / 3), rel_tol=0.15)   # var(t) = 1/3


def test_correlated_residuals_covered():
    """Residuals correlated within clusters (a random slope per cluster): the Gauss–Newton
    95 % interval of the slope covers the truth far too rarely, the reported one near 95 %
    (300 draws)."""
    rng = np.random.default_rng(2)
    hits, hits_gn = 0, 0
    for _ in range(300):
        b, sd, sd_gn = _line_fit(rng, tau=1.0)
        hits += abs(b - 2.0) <= Z_95 * sd[1]
        hits_gn += abs(b - 2.0) <= Z_95 * sd_gn[1]
    assert hits / 300 >= 0.9 and hits_gn / 300 < 0.7


def test_cluster_ids_cells():
    """Levels and phases of a (channel, order) cell share its cluster; the crank offset's
    prior row is a cluster of its own."""
    valid = np.zeros((3, 2, 4), bool)
    valid[:, 1, 2] = True
    valid[0, 0, 0] = True
    phase = valid.copy()
    phase[0, 0, 0] = False
    ids = cluster_ids(valid, phase)
    assert ids.tolist() == [0, 6, 6, 6, 6, 6, 6, -1]


def test_intervals_log_and_bounds():
    """A log-scale parameter's interval is multiplicative; an interval is clipped to its
    bounds; NaN σ gives no interval."""
    pack = SimpleNamespace(names=[("m", "mass"), ("m", "f"), ("m", "z")],
                           log=np.array([True, False, False]),
                           lower=np.array([math.log(0.5), 5.0, 0.0]),
                           upper=np.array([math.log(1e4), 200.0, 1.0]))
    x = np.array([math.log(10.0), 199.0, 0.5])
    iv = intervals(pack, x, np.array([0.1, 2.0, np.nan]))["m"]
    assert np.allclose(iv["mass"], [10 * math.exp(-Z_95 * 0.1), 10 * math.exp(Z_95 * 0.1)])
    assert np.allclose(iv["f"], [199.0 - Z_95 * 2.0, 200.0])
    assert iv["z"] == [None, None]


def test_model_floor_on_a_missing_mode():
    """The relative floor enters a missing body mode's frequency (linear) and modal mass
    (log coordinates) in quadrature; its damping ratio keeps its statistical 1σ."""
    e = "missing_body_mode"
    pack = SimpleNamespace(names=[(e, "frequency_hz"), (e, "modal_mass_kg"),
                                  (e, "damping_ratio")], log=np.array([False, True, True]))
    x = np.array([100.0, math.log(10.0), math.log(0.04)])
    sd = with_model_floor(pack, x, np.array([1.0, 0.01, 0.3]), floor=0.025)
    assert np.allclose(sd, [math.hypot(1.0, 2.5), math.hypot(0.01, math.log1p(0.025)), 0.3])
