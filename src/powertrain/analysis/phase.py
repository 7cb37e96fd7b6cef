r"""Order phase: the one convention, and the crank-angle origin of measured phases.

**Convention.** The order-:math:`o` component of a quantity is

.. math:: x_o(\theta) = \sqrt2\,\mathrm{RMS}_o\cos(o\,\theta + \varphi_o),

:math:`\theta` the crank angle [rad] from cylinder-1 firing TDC (in the sense of rotation),
:math:`\varphi_o` the phase [deg], wrapped to (-180°, 180°]. The complex amplitudes of the
package (:mod:`powertrain.analysis.fourier`, :mod:`powertrain.analysis.orders`, computed
order tracking and Vold–Kalman filtering) all satisfy
:math:`x_o = \mathrm{Re}\,(\hat S_o e^{i o\theta})`, so :math:`\varphi_o = \arg\hat S_o` once
:math:`\theta` is counted from that TDC. The simulation's crank angle is (cylinder 1 at its
firing TDC at :math:`\theta = 0`, :mod:`powertrain.models.engine`); a tracked recording's angle
is counted from its first tacho edge, and :func:`to_tdc` moves the origin.

**Measured origin** (``docs/guide/track.md``, order phase): the tacho's reference pulse
fixes the angle modulo 360°, ``--tdc-offset`` places cylinder-1 firing TDC after it
(:func:`tdc_origin`); half orders stay ambiguous by 180° unless a once-per-cycle signal
(``--cycle-reference``) picks the revolution (:func:`cycle_origin`).
"""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError

#: An order below this fraction of the largest order of its channel at that speed is
#: round-off (e.g. an order the load does not excite): its phase is undefined (NaN).
PHASE_FLOOR = 1e-9
#: Spacing of successive cycle-reference edges accepted as "once per cycle": 720° ± this.
CYCLE_TOLERANCE_DEG = 36.0
#: Fewest cycle-reference edges, and the share that must pick the same revolution.
MIN_CYCLE_EDGES = 2
CYCLE_AGREEMENT = 0.9


def wrap_deg(angle_deg):
    """Angle(s) wrapped to (-180°, 180°] [deg]."""
    wrapped = 180.0 - np.mod(180.0 - np.asarray(angle_deg, float), 360.0)
    return wrapped + 0.0


def phase_deg(amplitudes, axis=-1):
    """Phase [deg] of complex order amplitudes (module docstring), NaN where the order is
    round-off (below :data:`PHASE_FLOOR` x the largest along ``axis``, the orders axis)."""
    a = np.asarray(amplitudes, complex)
    mag = np.abs(a)
    top = np.max(mag, axis=axis, keepdims=True) if a.size else mag
    phase = wrap_deg(np.degrees(np.angle(a)))
    return np.where((mag > PHASE_FLOOR * top) & (mag > 0), phase, np.nan)


def to_tdc(amplitudes, orders, origin):
    r"""Complex amplitudes re an angle origin moved to ``origin`` [rad] (the old angle of
    cylinder-1 firing TDC): :math:`\hat S_o e^{i o\,\mathrm{origin}}`; orders on the last
    axis."""
    return np.asarray(amplitudes, complex) * np.exp(1j * np.asarray(orders, float) * origin)


def tdc_origin(profile, tdc_offset_deg, cycle_edges=None, *, file=None, key="--tdc-offset"):
    """Profile angle [rad] of cylinder-1 firing TDC, and whether it is known modulo 720°.

    Parameters
    ----------
    profile : SpeedProfile
        With a reference pulse (else InputError on ``key``).
    tdc_offset_deg : float
        Crank angle of cylinder-1 firing TDC after the reference pulse [deg]: 0..360 without
        a cycle reference, 0..720 with one.
    cycle_edges : ndarray, optional
        Times [s] of the cycle reference's rising edges.
    file, key : str, optional
        Named in an :class:`~powertrain.errors.InputError` (the recording and the option).

    Returns
    -------
    origin : float
        [rad]; modulo 2π without ``cycle_edges``, modulo 4π with them.
    per_cycle : bool
        True when ``cycle_edges`` fixed the revolution (half-order phases defined).
    """
    if profile.reference is None:
        raise InputError(f"the phase needs a once-per-revolution reference pulse; the speed "
                         f"source ({profile.source}) has none (a tacho with one pulse per "
                         "revolution or a missing-tooth gap)", file=file, key=key)
    span = 720.0 if cycle_edges is not None else 360.0
    if not (np.isfinite(tdc_offset_deg) and 0.0 <= tdc_offset_deg < span):
        raise InputError(f"must be 0 <= DEG < {span:g} (crank angle of cylinder-1 firing TDC "
                         "after the reference pulse)", key="--tdc-offset")
    start = profile.reference
    if cycle_edges is not None:
        start = cycle_origin(profile, cycle_edges, file=file)
    return start + np.radians(tdc_offset_deg), cycle_edges is not None


def cycle_origin(profile, edge_times, *, file=None, key="--cycle-reference"):
    """Profile angle [rad] of the first tacho reference pulse after a cycle-reference edge
    (the same for every edge modulo 4π, else InputError)."""
    i0, i1 = profile.valid
    t0, t1 = profile.time[i0], profile.time[i1]
    edges = np.asarray(edge_times, float)
    edges = edges[(edges >= t0) & (edges <= t1)]
    if edges.size < MIN_CYCLE_EDGES:
        raise InputError(f"{edges.size} cycle-reference edge(s) inside the tacho record; at "
                         f"least {MIN_CYCLE_EDGES} needed", file=file, key=key)
    theta = np.interp(edges, profile.time, profile.angle)
    step = np.degrees(np.diff(theta))
    if np.any(np.abs(step - 720.0) > CYCLE_TOLERANCE_DEG):
        raise InputError(f"edges are {np.min(step):.0f}..{np.max(step):.0f}° of crank angle "
                         "apart; a once-per-cycle signal (720°) is needed", file=file, key=key)
    two_pi = 2.0 * np.pi
    first = profile.reference + two_pi * np.ceil((theta - profile.reference) / two_pi)
    revolution = np.round((first - profile.reference) / two_pi).astype(int) % 2
    votes = np.bincount(revolution, minlength=2)
    if votes.max() < CYCLE_AGREEMENT * revolution.size:
        raise InputError("the cycle-reference edges fall on either revolution (the signal "
                         "sits on the tacho reference pulse, or is not once per cycle)",
                         file=file, key=key)
    return profile.reference + two_pi * int(np.argmax(votes))
