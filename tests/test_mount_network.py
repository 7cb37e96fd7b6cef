"""Closed-form checks of the mount networks (physics/mount_network.py, models/mount.py)
and of the Newmark integrator (solvers/newmark.py).

Oracles: Kovarik (2016) eq. 1-3 (cross- and input-point stiffness), eq. 8-9 (single mass
oscillator), eq. 29-39 (triple mass oscillator, parallel connection), Table 2 (parameter
counts); series/parallel spring combination at 0 Hz; the exact solution of a damped linear
oscillator; the known period error (w h)^2/12 of the average-acceleration Newmark method.
"""

from __future__ import annotations

import numpy as np
import pytest
from tolerances import (
    CLOSED_FORM_REL,
    NEWMARK_BOUND_SAFETY,
    PERIODIC_STATE_REL,
    TIME_VS_FREQUENCY_REL,
)

from powertrain.models.mount import TOPOLOGIES, MountModel
from powertrain.solvers.mount_time_domain import time_cross_point_stiffness
from powertrain.solvers.newmark import newmark, periodic_state

FREQS_HZ = np.array([0.5, 3.0, 17.0, 60.0, 150.0, 400.0])


def random_model(name, seed=0):
    """Random positive parameters of a realistic size: c [N/m], d [N s/m], m [kg]."""
    rng = np.random.default_rng(seed)
    topo = TOPOLOGIES[name]
    scale = {"c": 1e5, "d": 2e2, "m": 1.0}
    values = [scale[p[0]] * 10 ** rng.uniform(-1, 1) for p in topo.parameters]
    return MountModel.from_values(topo, values)


def rel_err(a, b):
    return np.max(np.abs(np.asarray(a) - np.asarray(b)) / np.abs(np.asarray(b)))


def test_kelvin_voigt_element():
    """K = c + i w d for a single Kelvin-Voigt element (eq. 10-12 applied to one element)."""
    c, d = 2.3e5, 170.0
    m = MountModel.from_values("kelvin-voigt", [c, d])
    w = 2 * np.pi * FREQS_HZ
    assert rel_err(m.cross_point_stiffness(FREQS_HZ), c + 1j * w * d) < CLOSED_FORM_REL
    # no internal mass: input- and cross-point stiffness coincide (eq. 1-3)
    assert rel_err(m.input_point_stiffness(FREQS_HZ), c + 1j * w * d) < CLOSED_FORM_REL


def triple_parallel_closed_form(w, c1, d1, c2, d2, m1, c3, d3, c4, d4, m2, c5, d5, m3, c6, d6):
    """Kovarik 2016, eq. 30, 32, 34 and 39, written out independently of the solver."""
    iw = 1j * w
    y1 = (iw * d2 + c2) / (-w**2 * m1 + iw * (d2 + d3) + c2 + c3)                  # eq. 30
    y2 = (iw * d5 + c5) / (-w**2 * m3 + iw * (d5 + d6) + c5 + c6)                  # eq. 32
    y3 = (iw * d4 + c4) / (-w**2 * m2 + iw * (d4 + d5 * (1 - y2)) + c4 + c5 * (1 - y2))  # 34
    return c1 + y1 * c3 + y2 * y3 * c6 + iw * (d1 + y1 * d3 + y2 * y3 * d6)        # eq. 39


@pytest.mark.parametrize("seed", range(5))
def test_triple_parallel_equals_thesis_closed_form(seed):
    """Triple mass oscillator, parallel connection: solver = eq. 29-39 (random parameters)."""
    m = random_model("triple-parallel", seed)
    w = 2 * np.pi * FREQS_HZ
    expected = triple_parallel_closed_form(w, *m.values)
    assert rel_err(m.cross_point_stiffness(FREQS_HZ), expected) < CLOSED_FORM_REL


@pytest.mark.parametrize("seed", range(3))
def test_single_mass_oscillator_input_point_stiffness(seed):
    """K_IP of the single mass oscillator = eq. 3 with X2/X1 from eq. 9, by hand."""
    m = random_model("single", seed)
    c1, d1, c2, d2, m1, c3, d3 = m.values
    me = 80.0
    w = 2 * np.pi * FREQS_HZ
    iw = 1j * w
    x2 = (c2 + iw * d2) / (-w**2 * m1 + iw * (d2 + d3) + c2 + c3)        # eq. 9, X1 = 1
    kip = -w**2 * me + iw * d1 + iw * d2 * (1 - x2) + c1 + c2 * (1 - x2)  # eq. 3, X1 = 1
    assert rel_err(m.input_point_stiffness(FREQS_HZ, engine_mass=me), kip) < CLOSED_FORM_REL
    kcp = c1 + iw * d1 + (c3 + iw * d3) * x2                              # eq. 14-16
    assert rel_err(m.cross_point_stiffness(FREQS_HZ), kcp) < CLOSED_FORM_REL


