r"""The fast cached path: channel velocities of a scenario on one
:class:`~powertrain.solvers.fast_harmonic.HarmonicModel`, many parameter sets.

Each effect of the scenario contributes through its hooks (:class:`Effect`): elastomer
scales change the networks' two-ports (condensed by the one kernel,
:func:`powertrain.kernels.two_port.two_port_kernel`), the effects' two-port changes follow,
load changes add, amplitude-dependent factors are iterated to consistency (under-relaxation
0.7, at most 60 iterations, tolerance 1e-6), sensor readings come last. Every effect that
changes the engine model predicts what its ``apply()`` runs, to round-off
(tests/test_diagnosis_physics.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.effects.registry import EFFECTS
from powertrain.solvers.fast_harmonic import HarmonicModel


@dataclass
class Prediction:
    """Complex channel velocities of a scenario on a :class:`HarmonicModel`.

    Attributes
    ----------
    velocity : ndarray (n_r, n_ch, 16) complex
        Peak amplitudes of orders 0.5..8 [m/s].
    iterations : int
        Fixed-point iterations of the equivalent linearisation (0 if none).
    factors : ndarray (n_r, n_net) or None
        Amplitude factors g(a_n) at convergence.
    """

    velocity: np.ndarray
    iterations: int = 0
    factors: np.ndarray | None = None


def _filled(hm, scenario):
    sc = {}
    for name, p in scenario.items():
        if name not in EFFECTS:
            raise KeyError(f"unknown effect {name!r}")
        sc[name] = (EFFECTS[name], {**EFFECTS[name].defaults(hm.engine), **p})
    return sc


def _two_ports(sc, hm, abc):
    """The networks' two-ports with every effect's change."""
    for eff, p in sc.values():
        abc = eff.two_port(hm, abc, p)
    return abc


def _body(hm, sc):
    """The modal body under the mounts with the effects' changes (None: no body)."""
    body = getattr(hm, "body", None)
    if body is None:
        return None
    for eff, p in sc.values():
        body = eff.body_change(hm, p, body)
    return body


def _amplitude_effect(hm, sc):
    """The amplitude-dependent effect of the scenario (switched on), or None."""
    for eff, p in sc.values():
        if eff.amplitude_factors(np.ones((1, len(hm.networks))), p) is not None:
            return eff, p
    return None


def _iterate(hm, sc, s0, load, amp, tol, max_iter, g0=None):
    eff, p = amp
    g = np.ones((hm.rpm.size, len(hm.networks)))
    if g0 is not None and np.shape(g0) == g.shape:
        g = np.array(g0, float)
    iterations = 0
    for iterations in range(1, max_iter + 1):  # noqa: B007 (count returned)
        abc = hm.two_ports_scaled((s0[None, :] * g)[:, None, :])
        eff_abc = _two_ports(sc, hm, abc)
        q = hm.solve(eff_abc[0], load, abc=eff_abc, body=_body(hm, sc))
        g_new = eff.amplitude_factors(hm.network_amplitude(q), p)
        change = np.max(np.abs(g_new - g))
        g = g + 0.7 * (g_new - g)
        if change < tol:
            break
    return hm.two_ports_scaled((s0[None, :] * g)[:, None, :]), iterations, g


def predict(hm: HarmonicModel, scenario: dict, *, tol=1e-6, max_iter=60,
            warm_factors=None) -> Prediction:
    """Channel velocities with the effects of ``scenario`` on the cached model.

    Parameters
    ----------
    hm : HarmonicModel
    scenario : dict
        ``{effect name: {parameter: value}}`` (SI); missing parameters take their defaults.
    tol, max_iter
        Convergence of amplitude-dependent factors.
    warm_factors : ndarray (n_r, n_net), optional
        Start of the amplitude fixed point (a nearby scenario's converged ``factors``: a
        fit's finite-difference steps then converge in one or two iterations instead of
        ten to twenty); the result agrees with a cold start to ``tol``.
    """
    sc = _filled(hm, scenario)
    s_el = None
    for eff, p in sc.values():
        s = eff.elastomer_scale(hm, p)
        if s is not None:
            s_el = s if s_el is None else s_el * s
    abc = hm.two_ports() if s_el is None else hm.two_ports_scaled(s_el[None, None, :])
    load = hm.load
    for eff, p in sc.values():
        d = eff.load_delta(hm, p)
        if d is not None:
            load = load + d
    iterations, g = 0, None
    amp = _amplitude_effect(hm, sc)
    if amp is not None:
        s0 = np.ones(len(hm.networks)) if s_el is None else s_el
        abc, iterations, g = _iterate(hm, sc, s0, load, amp, tol, max_iter, warm_factors)
    abc = _two_ports(sc, hm, abc)
    body = _body(hm, sc)
    v = hm.velocity(hm.solve(abc[0], load, abc=abc, body=body), body=body)
    for eff, p in sc.values():
        v = eff.reading(v, p)
    return Prediction(v, iterations, g)
