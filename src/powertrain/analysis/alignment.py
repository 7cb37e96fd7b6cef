r"""A recorded manoeuvre lined up with a simulated one (a trigger channel's time:
:mod:`powertrain.analysis.trigger`).

**Tacho speed** (:func:`tacho_rpm`): each interval between rising edges gives its mean speed
:math:`60\,\Delta c/(N\Delta t)` [rpm] at its midpoint, linear between; at rest before the
first edge (after the last) where the record extends more than one interval beyond it.

**Speed alignment** (:func:`align_speed`): the shift :math:`s` minimising the mean of
:math:`(n_\mathrm{rec}(t) - n_\mathrm{sim}(t - s))^2` over the recorded samples inside the
event; standard error :math:`\sigma / \sqrt{\sum \dot n_\mathrm{sim}^2}`, :math:`\sigma` the
recorded speed's scatter (second differences' RMS over :math:`\sqrt 6`). Refused where
:data:`ALIGN_SIGMAS` standard errors exceed the time the crank turns
:data:`ALIGN_TOLERANCE_DEG` at top speed, or where a shift outside the best one's valley
costs within :math:`\sigma^2` of the best (two starts).

**Tacho alignment** (:func:`align_tacho`): the shift minimising the variance of the event's
crank angle at the edges less :math:`1/N` revolution per pulse counted.
"""

from __future__ import annotations

import warnings

import numpy as np

from powertrain.analysis.speed import count_teeth, drop_spikes
from powertrain.errors import InputError, PowertrainWarning

#: Times of the event at which the speeds are matched.
GRID = 400
#: Smallest scatter assumed of a recorded speed [rpm] (an rpm channel's resolution).
SPEED_FLOOR_RPM = 1.0
#: Accepted when ALIGN_SIGMAS standard errors are at most the time the crank turns
#: ALIGN_TOLERANCE_DEG [deg] at top speed (2 deg: 4 deg of 2nd-order phase, ~7 % RMS).
ALIGN_SIGMAS = 3.0
ALIGN_TOLERANCE_DEG = 2.0
#: Least part of the event a recording must cover after alignment.
MIN_COVERAGE = 0.5
#: A speed channel changing at fewer than this share of its samples is held between updates.
HELD_SHARE = 0.5
#: Largest RMS speed difference at the best shift, as a share of the event's speed range.
MISMATCH_SHARE = 0.1
#: Tacho alignment: least pulses inside the event, least phase scatter [rev], and the most
#: [rev] at the best shift.
MIN_EDGES = 4
PHASE_FLOOR_REV = 1e-4
MISMATCH_REV = 0.05
#: Longest correlation of a speed residual [s] (two periods of the 2nd order at 250 rpm)
#: and of a tacho's phase residual [rev] (a sampled tacho's slow drift).
CORRELATION_S = 0.25
CORRELATION_REV = 8.0
#: The option an alignment's error offers instead.
TRIGGER = "--trigger CHANNEL"
#: Times the event's speed table is read at, and most recorded samples a speed cost reads.
FINE = 20001
COST_SAMPLES = 20000


class AlignmentWarning(PowertrainWarning):
    """A shift uncertain by more than :data:`ALIGN_TOLERANCE_DEG` (:data:`ALIGN_SIGMAS`
    standard errors) because the recorded speed differs from the event's (a correlated
    residual), not because it varies too little."""


def tacho_counts(edges, pulses_per_rev=1, *, file=None, key="tacho") -> tuple:
    """``(edges, counts)``: a tacho's rising ``edges`` [s], spikes dropped, and the pulses
    counted at each: one per edge at one pulse per revolution, else
    :func:`~powertrain.analysis.speed.count_teeth`'s; ``file``, ``key`` name errors."""
    edges = np.asarray(edges, float)
    if pulses_per_rev == 1:
        edges = drop_spikes(edges)[0]
        return edges, np.arange(edges.size, dtype=float)
    edges, counts, _ = count_teeth(edges, file=file, key=key)
    return edges, counts


def tacho_rpm(time, edges, counts, pulses_per_rev=1) -> np.ndarray:
    """Crank speed [rpm] at every sample from a tacho (module docstring).

    Parameters
    ----------
    time : ndarray (n,)
        [s]
    edges, counts : ndarray (m,)
        Rising edges [s] and pulses counted at each (:func:`tacho_counts`).
    pulses_per_rev : int
    """
    time = np.asarray(time, float)
    d = np.diff(edges)
    tt, rr = 0.5 * (edges[1:] + edges[:-1]), 60.0 * np.diff(counts) / (pulses_per_rev * d)
    if edges[0] - time[0] > d[0]:
        tt, rr = np.r_[edges[0] - d[0], tt], np.r_[0.0, rr]
    if time[-1] - edges[-1] > d[-1]:
        tt, rr = np.r_[tt, edges[-1] + d[-1]], np.r_[rr, 0.0]
    return np.interp(time, tt, rr)


