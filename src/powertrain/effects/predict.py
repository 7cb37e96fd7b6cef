r"""The fast cached path: channel velocities of a scenario on one
:class:`~powertrain.solvers.fast_harmonic.HarmonicModel`, many parameter sets.

Each effect of the scenario contributes through its hooks (:class:`Effect`): elastomer
scales change the networks' two-ports (condensed by the one kernel,
:func:`powertrain.kernels.two_port.two_port_kernel`), the effects' two-port changes follow,
load changes add (:meth:`Effect.load_terms`; where the load alone changes, as weighted sums
of the velocities of fixed load parts), sensor readings come last. Nonlinear mount elements
(an amplitude law or a port law, the engine's own or an effect's, :meth:`Effect.elements`)
act through :meth:`MountElement.two_port
<powertrain.physics.mount_elements.MountElement.two_port>` at
the amplitudes of the relative displacement across them, iterated to consistency at all
speeds at once (:func:`amplitude_iteration`) — the physics of the run-up's harmonic fixed
point (:mod:`powertrain.solvers.equivalent_linear`). Every effect that changes the engine
model predicts what its ``apply()`` runs, to round-off (tests/test_diagnosis_physics.py).
A linear scenario solves only the ``orders`` asked for; one body mode added to the nominal
model (a missing mode alone) is the nominal system's bordered extension, solved without a
new solve (:meth:`HarmonicModel.solve_one_more_mode`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.effects.registry import EFFECTS
from powertrain.physics.mount_network import PackedNetworks
from powertrain.solvers.equivalent_linear import fixed_point
from powertrain.solvers.fast_harmonic import HarmonicModel

#: Amplitude fixed point: relative change of every speed's amplitudes at convergence (the
#: run-up's :func:`powertrain.solvers.equivalent_linear.fixed_point`, looser: the fit's
#: residuals are compared at ~1e-3).
TOLERANCE = 1e-6


@dataclass
class Prediction:
    """Complex channel velocities of a scenario on a :class:`HarmonicModel`.

    Attributes
    ----------
    velocity : ndarray (n_r, n_ch, 16) complex
        Peak amplitudes of orders 0.5..8 [m/s].
    iterations : int
        Fixed-point iterations of the nonlinear elements (0 if none).
    amplitudes : ndarray (n_r, n_net) or None
        Relative-displacement amplitudes of the networks at convergence [m] (None: every
        element linear).
    elements : list or None
        The networks' mount elements the prediction used (None: every element linear).
    """

    velocity: np.ndarray
    iterations: int = 0
    amplitudes: np.ndarray | None = None
    elements: list | None = None


def _filled(hm, scenario):
    sc = {}
    for name, p in scenario.items():
        if name not in EFFECTS:
            raise KeyError(f"unknown effect {name!r}")
        sc[name] = (EFFECTS[name], {**hm.effect_defaults(EFFECTS[name]), **p})
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


def _load(hm, sc):
    """The load harmonics with every effect's change."""
    load = hm.load
    for eff, p in sc.values():
        d = eff.load_delta(hm, p)
        if d is not None:
            load = load + d
    return load


def _load_velocity(hm, sc):
    """Channel velocities of the nominal model under the load with every effect's change:
    the nominal load's velocities plus the effects' weighted load parts' (each part solved
    once, :meth:`HarmonicModel.load_velocity`)."""
    v = hm.load_velocity("nominal load", hm.load[None])[0]
    for eff, p in sc.values():
        terms = eff.load_terms(hm, p)
        if terms is not None and np.any(terms[1]):
            v = v + np.tensordot(terms[1], hm.load_velocity(*terms[::2]), axes=1)
    return v


def _elements(hm, sc, s_el):
    """The networks' mount elements with the elastomer scales ``s_el`` (spring and damper
    factors) and the effects' changes; None when every one is linear (the cached two-ports
    serve). The scales keep every element's laws, so linearity is told before any element
    is scaled."""
    probe = list(hm.elements)
    for eff, p in sc.values():
        probe = eff.elements(hm, probe, p)
    if not any(el.nonlinear for el in probe):
        return None
    if s_el is None:
        return probe
    els = [el.scaled(float(s), float(d))
           for el, s, d in zip(hm.elements, *s_el)]
    for eff, p in sc.values():
        els = eff.elements(hm, els, p)
    return els


