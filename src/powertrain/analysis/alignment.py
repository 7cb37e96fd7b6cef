r"""A recorded manoeuvre lined up with a simulated one: the crank speed of a
once-per-revolution tacho through standstill, a trigger channel's time, the time shift that
best matches two speed profiles and whether that shift is determined at all.

**Tacho speed** (:func:`tacho_rpm`): each interval between rising edges gives its mean speed
:math:`60/\Delta t` [rpm], placed at the interval's midpoint, linear between midpoints.
Before the first edge :math:`e_0`, with :math:`d_1` the first interval: where the recording
starts more than :math:`d_1` before :math:`e_0`, the crank cannot have turned at the first
interval's speed over that time (it would have passed the pulse once more inside the
record), so it is taken at rest until one first interval before the first edge
(:math:`e_0 - d_1`, where the pulse before would have been) and rising linearly from 0 there
to the first interval's speed at its midpoint; otherwise it was already turning and the
first interval's speed is held back to the first sample. After the last edge likewise: the
speed falls linearly to 0 at one last interval after it where the record goes on longer
than that, else the last interval's speed is held.

**Trigger** (:func:`trigger_time`): event time 0 is the first rising crossing (linear
between samples) of the mid level between the channel's smallest and largest values.

**Alignment on the speed** (:func:`align_speed`): the shift :math:`s` minimising the mean of
:math:`(n_\mathrm{rec}(t + s) - n_\mathrm{sim}(t))^2` over :data:`GRID` times of the
event, the shorter of the two taken to lie inside the longer (a grid of 801 shifts, then
refined 50 times finer about the best). Its standard error is
:math:`\sigma / \sqrt{\sum \dot n_\mathrm{sim}^2}` over those times (least squares on one
parameter), :math:`\sigma` the recorded speed's scatter (the second differences' RMS over
:math:`\sqrt 6`, at least :data:`SPEED_FLOOR_RPM`); where :data:`ALIGN_SIGMAS` standard
errors exceed the time the crank takes to turn :data:`ALIGN_TOLERANCE_DEG` at the event's
top speed, the speed varies too little to align on and the recording is refused (a trigger
channel is then needed). It is refused too where the speed matches as well elsewhere: a
shift outside the valley of the best one (beyond where the cost first rises by
:math:`\sigma^2` on either side) whose cost is within :math:`\sigma^2` of the best (a
recording of two starts).
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.speed import tacho_edges
from powertrain.errors import InputError

#: Times of the event at which the speeds are matched.
GRID = 400
#: Smallest scatter assumed of a recorded speed [rpm] (the resolution of an rpm channel).
SPEED_FLOOR_RPM = 1.0
#: An alignment on the speed is accepted when ALIGN_SIGMAS standard errors of its shift are
#: at most the time the crank takes to turn ALIGN_TOLERANCE_DEG [deg] at the event's top
#: speed (2 deg: 4 deg of phase on the 2nd order, about 7 % RMS of an identical waveform).
ALIGN_SIGMAS = 3.0
ALIGN_TOLERANCE_DEG = 2.0
#: Least part of the event a recording must cover after alignment.
MIN_COVERAGE = 0.5


def tacho_rpm(time, tacho, *, file=None, key="tacho") -> np.ndarray:
    """Crank speed [rpm] at every sample from a once-per-revolution tacho (module
    docstring: interval means at their midpoints, standstill before the first and after
    the last edge where the record is long enough to show it).

    Parameters
    ----------
    time : ndarray (n,)
        [s]
    tacho : ndarray (n,)
        Pulse train [V].
    file, key : str, optional
        Named in error messages.
    """
    time = np.asarray(time, float)
    edges = tacho_edges(time, tacho, file=file, key=key)
    d = np.diff(edges)
    tt, rr = 0.5 * (edges[1:] + edges[:-1]), 60.0 / d
    if edges[0] - time[0] > d[0]:
        tt, rr = np.r_[edges[0] - d[0], tt], np.r_[0.0, rr]
    if time[-1] - edges[-1] > d[-1]:
        tt, rr = np.r_[tt, edges[-1] + d[-1]], np.r_[rr, 0.0]
    return np.interp(time, tt, rr)


def trigger_time(time, signal, *, file=None, key="--trigger") -> float:
    """Time [s] of the first rising crossing of the mid level between the smallest and the
    largest value of ``signal`` (linear between samples).

    Parameters
    ----------
    time : ndarray (n,)
        [s]
    signal : ndarray (n,)
        Trigger channel [V or any unit].
    file, key : str, optional
        Named in error messages.
    """
    time = np.asarray(time, float)
    x = np.asarray(signal, float)
    lo, hi = float(np.min(x)), float(np.max(x))
    if not hi - lo > 1e-12 * max(abs(hi), abs(lo), 1.0):
        raise InputError("the trigger channel is constant (no rising crossing)",
                         file=file, key=key)
    mid = 0.5 * (lo + hi)
    up = np.flatnonzero((x[:-1] < mid) & (x[1:] >= mid))
    if up.size == 0:
        raise InputError("the trigger channel never rises through its mid level "
                         f"({mid:g})", file=file, key=key)
    i = int(up[0])
    return float(time[i] + (mid - x[i]) / (x[i + 1] - x[i]) * (time[i + 1] - time[i]))


def coverage(t0, t1, rec0, rec1, shift):
    """Part of the event ``t0..t1`` [s] the recording ``rec0..rec1`` covers when the event's
    time t is the recording's t + ``shift``: ``(first, last)`` event times [s]."""
    return max(t0, rec0 - shift), min(t1, rec1 - shift)


