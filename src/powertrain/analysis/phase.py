r"""Order phase: the one convention, and the crank-angle origin of measured phases.

**Convention.** The order-:math:`o` component of a quantity is

.. math:: x_o(\theta) = \sqrt2\,\mathrm{RMS}_o\cos(o\,\theta + \varphi_o),

:math:`\theta` the crank angle [rad] from cylinder-1 firing TDC, :math:`\varphi_o` the phase
[deg] wrapped to (-180°, 180°]. Every complex amplitude of the package satisfies
:math:`x_o = \mathrm{Re}\,(\hat S_o e^{i o\theta})`, so :math:`\varphi_o = \arg\hat S_o`; a
tracked recording's angle counts from its first tacho edge and :func:`to_tdc` moves it.

**Measured origin** (``docs/guide/track.md``): the tacho's reference pulse fixes the angle
modulo 360°, ``--tdc-offset`` places TDC after it (:func:`tdc_origin`); half orders need a
once-per-cycle signal (``--cycle-reference``, :func:`cycle_origin`).
"""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError

#: An order below this fraction of its channel's largest is round-off: phase NaN.
PHASE_FLOOR = 1e-9
#: Spacing of successive cycle-reference edges accepted as "once per cycle": 720° ± this.
CYCLE_TOLERANCE_DEG = 36.0
#: Fewest cycle-reference edges, and the share that must pick the same revolution.
MIN_CYCLE_EDGES = 2
CYCLE_AGREEMENT = 0.9


def wrap_deg(angle_deg):
    """``angle_deg`` [deg] wrapped to (-180°, 180°]."""
    wrapped = 180.0 - np.mod(180.0 - np.asarray(angle_deg, float), 360.0)
    return wrapped + 0.0


def phase_deg(amplitudes, axis=-1):
    """Phase [deg] of complex order ``amplitudes``; NaN below :data:`PHASE_FLOOR` times the
    largest along ``axis`` (the orders)."""
    a = np.asarray(amplitudes, complex)
    mag = np.abs(a)
    top = np.max(mag, axis=axis, keepdims=True) if a.size else mag
    phase = wrap_deg(np.degrees(np.angle(a)))
    return np.where((mag > PHASE_FLOOR * top) & (mag > 0), phase, np.nan)


def to_tdc(amplitudes, orders, origin):
    r"""``amplitudes`` of ``orders`` (last axis) re the angle ``origin`` [rad]:
    :math:`\hat S_o e^{i o\,\mathrm{origin}}`."""
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
        Named in error messages.

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
    """Angle [rad] of ``profile``'s first reference pulse after a cycle-reference edge
    (``edge_times`` [s]; the same modulo 4π for all, else InputError naming ``file``,
    ``key``)."""
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
                         "sits on the tacho reference pulse, or is not once per cycle)", file=file, key=key)
    return profile.reference + two_pi * int(np.argmax(votes))