def _series(*k):
    return 1.0 / sum(1.0 / x for x in k)


#: Static stiffness of each preset: springs in series/parallel (dampers carry no static load).
STATIC = {
    "kelvin-voigt": lambda p: p["c1"],
    "sls": lambda p: p["c1"],
    "single": lambda p: p["c1"] + _series(p["c2"], p["c3"]),
    "dual": lambda p: p["c1"] + _series(p["c2"], p["c3"], p["c4"]),
    "triple-series": lambda p: p["c1"] + _series(p["c2"], p["c3"], p["c4"], p["c5"]),
    "triple-parallel": lambda p: (p["c1"] + _series(p["c2"], p["c3"])
                                  + _series(p["c4"], p["c5"], p["c6"])),
    "quad": lambda p: (p["c1"] + _series(p["c2"], p["c3"], p["c4"])
                       + _series(p["c5"], p["c6"], p["c7"])),
    "penta": lambda p: (p["c1"] + _series(p["c2"], p["c3"]) + _series(p["c4"], p["c5"], p["c6"])
                        + _series(p["c7"], p["c8"], p["c9"])),
    "single-extra": lambda p: p["c1"] + _series(p["c2"], p["c3"] + _series(p["c4"], p["c5"])),
    "dual-extra": lambda p: p["c1"] + _series(p["c2"], _series(p["c3"], p["c4"])
                                              + _series(p["c5"], p["c6"])),
}


def test_static_table_covers_every_preset():
    assert set(STATIC) == set(TOPOLOGIES)


@pytest.mark.parametrize("name", sorted(TOPOLOGIES))
def test_static_stiffness_is_series_parallel_combination(name):
    """K_CP(0) = the spring network's series/parallel combination, imaginary part 0."""
    m = random_model(name, seed=7)
    k0 = m.cross_point_stiffness(0.0)[0]
    assert abs(k0.imag) <= CLOSED_FORM_REL * abs(k0.real)
    assert m.static_stiffness() == pytest.approx(STATIC[name](m.params), rel=CLOSED_FORM_REL)


#: Kovarik 2016, Table 2 ("n variables"); the Kelvin-Voigt element is the project's addition.
TABLE2_PARAMETER_COUNT = {
    "sls": 3, "single": 7, "dual": 10, "triple-series": 13, "triple-parallel": 15,
    "quad": 18, "penta": 23, "single-extra": 12, "dual-extra": 16, "kelvin-voigt": 2,
}


def test_presets_are_those_of_table_2():
    assert set(TOPOLOGIES) == set(TABLE2_PARAMETER_COUNT)


@pytest.mark.parametrize("name", sorted(TOPOLOGIES))
def test_parameter_count_of_table_2(name):
    assert len(TOPOLOGIES[name].parameters) == TABLE2_PARAMETER_COUNT[name]


@pytest.mark.parametrize("name", sorted(TOPOLOGIES))
def test_time_method_agrees_with_frequency_method(name):
    """Rate-machine test in time (Newmark + FFT) = condensed network, < 1e-3 relative.

    Includes the SLS model, whose internal node is massless.
    """
    m = random_model(name, seed=3)
    f = np.array([2.0, 35.0, 250.0])
    r = time_cross_point_stiffness(m, f)
    assert rel_err(r.kcp, m.cross_point_stiffness(f)) < TIME_VS_FREQUENCY_REL


def test_sls_has_a_massless_node():
    assert TOPOLOGIES["sls"].masses == (None,)


# --- Newmark average acceleration against exact solutions --------------------------------

MASS, OMEGA_N, ZETA = 2.0, 2 * np.pi * 5.0, 0.05     # kg, rad/s, -
STIFF = MASS * OMEGA_N**2                             # N/m
DAMP = 2 * ZETA * MASS * OMEGA_N                      # N s/m


def _sdof(F, h, x0=0.0, v0=0.0):
    X, V, _ = newmark([[MASS]], [[DAMP]], [[STIFF]], np.asarray(F, float)[:, None], h,
                      [x0], [v0])
    return X[:, 0], V[:, 0]