def trigger_shift(crossing, trigger_at, rpm_event, *, file=None, key="--trigger"):
    """The recording's time [s] of the event's time 0 from a trigger's ``crossing``
    (:class:`~powertrain.analysis.trigger.TriggerCrossing`) marking the event's time
    ``trigger_at`` [s]; refused where :data:`ALIGN_SIGMAS` noise errors and half a sampling
    interval (root sum of squares) exceed the time the crank turns
    :data:`ALIGN_TOLERANCE_DEG` at the top of ``rpm_event`` [rpm]."""
    top = max(float(np.max(np.abs(rpm_event))), SPEED_FLOOR_RPM)
    allowed = ALIGN_TOLERANCE_DEG / (6.0 * top)
    bound = float(np.hypot(ALIGN_SIGMAS * crossing.spread, 0.5 * crossing.sampling))
    if not bound <= allowed:
        raise InputError(f"the trigger fixes the event's start to +-{bound * 1e3:.3g} ms "
                         f"only ({ALIGN_SIGMAS:g} times its noise over its slope and half a "
                         f"sampling interval of {crossing.sampling * 1e3:.3g} ms), more than "
                         f"{allowed * 1e3:.3g} ms = {ALIGN_TOLERANCE_DEG:g} deg of crank at "
                         f"{top:.0f} rpm", file=file, key=key)
    return crossing.time - float(trigger_at)


def coverage(t0, t1, rec0, rec1, shift):
    """``(first, last)`` event times [s] of ``t0..t1`` the recording ``rec0..rec1`` covers,
    the event's time t being the recording's t + ``shift`` [s]."""
    return max(t0, rec0 - shift), min(t1, rec1 - shift)


def align_speed(t_sim, rpm_sim, t_rec, rpm_rec, *, file=None, key="rpm",
                partial=True, trigger=TRIGGER) -> tuple:
    """Shift [s] of the recording against the event, and its standard error [s], from the speeds.

    Parameters
    ----------
    t_sim, rpm_sim : ndarray
        The event's times [s] and crank speed [rpm].
    t_rec, rpm_rec : ndarray
        The recording's sample times [s] and crank speed [rpm].
    file, key : str, optional
        Named in error messages.
    partial : bool
        The recording may cover part of the event (at least :data:`MIN_COVERAGE`); False:
        all of it.
    trigger : str
        The option an error message offers instead.

    Raises
    ------
    InputError
        The recording too short, the speed too flat, matching at two places or nowhere.
    """
    t_sim, t_rec = np.asarray(t_sim, float), np.asarray(t_rec, float)
    length, event = t_rec[-1] - t_rec[0], t_sim[-1] - t_sim[0]
    if length < MIN_COVERAGE * event:
        raise InputError(f"the recording is {length:.4g} s long, less than "
                         f"{MIN_COVERAGE:.0%} of the {event:.4g} s event", file=file, key="time")
    sigma = _scatter(t_rec, rpm_rec)
    t_rec, rpm_rec = unheld_speed(t_rec, np.asarray(rpm_rec, float))
    t, target = _fine(t_sim, rpm_sim)
    costs = _costs(t, target, t_rec, rpm_rec)
    shifts, coarse, shift = _search(costs, _shift_range(t_sim, (t_rec[0], t_rec[-1]), partial), event)
    best = int(np.argmin(coarse))
    other = _second_match(coarse, best, sigma ** 2)
    if other is not None:
        raise InputError(f"the crank speed matches the event's at two places of the recording "
                         f"(the event starting at {shift:.4f} s or at {shifts[other]:.4f} s); "
                         f"give {trigger}", file=file, key=key)
    _check_match(float(np.sqrt(costs(np.array([shift]))[0])), sigma, target, (file, key), trigger)
    white, error = _shift_error(t, target, t_rec, rpm_rec, shift, sigma)
    top = max(float(np.max(np.abs(target))), SPEED_FLOOR_RPM)
    allowed = ALIGN_TOLERANCE_DEG / (6.0 * top)
    if not ALIGN_SIGMAS * white <= allowed:
        raise InputError(
            f"the crank speed varies too little over the event to line the recording up on "
            f"it (shift uncertain by +-{ALIGN_SIGMAS * white * 1e3:.3g} ms, more than "
            f"{allowed * 1e3:.2g} ms = {ALIGN_TOLERANCE_DEG:g} deg of crank at {top:.0f} "
            f"rpm); give {trigger}", file=file, key=key)
    _warn_uncertain(error, allowed, "crank speed", file)
    return shift, error


