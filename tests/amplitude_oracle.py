"""Test oracle of the amplitude law's linearisation: the assembled linear model integrated by
Newmark cycle by cycle, every network's springs and dampers rescaled by the law at the start
of each engine cycle (a numerical path independent of the harmonic fixed point of
:mod:`powertrain.solvers.equivalent_linear` and of the diagnosis's prediction)."""

from __future__ import annotations

import numpy as np

from powertrain.analysis.channel import DIRECTIONS
from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.analysis.orders import order_spectrum
from powertrain.effects.amplitude_stiffness import amplitude_law
from powertrain.effects.base import with_network_elastomer
from powertrain.physics.rigid_body import direction_row
from powertrain.solvers.harmonic import harmonic_response
from powertrain.solvers.newmark import newmark


def _rows(engine):
    cg = np.asarray(engine.body.cg, float)
    return np.array([direction_row(np.asarray(m.position, float) - cg,
                                   np.asarray(m.rotation, float)[:, i])
                     for m in engine.mounts for i, _ in enumerate(DIRECTIONS)])


def _initial_state(system, load, n_cycle, omega):
    fh = harmonic_amplitudes(load, axis=0)[: n_cycle // 2]
    om = 0.5 * omega * np.arange(fh.shape[0])
    qh = harmonic_response(system, fh, om)
    return (qh.real.sum(0), (1j * om[:, None] * qh).real.sum(0),
            (-(om ** 2)[:, None] * qh).real.sum(0))


def time_domain_amplitude_check(engine, rpm, exponent, *, cycles=40, angle_step_deg=1.0):
    r"""The candidate's law in the time domain, for checking the linearisation (rigid
    ground: the engine-side displacement is the relative one).

    The assembled linear model is integrated by Newmark (average acceleration) cycle by
    cycle; at the start of each engine cycle every network's springs and dampers are
    rescaled by the law's factor :math:`g(A_n)` (masses kept; under-relaxed by 0.7) with
    :math:`A_n = \sqrt2\,\mathrm{RMS}` of its displacement over the previous cycle. After
    ``cycles`` cycles the last cycle is order-analysed.

    Returns
    -------
    velocity : ndarray (n_ch, 16) complex
        Order amplitudes of the last cycle [m/s].
    factors : ndarray (n_net,)
        Stiffness factors used in the last cycle.
    periodicity : float
        Max change of the channel velocities between the last two cycles, relative.
    """
    law = amplitude_law(exponent)
    n_cycle = int(round(720.0 / angle_step_deg))
    omega = rpm * 2 * np.pi / 60.0
    h = np.deg2rad(angle_step_deg) / omega
    theta = np.arange(n_cycle) * (4 * np.pi / n_cycle)
    load = np.asarray(engine.generalized_load(rpm, theta), float)
    rows = _rows(engine)
    g = np.ones(3 * len(engine.mounts))
    state = prev_v = None
    for _ in range(cycles):
        system = with_network_elastomer(engine, g).assemble(rigid_ground=True)
        F = np.zeros((n_cycle + 1, system.n_dof))
        F[:, :6] = np.concatenate([load, load[:1]])
        if state is None:
            state = _initial_state(system, load, n_cycle, omega)
        X, V, A = newmark(system.M, system.C, system.K, F, h, *state)
        state = (X[-1], V[-1], A[-1])
        a = np.sqrt(2.0) * np.std(X[:-1, :6] @ rows.T, axis=0)
        last_v = V[:-1] @ system.channel_matrix.T
        g_used = g
        g = g + 0.7 * (law.scales(a)[0] - g)
        per = float("nan") if prev_v is None else \
            np.max(np.abs(last_v - prev_v)) / np.max(np.abs(last_v))
        prev_v = last_v
    return order_spectrum(last_v, 2).T, g_used, per
