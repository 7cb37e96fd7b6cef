r"""The fast cached path: channel velocities of a scenario on one
:class:`~powertrain.solvers.fast_harmonic.HarmonicModel`, many parameter sets.

Each effect contributes through its hooks (:class:`Effect`): elastomer scales and two-port
changes, load changes (weighted sums of the velocities of fixed load parts), sensor readings
last. Nonlinear mount elements act at the amplitudes of the relative displacement across
them, iterated to consistency at all speeds at once (:func:`amplitude_iteration`, the
run-up's harmonic fixed point, :mod:`powertrain.solvers.equivalent_linear`). Every effect
that changes the engine model predicts what its ``apply()`` runs, to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.effects.registry import EFFECTS
from powertrain.physics.mount_network import PackedNetworks
from powertrain.solvers.equivalent_linear import fixed_point
from powertrain.solvers.fast_harmonic import HarmonicModel

#: Amplitude fixed point: relative change of every speed's amplitudes at convergence.
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
        Relative-displacement amplitudes of the networks [m] (None: all linear).
    elements : list or None
        The networks' mount elements used (None: all linear).
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
    for eff, p in sc.values():
        abc = eff.two_port(hm, abc, p)
    return abc


def _body(hm, sc):
    """The modal body with the effects' changes (None: no body)."""
    body = getattr(hm, "body", None)
    if body is None:
        return None
    for eff, p in sc.values():
        body = eff.body_change(hm, p, body)
    return body


def _load(hm, sc):
    load = hm.load
    for eff, p in sc.values():
        d = eff.load_delta(hm, p)
        if d is not None:
            load = load + d
    return load


def _load_velocity(hm, sc):
    """Nominal model's channel velocities under the changed load (each load part solved once)."""
    v = hm.load_velocity("nominal load", hm.load[None])[0]
    for eff, p in sc.values():
        terms = eff.load_terms(hm, p)
        if terms is not None and np.any(terms[1]):
            v = v + np.tensordot(terms[1], hm.load_velocity(*terms[::2]), axes=1)
    return v


def _elements(hm, sc, s_el):
    """The networks' mount elements with the elastomer scales ``s_el`` and the effects'
    changes; None when every one is linear."""
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
    """The nonlinear elements' amplitude fixed point at every speed at once, from ``start``
    [m]: ``(two-ports, rigid-body amplitudes q, A (n_r, n_net) [m], iterations)``; raises
    ``AmplitudeNotConverged`` (a ``FloatingPointError``) without convergence."""
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
    """Channel velocities (n_r, n_ch, 16) of the linear model, solved at ``orders`` only."""
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
        Start of the amplitude fixed point [m]; the result agrees with a cold start to ``tol``.
    orders : array_like of int, optional
        Indices (0..15, orders 0.5..8) wanted; with linear elements only those are solved
        (the others zero). None: all.
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
