r"""Run-up velocities with unmodelled effects on the frequency-domain model (the fast
prediction of :mod:`powertrain.effects`), as a run-up result; the ordinary run-up with effects
is :func:`powertrain.workflows.runup.runup_with_effects`.
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.orders import ORDERS
from powertrain.effects import predict
from powertrain.results.runup import RunupResult
from powertrain.solvers.fast_harmonic import N_HARMONICS, HarmonicModel


def simulate(engine, rpm, scenario: dict):
    """Run-up velocities (harmonic steady state) of ``engine`` with the effects of
    ``scenario``; a :class:`~powertrain.results.runup.RunupResult` holding the velocity only
    (displacement = velocity/(iω), acceleration = iω·velocity, no mount forces)."""
    hm = HarmonicModel(engine, rpm)
    w = hm.omega[:, 1:N_HARMONICS][:, None, :]
    v = predict(hm, scenario).velocity
    return RunupResult(rpm=hm.rpm, orders=ORDERS.copy(), channels=list(hm.channels),
                       displacement=v / (1j * w), velocity=v, acceleration=1j * w * v,
                       mount_force=np.zeros_like(v), mean_mount_force=np.zeros(v.shape[:2]),
                       periodicity=np.zeros(hm.rpm.size),
                       settings={"solver": "harmonic (effects)", "effects": scenario},
                       meta={"engine": getattr(engine, "name", "")})