def align_speed(t_sim, rpm_sim, t_rec, rpm_rec, *, file=None, key="rpm") -> tuple:
    """Time shift [s] of the recording against the event (the recording's time of the event's
    time 0) and its standard error [s], from the speeds (module docstring).

    Parameters
    ----------
    t_sim, rpm_sim : ndarray
        The event's times [s] and crank speed [rpm] (the manoeuvre's or the simulation's).
    t_rec, rpm_rec : ndarray
        The recording's sample times [s] and crank speed [rpm].
    file, key : str, optional
        Named in error messages.

    Raises
    ------
    InputError
        The recording shorter than :data:`MIN_COVERAGE` of the event, or the speed too flat
        to align on.
    """
    t_sim, t_rec = np.asarray(t_sim, float), np.asarray(t_rec, float)
    length, event = t_rec[-1] - t_rec[0], t_sim[-1] - t_sim[0]
    if length < MIN_COVERAGE * event:
        raise InputError(f"the recording is {length:.4g} s long, less than "
                         f"{MIN_COVERAGE:.0%} of the {event:.4g} s event", file=file,
                         key="time")
    t = np.linspace(t_sim[0], t_sim[-1], GRID)
    target = np.interp(t, t_sim, rpm_sim)
    costs = _costs(t, target, t_rec, rpm_rec)
    lo, hi = sorted((t_rec[0] - t_sim[0], t_rec[-1] - t_sim[-1]))
    shifts = np.linspace(lo, hi, 801)
    coarse = costs(shifts)
    best = int(np.argmin(coarse))
    shift = float(shifts[best])
    step = shifts[1] - shifts[0]
    if step > 0:
        fine = np.clip(shift + np.linspace(-2.0, 2.0, 201) * step, lo, hi)
        shift = float(fine[np.argmin(costs(fine))])
    sigma = _scatter(t, t_rec, rpm_rec, shift)
    other = _second_match(coarse, best, sigma ** 2)
    if other is not None:
        raise InputError(f"the crank speed matches the event's at two places of the recording "
                         f"(the event starting at {shift:.4f} s or at {shifts[other]:.4f} s); "
                         "give --trigger CHANNEL", file=file, key=key)
    slope = np.gradient(target, t)[(t + shift >= t_rec[0]) & (t + shift <= t_rec[-1])]
    info = float(np.sum(slope ** 2))
    error = sigma / np.sqrt(info) if info > 0 else np.inf
    top = max(float(np.max(np.abs(target))), SPEED_FLOOR_RPM)
    allowed = ALIGN_TOLERANCE_DEG / (6.0 * top)
    if not ALIGN_SIGMAS * error <= allowed:
        raise InputError(
            f"the crank speed varies too little over the event to line the recording up on "
            f"it (shift uncertain by +-{ALIGN_SIGMAS * error * 1e3:.3g} ms, more than "
            f"{allowed * 1e3:.2g} ms = {ALIGN_TOLERANCE_DEG:g} deg of crank at {top:.0f} "
            "rpm); give --trigger CHANNEL", file=file, key=key)
    return shift, error


def _costs(t, target, t_rec, rpm_rec):
    """Mean squared speed difference [rpm²] over the event times inside the recording, as
    a function of an array of shifts."""
    def costs(shifts):
        at = t[None, :] + shifts[:, None]
        inside = (at >= t_rec[0]) & (at <= t_rec[-1])
        err = np.where(inside, np.interp(at, t_rec, rpm_rec) - target, 0.0)
        return np.sum(err ** 2, axis=1) / np.maximum(np.sum(inside, axis=1), 1)
    return costs


def _second_match(costs, best, margin):
    """Index of the best shift outside the valley of ``best`` whose cost is within
    ``margin`` of the best (as good a match elsewhere), else None."""
    above = np.flatnonzero(costs >= costs[best] + margin)
    left = above[above < best]
    right = above[above > best]
    outside = np.zeros(costs.size, bool)
    if left.size:
        outside[:left[-1]] = True
    if right.size:
        outside[right[0] + 1:] = True
    close = np.flatnonzero(outside & (costs < costs[best] + margin))
    return int(close[np.argmin(costs[close])]) if close.size else None


def _scatter(t, t_rec, rpm_rec, shift) -> float:
    """The recorded speed's scatter [rpm] over the event at ``shift``: the RMS of its second
    differences over sqrt(6) (white noise), at least :data:`SPEED_FLOOR_RPM`."""
    sel = (t_rec >= t[0] + shift) & (t_rec <= t[-1] + shift)
    r = np.asarray(rpm_rec, float)[sel]
    scatter = np.sqrt(np.mean(np.diff(r, 2) ** 2) / 6.0) if r.size > 2 else 0.0
    return max(scatter, SPEED_FLOOR_RPM)
