r"""``amplitude_stiffness``: the elastomer's stiffness depends on the engine-side amplitude.

Springs and dampers × :math:`g(a) = 1 + \kappa[1/(1 + a/a_c) - 1/(1 + a_{ref}/a_c)]`
(mount data at :math:`a_{ref}` = 0.1 mm), masses kept. Equivalent linearisation: at each
speed every network's elastomer is scaled by :math:`g(a_n)`, :math:`a_n` the engine-side
peak displacement of network n, iterated to consistency (:func:`powertrain.effects.predict`).
Its time-domain check is :func:`time_domain_amplitude_check`.
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, with_network_elastomer

#: Reference amplitude of the mount data (dynamic stiffness measured at 0.1 mm) [m].
A_REF = 1.0e-4


def amplitude_factor(a, kappa, a_c):
    r"""Stiffness factor :math:`g(a) = 1 + \kappa\,[1/(1 + a/a_c) - 1/(1 + a_{ref}/a_c)]`,
    g(a_ref) = 1; ``a`` engine-side peak displacement [m], ``kappa`` [1], ``a_c`` [m]."""
    a = np.asarray(a, float)
    return 1.0 + kappa * (1.0 / (1.0 + a / a_c) - 1.0 / (1.0 + A_REF / a_c))


class AmplitudeStiffness(Effect):
    name = "amplitude_stiffness"
    kind = "structure"
    description = ("amplitude-dependent mount stiffness, equivalent linearisation iterated to "
                   "consistency (mount data at 0.1 mm)")
    engine_change = False

    def parameters(self, engine=None):
        return (Parameter("kappa", "1", 0.0, 3.0, 0.0, False,
                          "stiffening from large to vanishing amplitude"),
                Parameter("a_c", "m", 1.0e-6, 1.0e-3, 2.0e-5, True, "characteristic amplitude"))

    def start_grid(self, engine=None):
        return ((0.3, 1.0, 2.0), (3e-6, 2e-5, 1.5e-4))

    def amplitude_factors(self, amplitude, p):
        if p["kappa"] == 0.0:
            return None
        return amplitude_factor(amplitude, p["kappa"], p["a_c"])


def _rows(engine):
    from powertrain.assembly import DIRECTIONS
    from powertrain.physics.rigid_body import direction_row
    cg = np.asarray(engine.body.cg, float)
    return np.array([direction_row(np.asarray(m.position, float) - cg,
                                   np.asarray(m.rotation, float)[:, i])
                     for m in engine.mounts for i, _ in enumerate(DIRECTIONS)])


def _initial_state(system, load, n_cycle, omega):
    from powertrain.analysis.fourier import harmonic_amplitudes
    from powertrain.solvers.harmonic import harmonic_response
    fh = harmonic_amplitudes(load, axis=0)[: n_cycle // 2]
    om = 0.5 * omega * np.arange(fh.shape[0])
    qh = harmonic_response(system, fh, om)
    return (qh.real.sum(0), (1j * om[:, None] * qh).real.sum(0),
            (-(om ** 2)[:, None] * qh).real.sum(0))


def time_domain_amplitude_check(engine, rpm, kappa, a_c, *, cycles=40, angle_step_deg=1.0):
    r"""Amplitude-dependent mounts in the time domain, for checking the linearisation.

    The assembled model is integrated by Newmark (average acceleration) cycle by cycle; at
    the start of each engine cycle every network's springs and dampers are rescaled by
    :math:`g(a_n)` (masses kept; under-relaxed by 0.7 like the frequency-domain iteration)
    with :math:`a_n = \sqrt2\,\mathrm{RMS}` of its engine-side displacement over the
    previous cycle. After ``cycles`` cycles the last cycle is order-analysed.

    Returns
    -------
    velocity : ndarray (n_ch, 16) complex
        Order amplitudes of the last cycle [m/s].
    factors : ndarray (n_net,)
        Stiffness factors used in the last cycle.
    periodicity : float
        Max change of the channel velocities between the last two cycles, relative.
    """
    from powertrain.analysis.orders import order_spectrum
    from powertrain.assembly import assemble
    from powertrain.solvers.newmark import newmark
    n_cycle = int(round(720.0 / angle_step_deg))
    omega = rpm * 2 * np.pi / 60.0
    h = np.deg2rad(angle_step_deg) / omega
    theta = np.arange(n_cycle) * (4 * np.pi / n_cycle)
    load = np.asarray(engine.generalized_load(rpm, theta), float)
    b, rows = engine.body, _rows(engine)
    g = np.ones(3 * len(engine.mounts))
    state = prev_v = None
    for _ in range(cycles):
        system = assemble(b.mass, b.cg, b.inertia, with_network_elastomer(engine, g).mounts)
        F = np.zeros((n_cycle + 1, system.n_dof))
        F[:, :6] = np.concatenate([load, load[:1]])
        if state is None:
            state = _initial_state(system, load, n_cycle, omega)
        X, V, A = newmark(system.M, system.C, system.K, F, h, *state)
        state = (X[-1], V[-1], A[-1])
        a = np.sqrt(2.0) * np.std(X[:-1, :6] @ rows.T, axis=0)
        last_v = V[:-1] @ system.channel_matrix.T
        g_used = g
        g = g + 0.7 * (amplitude_factor(a, kappa, a_c) - g)
        per = float("nan") if prev_v is None else \
            np.max(np.abs(last_v - prev_v)) / np.max(np.abs(last_v))
        prev_v = last_v
    return order_spectrum(last_v, 2).T, g_used, per