def align_tacho(t_sim, rpm_sim, span, edges, *, counts=None, pulses_per_rev=1, file=None,
                key="tacho", partial=True, trigger=TRIGGER) -> tuple:
    """Shift [s] of the recording against the event, and its standard error [s], from a tacho.

    Parameters
    ----------
    t_sim, rpm_sim : ndarray
        The event's times [s] and crank speed [rpm].
    span : (float, float)
        The recording's first and last time [s].
    edges : ndarray
        The tacho's rising edges [s].
    counts : ndarray, optional
        Pulses counted at each edge (default one per edge; :func:`tacho_counts`).
    pulses_per_rev : int
    file, key, partial, trigger
        As :func:`align_speed`'s.

    Raises
    ------
    InputError
        Fewer than :data:`MIN_EDGES` edges in the event, no match, two, or one not determined.
    """
    t_sim, rpm_sim = _fine(t_sim, rpm_sim)
    edges = np.asarray(edges, float)
    revs = (np.arange(edges.size, dtype=float) if counts is None
            else np.asarray(counts, float)) / pulses_per_rev
    speed = np.abs(rpm_sim) / 60.0                                        # [rev/s]
    rev = np.r_[0.0, np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t_sim))]
    event = t_sim[-1] - t_sim[0]
    shifts, coarse, shift = _search(
        lambda ss: np.array([_phase_cost(s, t_sim, rev, edges, revs, span) for s in ss]),
        _shift_range(t_sim, span, partial), event)
    if not np.isfinite(coarse).any():
        raise InputError(f"the tacho's pulses match the event's revolutions at no shift (at "
                         f"least {MIN_EDGES} pulses in the event, {pulses_per_rev} per "
                         "revolution); give --pulses-per-rev N for a wheel of N teeth, or "
                         f"{trigger}", file=file, key=key)
    best = int(np.argmin(coarse))
    sigma = max(float(np.sqrt(_phase_cost(shift, t_sim, rev, edges, revs, span))), PHASE_FLOOR_REV)
    if sigma > MISMATCH_REV:
        raise InputError(f"the tacho's pulses do not follow the event's crank angle at any "
                         f"shift ({sigma:.2g} rev RMS at the best, read as {pulses_per_rev} "
                         "per revolution); give --pulses-per-rev N for a wheel of N teeth, "
                         f"or {trigger}", file=file, key=key)
    other = _second_match(coarse, best, sigma ** 2)
    if other is not None:
        raise InputError(f"the tacho's pulses match the event at two places of the recording "
                         f"(the event starting at {shift:.4f} s or at {shifts[other]:.4f} s); "
                         f"give {trigger}", file=file, key=key)
    white, error = _phase_error(shift, t_sim, rev, speed, edges, revs, span, sigma)
    allowed = ALIGN_TOLERANCE_DEG / (360.0 * max(float(np.max(speed)), 1e-9))
    if not ALIGN_SIGMAS * white <= allowed:
        raise InputError(f"the tacho's pulses fix the event's start to +-"
                         f"{ALIGN_SIGMAS * white * 1e3:.3g} ms only, more than "
                         f"{allowed * 1e3:.2g} ms = {ALIGN_TOLERANCE_DEG:g} deg of crank; give "
                         f"{trigger}", file=file, key=key)
    _warn_uncertain(error, allowed, "tacho's pulses", file)
    return shift, error


def _warn_uncertain(error, allowed, what, file) -> None:
    """:class:`AlignmentWarning` where ALIGN_SIGMAS times ``error`` [s] exceeds ``allowed`` [s]."""
    if ALIGN_SIGMAS * error > allowed:
        warnings.warn(AlignmentWarning(
            f"{file or 'the recording'}: lined up on the {what}, but the recorded speed "
            f"differs from the event's: the shift is uncertain by "
            f"+-{ALIGN_SIGMAS * error * 1e3:.3g} ms, more "
            f"than {allowed * 1e3:.2g} ms = {ALIGN_TOLERANCE_DEG:g} deg of crank; a trigger "
            "channel (--trigger) lines it up better"), stacklevel=3)


def _edges_inside(shift, t_sim, span, edges) -> tuple:
    """``(first, last, at, inside)``: the covered event span [s], edges in event time, mask."""
    first, last = coverage(t_sim[0], t_sim[-1], span[0], span[1], shift)
    at = edges - shift
    return first, last, at, (at >= first) & (at <= last)


