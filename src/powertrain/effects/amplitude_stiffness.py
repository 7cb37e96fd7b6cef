r"""``amplitude_stiffness``: the elastomer's stiffness depends on the amplitude across the mount.

A fit of the mount laws of issue 20, not a physics of its own: the candidate puts one
:class:`~powertrain.physics.mount_laws.PowerLaw` on every mount direction,

.. math:: \text{springs} \times f,\quad \text{dampers} \times f^{\gamma},\qquad
   f = \mathrm{clip}\big((A_{ref}/A)^{n},\ 0.2,\ 5\big),

:math:`A_{ref}` = 0.1 mm (where mount data are measured and the networks fitted, so the
network is unchanged at :math:`A_{ref}`), :math:`A` the amplitude of the relative
displacement across the mount direction (√2 × RMS of orders 0.5–8), masses kept; one
exponent :math:`n` and one damping exponent :math:`\gamma` (as ``mount_stiffness``'s: prior
1 ± 0.5, a constant loss factor at 1) for all mounts (one law per mount design doubled the fit time without
separating it from ``mount_stiffness``, docs/validation/diagnosis.md). :meth:`~AmplitudeStiffness.apply`
sets :attr:`MountModel.amplitude_law <powertrain.models.mount.MountModel.amplitude_law>`,
which the run-up's harmonic fixed point
(:mod:`powertrain.solvers.equivalent_linear`) solves; the fast path
(:func:`powertrain.effects.predict`) evaluates the same
:meth:`MountElement.two_port <powertrain.physics.mount_elements.MountElement.two_port>` at
its own fixed-point amplitudes. At :math:`n = 0` (the default) the mounts are left as they
are (a law of the engine's mount files included); otherwise the candidate's law replaces
theirs. Its time-domain check is :func:`time_domain_amplitude_check`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.effects.base import Effect, Parameter, map_networks, with_network_elastomer
from powertrain.effects.mount_stiffness import damping_exponent_parameter
from powertrain.physics.mount_laws import PowerLaw

#: Reference amplitude of the mount data (dynamic stiffness measured at 0.1 mm) [m].
A_REF = 1.0e-4


def amplitude_law(exponent: float, damping_exponent: float = 1.0) -> PowerLaw:
    """The candidate's law: :class:`PowerLaw` at :data:`A_REF` with its default limits."""
    return PowerLaw(A_REF, float(exponent), damping_exponent=float(damping_exponent))


class AmplitudeStiffness(Effect):
    name = "amplitude_stiffness"
    kind = "structure"
    description = ("amplitude-dependent mount stiffness: springs x f = (A_ref/A)^n, dampers "
                   "x f^γ (A_ref = 0.1 mm, A across the mount), at the harmonic fixed point")

    def parameters(self, engine=None):
        return (Parameter("exponent", "1", 0.0, 1.0, 0.0, False,
                          "power-law exponent n of every mount's elastomer"),
                damping_exponent_parameter("f"))

    def start_grid(self, engine=None):
        return ((0.1, 0.2, 0.35), (1.0,))

    def apply(self, engine, **params):
        if params.get("exponent", 0.0) == 0.0:
            return engine
        law = amplitude_law(params["exponent"], params.get("damping_exponent", 1.0))
        return map_networks(engine, lambda mi, m, ax, mod:
                            dataclasses.replace(mod, amplitude_law=law))

    def elements(self, hm, elements, p):
        if p["exponent"] == 0.0:
            return elements
        law = amplitude_law(p["exponent"], p.get("damping_exponent", 1.0))
        return [dataclasses.replace(el, amplitude_law=law) for el in elements]


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
    from powertrain.analysis.orders import order_spectrum
    from powertrain.assembly import assemble
    from powertrain.solvers.newmark import newmark
    law = amplitude_law(exponent)
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
        g = g + 0.7 * (law.scales(a)[0] - g)
        per = float("nan") if prev_v is None else \
            np.max(np.abs(last_v - prev_v)) / np.max(np.abs(last_v))
        prev_v = last_v
    return order_spectrum(last_v, 2).T, g_used, per
