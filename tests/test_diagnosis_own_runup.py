"""No claim on perfect data: the engine's own run-up, written as the measured file with the
numerical error of a time-domain solve, is "no effect" with and without order phase at any
noise floor (issue 37)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from powertrain.analysis.orders import order_label
from powertrain.diagnosis import diagnose
from powertrain.diagnosis.data import DYNAMIC_RANGE_DB, gap_data
from powertrain.effects import predict
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.measured import MeasuredRunup
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows.measurement import WRITTEN_ORDERS

RPM = np.arange(1000.0, 6001.0, 100.0)


@pytest.fixture(scope="module")
def engine():
    return read_engine(DEFAULT_ENGINE_PATH)


def _as_measured(v, channels, phase, rng):
    """The run-up ``v`` (n_r, n_ch, 16) [m/s peak] as a measured file, with the numerical
    error the project's Newmark run-up leaves against the harmonic solve (0.02 dB and 0.03 deg
    on the orders present; the orders that are zero in the harmonic solve at 85-120 dB below
    the channel's strongest order, random phase)."""
    rms = np.abs(v) / math.sqrt(2.0)
    top = rms.max(axis=(1, 2), keepdims=True)
    junk = top * 10 ** (rng.uniform(-130, -100, rms.shape) / 20)
    zero = rms < 1e-12 * rms.max(axis=-1, keepdims=True)
    lev = np.where(zero, junk, rms * 10 ** (rng.normal(0, 0.02, rms.shape) / 20))
    phi = np.where(zero, rng.uniform(-180, 180, rms.shape),
                   np.degrees(np.angle(v)) + rng.normal(0, 0.03, rms.shape))
    curves, phases = {}, {}
    for c, (m, d) in enumerate(channels):
        for o in WRITTEN_ORDERS:
            h = int(round(2 * o)) - 1
            curves[(m, d, order_label(o))] = (RPM.copy(), lev[:, c, h].copy())
            if phase:
                phases[(m, d, order_label(o))] = phi[:, c, h].copy()
    return MeasuredRunup(curves, source="own run-up", phases=phases)


@pytest.mark.parametrize("floor, phase", [(1e-12, True)])
def test_own_run_up_with_solver_error_is_no_effect(engine, floor, phase):
    """At a floor far below the solver's error, with phase (the guard itself, at any floor:
    tests/test_decision_rule.py; the twelve run-ups of issue 37: docs/validation)."""
    hm = HarmonicModel(engine, RPM)
    meas = _as_measured(predict(hm, {}).velocity, hm.channels, phase,
                        np.random.default_rng(37))
    d = diagnose(meas, engine, noise_floor=floor, progress=False, band_check=False,
                 pairs=False).to_dict()
    assert d["verdict"] == "no effect", d["verdict_text"]


def test_levels_below_the_dynamic_range_are_left_out_censored_ones_kept(engine):
    """Against the strongest order of any channel at that speed."""
    r = np.array([1000.0, 2000.0, 3000.0])
    top, tiny = np.full(3, 1e-3), np.full(3, 1e-3 * 10 ** (-(DYNAMIC_RANGE_DB + 5) / 20))
    meas = MeasuredRunup({("left", "z", "order_2"): (r, top),
                          ("left", "z", "order_0.5"): (r, tiny),
                          ("left", "z", "order_1"): (r, np.full(3, 1e-12))},
                         phases={("left", "z", "order_0.5"): np.zeros(3),
                                 ("left", "z", "order_2"): np.zeros(3)})
    d = gap_data(meas, engine, noise_floor=1e-13)
    c = d.channels.index(("left", "z"))
    q = {name: d.quantities.index(name) for name in ("order_0.5", "order_1", "order_2")}
    assert np.isnan(d.level[:, c, q["order_0.5"]]).all()       # numerical error: left out
    assert np.isnan(d.phase[:, c, q["order_0.5"]]).all()
    assert np.isfinite(d.level[:, c, q["order_2"]]).all()
    d = gap_data(meas, engine, noise_floor=1e-7)                # below 3x the floor: censored
    assert d.censored[:, c, q["order_0.5"]].all()