def _phase_error(shift, t_sim, rev, speed, edges, revs, span, sigma) -> tuple:
    """``(white, error)`` [s] of the tacho's shift: from the white phase scatter ``sigma``
    [rev], and from the residual as correlated (:func:`_correlated_error`), at least white."""
    _, _, at, inside = _edges_inside(shift, t_sim, span, edges)
    phase = np.interp(at[inside], t_sim, rev) - revs[inside]
    rate = np.interp(at[inside], t_sim, speed)
    lags = round(CORRELATION_REV * np.median(np.diff(revs)) ** -1)
    design = rate - np.mean(rate)
    white = sigma / np.sqrt(float(design @ design)) if np.any(design) else np.inf
    return white, max(white, _correlated_error(design, phase - np.mean(phase), PHASE_FLOOR_REV, lags))


def _phase_cost(shift, t_sim, rev, edges, revs, span) -> float:
    """Variance [rev²] of the event's angle at the edges less ``revs``; inf where fewer than
    :data:`MIN_EDGES` or the edges span other revolutions than the event turns (within one)."""
    first, last, at, inside = _edges_inside(shift, t_sim, span, edges)
    at, counted = at[inside], revs[inside]
    if at.size < MIN_EDGES:
        return np.inf
    turned = np.interp(last, t_sim, rev) - np.interp(first, t_sim, rev)
    if abs(counted[-1] - counted[0] + counted[1] - counted[0] - turned) > 1.5:
        return np.inf
    return float(np.var(np.interp(at, t_sim, rev) - counted))


def _search(costs, bounds, event) -> tuple:
    """``(shifts, their costs, best shift)``: a grid over ``bounds`` at most ``event / GRID``
    apart, 100 times finer about its best, then the parabola vertex (:func:`_vertex`)."""
    lo, hi = bounds
    shifts = np.linspace(lo, hi, max(801, int(np.ceil((hi - lo) / (event / GRID))) + 1))
    coarse = costs(shifts)
    best = int(np.argmin(coarse))
    fine = np.clip(shifts[best] + np.linspace(-2.0, 2.0, 401) * (shifts[1] - shifts[0]), lo, hi)
    near = costs(fine)
    k = int(np.argmin(near))
    return shifts, coarse, _vertex(fine, near, k)


def _vertex(shifts, costs, k) -> float:
    """Vertex of the parabola through ``k`` and its neighbours where finite and convex, else
    ``shifts[k]``."""
    if not 0 < k < shifts.size - 1 or not np.all(np.isfinite(costs[k - 1:k + 2])):
        return float(shifts[k])
    left, mid, right = costs[k - 1:k + 2]
    curve = left - 2.0 * mid + right
    if not curve > 0:
        return float(shifts[k])
    step = 0.5 * (shifts[k + 1] - shifts[k - 1])
    return float(shifts[k] + 0.5 * (left - right) / curve * step)


def _shift_range(t_sim, span, partial) -> tuple:
    """Shifts [s] searched: covering :data:`MIN_COVERAGE` of the event (``partial``), else all."""
    event = t_sim[-1] - t_sim[0]
    if partial:
        return (span[0] - t_sim[-1] + MIN_COVERAGE * event, span[1] - t_sim[0] - MIN_COVERAGE * event)
    return tuple(sorted((span[0] - t_sim[0], span[1] - t_sim[-1])))


def unheld_speed(t_rec, rpm_rec):
    """``(t_rec, rpm)``: a speed channel ``rpm_rec`` [rpm] held between updates (most samples
    repeat the one before) as its updates, linear between them; any other as it is."""
    changed = np.r_[True, np.diff(rpm_rec) != 0]
    if np.mean(changed) >= HELD_SHARE or np.count_nonzero(changed) < 4:
        return t_rec, rpm_rec
    keep = changed | (np.arange(t_rec.size) == t_rec.size - 1)
    return t_rec, np.interp(t_rec, t_rec[keep], rpm_rec[keep])


def _check_match(residual, sigma, target, where, trigger):
    """Refuse a best shift whose RMS ``residual`` [rpm] exceeds :data:`MISMATCH_SHARE` of the
    event's speed range and five times the scatter."""
    span, (file, key) = float(np.ptp(target)), where
    if residual > max(MISMATCH_SHARE * span, 5.0 * sigma):
        raise InputError(f"the recorded crank speed does not match the event's at any shift "
                         f"(RMS difference {residual:.3g} rpm at the best, over "
                         f"{MISMATCH_SHARE:.0%} of its {span:.4g} rpm range); give {trigger}, or "
                         "drive the simulation with --speed-from", file=file, key=key)