def _free(t, x0, v0):
    """Exact free vibration of the damped oscillator."""
    wd = OMEGA_N * np.sqrt(1 - ZETA**2)
    s = ZETA * OMEGA_N
    return np.exp(-s * t) * (x0 * np.cos(wd * t) + (v0 + s * x0) / wd * np.sin(wd * t))


def _transient_bound(amplitude, h, t):
    """Leading-order error of a decaying free vibration of initial amplitude ``amplitude``.

    The period error (w h)^2/12 turns into a phase error w t (w h)^2/12 that grows with t
    while the envelope decays as exp(-zeta w t): bound = amplitude (w h)^2/12
    max_t[exp(-zeta w t) w t], times the safety factor.
    """
    growth = np.max(np.exp(-ZETA * OMEGA_N * t) * OMEGA_N * t)
    return NEWMARK_BOUND_SAFETY * amplitude * (OMEGA_N * h) ** 2 / 12 * growth


@pytest.mark.parametrize("steps_per_period", [40, 80])
def test_newmark_free_vibration(steps_per_period):
    """Free damped vibration within the period-error bound (and not far below it)."""
    h = 2 * np.pi / OMEGA_N / steps_per_period
    t = np.arange(5 * steps_per_period + 1) * h           # five periods
    x, _ = _sdof(np.zeros(t.size), h, x0=1e-3, v0=0.0)
    err = np.max(np.abs(x - _free(t, 1e-3, 0.0)))
    bound = _transient_bound(1e-3, h, t)
    assert bound / NEWMARK_BOUND_SAFETY / 2 <= err <= bound


def test_newmark_second_order_convergence():
    """Halving the step divides the error by 4 (second-order method)."""
    errs = []
    for n in (40, 80, 160):
        h = 2 * np.pi / OMEGA_N / n
        t = np.arange(5 * n + 1) * h
        x, _ = _sdof(np.zeros(t.size), h, x0=1e-3)
        errs.append(np.max(np.abs(x - _free(t, 1e-3, 0.0))))
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 3.6) & (ratios < 4.4)), ratios


def test_newmark_harmonic_load_from_rest():
    """F0 cos(W t) from rest: exact = steady state + free transient.

    Bound: the transient as in the free case, plus the steady-state error. The trapezoidal
    rule's steady state is the exact one at the warped frequency W (1 + (W h)^2/12), so
    its error is |X_p| (W h)^2/12 * W |d ln H/dW| (no growth in time).
    """
    F0, W = 10.0, 2 * np.pi * 3.0
    h = 2 * np.pi / OMEGA_N / 60
    t = np.arange(int(round(1.0 / h)) + 1) * h             # 1 s: 5 natural periods
    dyn = STIFF - MASS * W**2 + 1j * DAMP * W
    Xp = F0 / dyn
    xp = (Xp * np.exp(1j * W * t)).real
    vp = (1j * W * Xp * np.exp(1j * W * t)).real
    exact = xp + _free(t, -xp[0], -vp[0])
    x, _ = _sdof(F0 * np.cos(W * t), h)
    wd = OMEGA_N * np.sqrt(1 - ZETA**2)
    transient = np.hypot(xp[0], (vp[0] + ZETA * OMEGA_N * xp[0]) / wd)
    sensitivity = W * abs((-2 * MASS * W + 1j * DAMP) / dyn)
    bound = (_transient_bound(transient, h, t)
             + NEWMARK_BOUND_SAFETY * abs(Xp) * (W * h) ** 2 / 12 * sensitivity)
    assert np.max(np.abs(x - exact)) <= bound


def test_periodic_state_repeats_after_one_period():
    """periodic_state gives (x0, v0, a0) that Newmark maps onto itself after one period."""
    rng = np.random.default_rng(1)
    M = np.diag([1.0, 0.5, 0.0])                             # with a massless node
    A = rng.uniform(0.5, 2.0, (3, 3))
    K = 1e4 * (A @ A.T + 3 * np.eye(3))
    C = 5.0 * (A @ A.T)
    N = 64
    h = 1.0 / (7.0 * N)
    t = np.arange(N + 1) * h
    F = np.column_stack([np.cos(2 * np.pi * 7 * t), 0.3 * np.sin(4 * np.pi * 7 * t),
                         np.zeros(N + 1)])
    x0, v0, a0 = periodic_state(M, C, K, F, h)
    X, V, Acc = newmark(M, C, K, F, h, x0, v0, a0)
    for Z, z0 in ((X, x0), (V, v0), (Acc, a0)):
        assert np.max(np.abs(Z[-1] - z0)) <= PERIODIC_STATE_REL * np.max(np.abs(Z))
    assert np.max(np.abs(X)) > 0
