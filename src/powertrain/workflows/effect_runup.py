r"""Run-ups with unmodelled effects through the ordinary run-up (a workflow over the effect
registry, :mod:`powertrain.effects`).

* engine-model effects change the engine (``Effect.apply``), in registry order;
* amplitude-dependent effects: the factors :math:`g(a_n)` of the equivalent linearisation
  are converged at each speed on the frequency-domain model
  (:func:`powertrain.effects.predict`); then each speed step runs with every network's
  springs and dampers scaled by its factor at that speed (``meta["amplitude_factors"]``);
* sensor effects: the channels' displacement, velocity and acceleration are read through
  the effect (the transmitted forces are not sensor readings and stay as they are).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.effects import EFFECTS, check_scenario, predict, with_network_elastomer
from powertrain.solvers.fast_harmonic import N_HARMONICS, HarmonicModel


def runup_with_effects(engine, rpm, scenario: dict, **options):
    """Run-up of ``engine`` with the effects of ``scenario`` (``{effect: {parameter:
    value}}``, SI) through :func:`powertrain.workflows.runup.run_runup` (``**options``: its keyword
    arguments); ``settings["effects"]`` records the scenario."""
    from powertrain.workflows.runup import run_runup
    sc = check_scenario(scenario, engine)
    rpm = np.atleast_1d(np.asarray(rpm, float))
    for name, eff in EFFECTS.items():
        if name in sc and eff.engine_change:
            engine = eff.apply(engine, **sc[name])
    amp = {n: p for n, p in sc.items()
           if EFFECTS[n].amplitude_factors(np.ones((1, 1)), p) is not None}
    if amp:
        g = predict(HarmonicModel(engine, rpm), amp).factors
        parts = [run_runup(with_network_elastomer(engine, g[i]), [r], **options)
                 for i, r in enumerate(rpm)]
        result = _concatenate(parts)
        result.rigid_body_modes_hz = run_runup(engine, rpm[:1], solver="harmonic"
                                               ).rigid_body_modes_hz
        result.meta["amplitude_factors"] = g.tolist()
    else:
        result = run_runup(engine, rpm, **options)
    for name, p in sc.items():
        if EFFECTS[name].response_only:
            for attr in ("displacement", "velocity", "acceleration"):
                setattr(result, attr, EFFECTS[name].reading(getattr(result, attr), p))
    result.settings["effects"] = sc
    return result


def _concatenate(parts):
    """One RunupResult from single-speed results (same channels and orders)."""
    first = parts[0]
    out = dataclasses.replace(first)
    for attr in ("rpm", "displacement", "velocity", "acceleration", "mount_force",
                 "mean_mount_force", "periodicity"):
        setattr(out, attr, np.concatenate([getattr(p, attr) for p in parts], axis=0))
    out.solver_seconds = float(sum(p.solver_seconds for p in parts))
    out.settings = dict(first.settings)
    out.meta = dict(first.meta)
    return out


def simulate(engine, rpm, scenario: dict):
    """Run-up velocities (harmonic steady state) of ``engine`` with the effects of
    ``scenario``; a :class:`~powertrain.results.runup.RunupResult` holding the velocity only
    (displacement = velocity/(iω), acceleration = iω·velocity, no mount forces)."""
    from powertrain.analysis.orders import ORDERS
    from powertrain.results.runup import RunupResult
    hm = HarmonicModel(engine, rpm)
    w = hm.omega[:, 1:N_HARMONICS][:, None, :]
    v = predict(hm, scenario).velocity
    return RunupResult(rpm=hm.rpm, orders=ORDERS.copy(), channels=list(hm.channels),
                       displacement=v / (1j * w), velocity=v, acceleration=1j * w * v,
                       mount_force=np.zeros_like(v), mean_mount_force=np.zeros(v.shape[:2]),
                       periodicity=np.zeros(hm.rpm.size),
                       settings={"solver": "harmonic (effects)", "effects": scenario},
                       meta={"engine": getattr(engine, "name", "")})
