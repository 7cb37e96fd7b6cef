r"""``balancer_error``: the balancer shafts' unbalance and timing, per shaft.

Shaft k's unbalance times :math:`g(1 \pm a/2)` and its drive lagging by :math:`\delta \pm s/2`
[rad of shaft angle], + for the first half of the shafts (file order), − for the others.
A lag delays the shaft's force: its order amplitude times :math:`g_k e^{-i\delta_k}`, in the
engine model :math:`\alpha = \sigma(\rho\theta - \delta_k) + \phi`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.effects.base import Effect, Parameter


def shaft_signs(n):
    """+1 for the first half of the shafts (file order), −1 for the others (0 for one)."""
    return np.where(np.arange(n) < n / 2.0, 1.0, -1.0) if n > 1 else np.zeros(n)


def shaft_factors(n, gain, asym):
    """Unbalance factor of each shaft: ``gain (1 ± asym/2)``."""
    return gain * (1.0 + 0.5 * asym * shaft_signs(n))


def shaft_lags(n, lag, skew):
    """Drive lag of each shaft [rad]: ``lag ± skew/2``."""
    return lag + 0.5 * skew * shaft_signs(n)


def with_balancer_error(engine, gain=1.0, lag=0.0, asym=0.0, skew=0.0):
    """The engine with every shaft's unbalance and timing changed (module docstring)."""
    n = len(engine.balancer.shafts)
    f, d = shaft_factors(n, gain, asym), shaft_lags(n, lag, skew)
    shafts = tuple(dataclasses.replace(s, mass_radius=s.mass_radius * fk,
                                       phase=s.phase - s.sense * dk)
                   for s, fk, dk in zip(engine.balancer.shafts, f, d))
    return engine.replace(balancer=dataclasses.replace(engine.balancer, shafts=shafts))


class BalancerError(Effect):
    name = "balancer_error"
    kind = "excitation"
    description = ("balancer shafts' unbalance and drive timing, common and shaft-to-shaft "
                   "(per-shaft unbalance and timing)")

    def parameters(self, engine=None):
        return (Parameter("gain", "1", 0.0, 2.0, 1.0, False, "balancer unbalance factor"),
                Parameter("lag", "rad", -0.7, 0.7, 0.0, False, "balancer timing lag"),
                Parameter("asym", "1", -0.8, 0.8, 0.0, False,
                          "unbalance difference between the shafts (first - second, relative)"),
                Parameter("skew", "rad", -0.7, 0.7, 0.0, False,
                          "timing difference between the shafts (first - second lag)"))

    def start_grid(self, engine=None):
        return ((0.6, 1.0, 1.4), (-0.35, -0.15, 0.0, 0.15, 0.35), (-0.3, 0.0, 0.3),
                (-0.3, -0.15, 0.0, 0.15, 0.3))

    def applicable(self, engine):
        return len(engine.balancer.shafts) > 0

    def apply(self, engine, **params):
        return with_balancer_error(engine, **params)

    def warm(self, hm):
        hm.shaft_loads()

    def load_terms(self, hm, p):
        sh = hm.shaft_loads()
        n = sh.shape[0]
        on = 1.0 if hm.engine.balancer.enabled else 0.0
        f = shaft_factors(n, p["gain"], p["asym"]) * np.exp(
            -1j * shaft_lags(n, p["lag"], p.get("skew", 0.0)))
        return "shafts", f - on, sh
