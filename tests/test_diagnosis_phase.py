"""Order phase in the diagnosis (issue 21, item 4): the crank-offset nuisance, the phase
noise model, and what the cylinder finding may name given the measured phases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from powertrain.diagnosis import phase as ph
from powertrain.effects import EFFECTS
from powertrain.effects.cylinder_imbalance import equivalent_cylinders


def test_crank_offset_is_recovered_from_phase_gaps_that_grow_with_the_order():
    rng = np.random.default_rng(1)
    k = np.repeat(np.arange(1, 17) * 0.5, 40)
    true = math.radians(1.3)
    d = k * true + rng.normal(0, 0.05, k.size)
    w = np.full(k.size, 8.7)
    delta = ph.crank_offset(d, k, w, sigma_db=0.7)
    assert abs(math.degrees(delta) - 1.3) < 0.05
    # the prior pulls a lone noisy point towards 0
    assert abs(ph.crank_offset(np.array([0.5]), np.array([1.0]), np.array([0.1]), 0.7)) < 0.01


def test_phase_weight_falls_as_the_level_nears_the_floor_and_is_off_below_censoring():
    floor, sigma = 1e-6, 0.8
    level = np.array([1e-3, 1e-5, 4e-6, 2e-6])
    w = ph.phase_weights(level, np.zeros(4), floor, sigma)
    assert w[0] == pytest.approx(20 / math.log(10), rel=1e-3)    # far above: 8.7 dB/rad
    assert w[0] > w[1] > w[2]
    assert np.isnan(w[3])                                          # below 3 x floor
    assert np.isnan(ph.phase_weights(level[:1], np.array([np.nan]), floor, sigma)[0])


def test_wrap_keeps_angles_in_one_turn():
    x = np.array([0.1, math.pi + 0.1, -3 * math.pi + 0.2])
    np.testing.assert_allclose(ph.wrap(x), [0.1, -math.pi + 0.1, -math.pi + 0.2], atol=1e-12)


def test_equivalent_cylinders_follow_the_measured_phases(default_engine):
    e = default_engine
    assert equivalent_cylinders(e, 1, True, "all") == [(1, True)]
    whole = equivalent_cylinders(e, 1, True, "whole")
    assert set(whole) == {(1, True), (2, True), (0, False), (3, False)}
    assert whole[0] == (1, True)
    assert len(equivalent_cylinders(e, 1, True, "none")) == 8


def test_finding_names_cylinder_and_sign_and_says_why_pins_are_ambiguous(default_engine):
    eff = EFFECTS["cylinder_imbalance"]
    p = {"e1": 0.0, "e2": 0.0, "e3": -0.1, "e4": 0.0}
    f = eff.finding(p, default_engine, "all")
    assert (f["cylinder"], f["sign"]) == (3, "weak")
    assert f["text"].startswith("cylinder 3 weak")
    w = eff.finding(p, default_engine, "whole")
    assert "cylinder 3 or 2 weak" in w["text"] and "1 and 4, 2 and 3" in w["text"]
    assert "needs the order phases" in eff.finding(p, default_engine, "none")["text"]


def test_whole_orders_cannot_tell_a_weak_cylinder_from_a_strong_one_on_the_other_pin(
        default_engine):
    """The claim behind ``equivalent_cylinders``, on the fast model: cylinder 2 weak and
    cylinder 1 strong with the mean kept give the same whole orders and the same half-order
    magnitudes; only the half-order phases differ."""
    from powertrain.effects import predict
    from powertrain.solvers.fast_harmonic import HarmonicModel
    hm = HarmonicModel(default_engine, np.array([1500.0, 3000.0, 4500.0]))
    d = 0.08
    a = predict(hm, {"cylinder_imbalance": {"e2": -d}}).velocity
    b = predict(hm, {"cylinder_imbalance": {"e1": d / 2, "e2": -d / 2, "e3": -d / 2,
                                            "e4": -d / 2}}).velocity
    whole, half = slice(1, None, 2), slice(0, None, 2)
    np.testing.assert_allclose(b[..., whole], a[..., whole], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(np.abs(b[..., half]), np.abs(a[..., half]), rtol=1e-9)
    big = np.abs(a[..., 0]) > 1e-3 * np.abs(a[..., 0]).max()
    dphi = np.angle(b[..., 0][big] / a[..., 0][big])
    assert np.all(np.abs(np.abs(dphi) - math.pi / 2) < 1e-6)   # order 0.5: 90 deg apart


@pytest.mark.parametrize("kind", ["sz", "traces"])
def test_cylinder_load_derivative_is_exact_by_one_forward_difference(kind):
    """The cached derivative (forward differences) equals central differences to round-off:
    the load is linear in the cylinder factors for the single-zone model and for traces."""
    from benchmarks.cases import engines
    from powertrain.effects.cylinder_imbalance import STEP
    from powertrain.solvers.fast_harmonic import HarmonicModel
    e = engines()[kind]
    hm = HarmonicModel(e, np.array([1200.0, 5400.0]))
    eff = EFFECTS["cylinder_imbalance"]
    d = eff.warm(hm)
    for k in range(d.shape[0]):
        up, dn = (hm.load_of(eff.apply(e, **{f"e{k + 1}": s})) for s in (STEP, -STEP))
        central = (up - dn) / (2 * STEP)
        assert np.abs(d[k] - central).max() <= 1e-12 * np.abs(central).max()