def amplitude_iteration(hm, sc, els, load, body, *, tol=TOLERANCE, start=None):
    """The nonlinear elements' fixed point at every speed at once
    (:func:`powertrain.solvers.equivalent_linear.fixed_point`, the run-up's), ``g`` the
    amplitudes of :meth:`HarmonicModel.relative_amplitude`.

    Returns ``(two-ports with the effects, rigid-body amplitudes q, A (n_r, n_net),
    iterations)``; raises ``AmplitudeNotConverged`` (a ``FloatingPointError``) naming the
    mount direction and speed when it does not converge."""
    nl = np.array([el.nonlinear for el in els])
    base = np.zeros((hm.rpm.size, len(els)))
    if start is not None and np.shape(start) == base.shape:
        base = np.array(start, float)
    names = [f"{hm.mount_names[mi]}.{axis}" for (mi, axis, _), k in zip(hm.networks, nl) if k]
    packed = PackedNetworks.of([el.lumped for el in els])    # once per fixed point

    def full(a):
        A = base.copy()
        A[:, nl] = a
        return A

    def solve(a):
        abc = _two_ports(sc, hm, hm.two_ports_at(full(a), els, packed))
        return abc, hm.solve(abc[0], load, abc=abc, body=body)

    a, (abc, q), iterations = fixed_point(
        solve, lambda x: hm.relative_amplitude(x[1], body)[:, nl], names, hm.rpm,
        base[:, nl], tol)
    return abc, q, full(a), iterations


def _linear_velocity(hm, abc, load, body, orders):
    """Channel velocities (n_r, n_ch, 16) of the linear model with the two-ports ``abc``,
    the load ``load`` and the body ``body``, solved at the ``orders`` only (zero at the
    others; None: all)."""
    h = slice(1, None) if orders is None else np.asarray(orders, int) + 1
    if (body is not None and body is not hm.body and abc is hm.two_ports()
            and load is hm.load and body.adds_one_mode_to(hm.body)):
        q = hm.solve_one_more_mode(body, harmonics=h)       # one mode added: no solve
    else:
        q = hm.solve(abc[0], load, harmonics=h, abc=abc, body=body)
    sub = hm.velocity(q, harmonics=h, body=body)
    if orders is None:
        return sub
    v = np.zeros(sub.shape[:2] + (hm.omega.shape[1] - 1,), complex)
    v[..., h - 1] = sub
    return v


def predict(hm: HarmonicModel, scenario: dict, *, tol=TOLERANCE,
            warm_amplitudes=None, orders=None) -> Prediction:
    """Channel velocities with the effects of ``scenario`` on the cached model.

    Parameters
    ----------
    hm : HarmonicModel
    scenario : dict
        ``{effect name: {parameter: value}}`` (SI); missing parameters take their defaults.
    tol : float
        Convergence of the nonlinear elements' amplitudes (relative).
    warm_amplitudes : ndarray (n_r, n_net), optional
        Start of the amplitude fixed point (a nearby scenario's converged ``amplitudes``: a
        fit's finite-difference steps then converge in a few iterations instead of ten to
        twenty); the result agrees with a cold start to ``tol``.
    orders : array_like of int, optional
        Indices (0..15, orders 0.5..8) of the velocities wanted: where every element is
        linear, only their harmonics are solved (the other velocities are zero; a fit that
        scores some orders solves only those). None: all. The nonlinear elements' fixed
        point needs every harmonic (the amplitudes sum over them) and solves them all.
    """
    sc = _filled(hm, scenario)
    s_el = None
    for eff, p in sc.values():
        s = eff.elastomer_scale(hm, p)
        if s is not None:
            s_el = s if s_el is None else (s_el[0] * s[0], s_el[1] * s[1])
    body = _body(hm, sc)
    els = _elements(hm, sc, s_el)
    A, iterations = None, 0
    if els is not None:
        _, q, A, iterations = amplitude_iteration(hm, sc, els, _load(hm, sc), body, tol=tol,
                                                  start=warm_amplitudes)
        v = hm.velocity(q, body=body)
    else:
        h = None if orders is None else np.asarray(orders, int) + 1
        nominal = hm.two_ports() if s_el is None else hm.two_ports_scaled(*s_el, harmonics=h)
        abc = _two_ports(sc, hm, nominal)
        if s_el is None and abc is nominal and body is getattr(hm, "body", None):
            v = _load_velocity(hm, sc)          # only the load changed: no solve
        else:
            v = _linear_velocity(hm, abc, _load(hm, sc), body, orders)
    for eff, p in sc.values():
        v = eff.reading(v, p)
    return Prediction(v, iterations, A, els)