def _fine(t_sim, rpm_sim):
    """The event's speed [rpm] on :data:`FINE` times (its angle is not linear between rows)."""
    t_sim = np.asarray(t_sim, float)
    t = np.linspace(t_sim[0], t_sim[-1], FINE)
    return t, np.interp(t, t_sim, np.asarray(rpm_sim, float))


def _cost_samples(target, t_rec, rpm_rec) -> tuple:
    """``(target, every)``: the event's magnitude against an unsigned channel, and the stride
    keeping at most :data:`COST_SAMPLES` recorded samples."""
    if np.min(rpm_rec) >= 0:
        target = np.abs(target)
    return target, max(1, int(np.ceil(t_rec.size / COST_SAMPLES)))


def _shift_error(t, target, t_rec, rpm_rec, shift, sigma) -> tuple:
    """``(white, error)`` [s] of the speed shift: from the white scatter ``sigma`` [rpm], and
    from the residual as correlated (:func:`_correlated_error`), at least white."""
    target, every = _cost_samples(target, t_rec, rpm_rec)
    at, rr = t_rec[::every] - shift, rpm_rec[::every]
    inside = (at >= t[0]) & (at <= t[-1])
    slope = np.interp(at[inside], t, np.gradient(target, t))
    residual = rr[inside] - np.interp(at[inside], t, target)
    lags = round(CORRELATION_S / (every * (t_rec[1] - t_rec[0])))
    white = sigma / np.sqrt(float(slope @ slope)) if np.any(slope) else np.inf
    return white, max(white, _correlated_error(slope, residual, SPEED_FLOOR_RPM, lags))


def _correlated_error(design, residual, floor, lags) -> float:
    r"""Standard error of a one-parameter least-squares fit with correlated residuals.

    Newey and West (1987): :math:`\sqrt{\sum_{|k|\le L} w_k \sum_i u_i u_{i+k}} / \sum_i
    d_i^2`, :math:`u_i = d_i r_i`, Bartlett weights :math:`w_k = 1 - |k|/(L+1)`, :math:`L`
    = ``lags`` (at most a fifth of the points); at least ``floor`` over
    :math:`\sqrt{\sum d_i^2}`."""
    d, r = np.asarray(design, float), np.asarray(residual, float)
    info = float(d @ d)
    if not info > 0:
        return np.inf
    u = d * r
    m = 1 << int(np.ceil(np.log2(2 * u.size)))             # zero-padded: no wrap-around
    lags = int(min(max(lags, 0), u.size // 5))
    cov = np.fft.irfft(np.abs(np.fft.rfft(u, m)) ** 2, m)[:lags + 1]
    weight = 2.0 * (1.0 - np.arange(lags + 1) / (lags + 1.0))
    weight[0] = 1.0
    quad = float(np.sum(weight * cov))
    return max(np.sqrt(max(quad, 0.0)), floor * np.sqrt(info)) / info


def _costs(t, target, t_rec, rpm_rec):
    """Mean squared speed difference [rpm²] inside the event as a function of shifts."""
    target, every = _cost_samples(target, t_rec, rpm_rec)
    tr, rr = t_rec[::every], rpm_rec[::every]

    def costs(shifts):
        out = np.empty(len(shifts))
        for i in range(0, len(shifts), 32):
            at = tr[None, :] - np.asarray(shifts[i:i + 32])[:, None]
            inside = (at >= t[0]) & (at <= t[-1])
            err = np.where(inside, rr - np.interp(at, t, target), 0.0)
            out[i:i + 32] = np.sum(err ** 2, axis=1) / np.maximum(np.sum(inside, axis=1), 1)
        return out
    return costs


def _second_match(costs, best, margin):
    """Index of the best shift outside ``best``'s valley costing within ``margin``, else None."""
    above = np.flatnonzero(costs >= costs[best] + margin)
    left, right = above[above < best], above[above > best]
    outside = np.zeros(costs.size, bool)
    if left.size:
        outside[:left[-1]] = True
    if right.size:
        outside[right[0] + 1:] = True
    close = np.flatnonzero(outside & (costs < costs[best] + margin))
    return int(close[np.argmin(costs[close])]) if close.size else None


def _scatter(t_rec, rpm_rec) -> float:
    """Speed scatter [rpm]: second differences' RMS over sqrt(6), at least SPEED_FLOOR_RPM."""
    r = np.asarray(rpm_rec, float)
    scatter = np.sqrt(np.mean(np.diff(r, 2) ** 2) / 6.0) if r.size > 2 else 0.0
    return max(scatter, SPEED_FLOOR_RPM)
