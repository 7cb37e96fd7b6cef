r"""The time of a trigger channel's step, and how well it is known.

**Levels**: low and high are the medians of the samples below and above the middle of the
1st and 99th percentiles; the trigger level is their mean.

**Time** (:func:`trigger_crossing`; ``edge="falling"`` reads the channel inverted): the
first rising crossing of the level (linear between samples, or the least-squares line
through three or more consecutive samples within 25 % of the step of it) after which the
channel stays above for :data:`TRIGGER_HOLD_S`; crossings less than
:data:`TRIGGER_BOUNCE_S` apart are one bounce, read at its first rising crossing. A step
under :data:`TRIGGER_STEP_NOISE` times the noise (second differences' RMS over
:math:`\sqrt 6`) is refused.

**Standard error**: :math:`\sqrt{(\sigma/\dot x)^2 + t_r^2/12}`, the noise over the slope
and the time :math:`t_r` the step may lie anywhere in (from 10 % to 90 % of the step): a
held channel's update interval; one sample interval for a rise over one or two; a straight
rise's (linearly resampled) time over the whole step; else 0.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from powertrain.errors import InputError, PowertrainWarning

#: Least step [noise RMS]; time [s] the channel stays above its level after the crossing.
TRIGGER_STEP_NOISE = 10.0
TRIGGER_HOLD_S = 0.002
#: Crossings less than this apart [s] are one bounce (a switch's).
TRIGGER_BOUNCE_S = 0.005
#: A channel changing at fewer than this share of its samples (ten or more) is held.
HELD_SHARE = 0.5
#: The edges a trigger may mark.
TRIGGER_EDGES = ("rising", "falling")


class TriggerWarning(PowertrainWarning):
    """A trigger channel above its level most of the time before it rises: an active-low
    trigger read at its release."""


class TriggerCrossing(NamedTuple):
    """A trigger's step ``time`` [s] and standard ``error`` [s], from the noise ``spread``
    [s] and the ``sampling`` interval [s] the step may lie anywhere in."""

    time: float
    error: float
    spread: float
    sampling: float


def trigger_time(time, signal, *, edge="rising", file=None, key="--trigger") -> float:
    """Time [s] of the step of ``signal`` at ``time`` [s]: :func:`trigger_crossing`'s
    (``edge``, ``file``, ``key`` as there) without its error."""
    return trigger_crossing(time, signal, edge=edge, file=file, key=key).time


def trigger_crossing(time, signal, *, edge="rising", file=None, key="--trigger") -> TriggerCrossing:
    """Time [s] of a trigger channel's step and its standard error [s] (module docstring).

    Parameters
    ----------
    time : ndarray (n,)
        [s]
    signal : ndarray (n,)
        Trigger channel [V or any unit].
    edge : str
        ``rising`` (default) or ``falling`` (an active-low trigger).
    file, key : str, optional
        Named in error messages.

    Raises
    ------
    InputError
        A channel that is not finite, does not step, or never rises to stay.
    """
    if edge not in TRIGGER_EDGES:
        raise InputError(f"expected one of {', '.join(TRIGGER_EDGES)}, got {edge!r}", key="--trigger-edge")
    time = np.asarray(time, float)
    x = np.asarray(signal, float) * (1.0 if edge == "rising" else -1.0)
    if not np.all(np.isfinite(x)):
        raise InputError("the trigger channel has NaN or infinite values", file=file, key=key)
    lo, hi = trigger_levels(x, file, key)
    mid = 0.5 * (lo + hi)
    hold = max(1, int(np.ceil(TRIGGER_HOLD_S / np.median(np.diff(time)))))
    above = x >= mid
    up = np.flatnonzero(~above[:-1] & above[1:])
    up = [i for i in up if np.all(above[i + 1:i + 1 + hold])]
    if not up:
        other = "falling" if edge == "rising" else "rising"
        raise InputError(f"the trigger channel never {'rises' if edge == 'rising' else 'falls'} "
                         f"through its level ({abs(mid):g}) to stay there "
                         f"{TRIGGER_HOLD_S * 1e3:g} ms (for its {other} edge give "
                         f"--trigger-edge {other})", file=file, key=key)
    i = _first_contact(time, above, int(up[0]))
    if np.mean(above[:i + 1]) > 0.5:
        warnings.warn(TriggerWarning(
            f"{file or 'the trigger'}: {key} is above its level most of the time before it "
            "rises: an active-low trigger read at its release? (--trigger-edge falling reads "
            "its press)"), stacklevel=2)
    when, spread = _crossing(time, x, mid, 0.25 * (hi - lo), i)
    sampling = _rise_time(time, x, *_rise(x, lo, hi, i), hi - lo)
    return TriggerCrossing(when, float(np.hypot(spread, sampling / np.sqrt(12.0))),
                           float(spread), float(sampling))


def _crossing(time, x, level, width, i) -> tuple:
    """Time [s] ``x`` crosses ``level`` after sample ``i`` and its noise error [s]: of the
    least-squares line through 3+ samples within ``width`` of it, else between two samples."""
    noise = np.sqrt(np.mean(np.diff(x, 2) ** 2) / 6.0) if x.size > 2 else 0.0
    band = _band(x, level, width, i)
    if band.size >= 3:
        return _fitted_crossing(time[band], x[band], level, noise)
    slope = (x[i + 1] - x[i]) / (time[i + 1] - time[i])
    return float(time[i] + (level - x[i]) / slope), noise / slope


def _band(x, level, width, i) -> np.ndarray:
    """Indices of consecutive samples within ``width`` of ``level`` about sample ``i + 1``."""
    inside = np.abs(x - level) <= width
    lo = hi = i + 1 if inside[i + 1] else i
    if not inside[lo]:
        return np.empty(0, int)
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    while hi < x.size - 1 and inside[hi + 1]:
        hi += 1
    return np.arange(lo, hi + 1)


def _fitted_crossing(t, x, level, noise) -> tuple:
    """Crossing time [s] of ``level`` by the least-squares line, and its error [s] from ``noise``."""
    a, b = np.polyfit(t - t[0], x, 1)
    when = (level - b) / a
    spread = noise / a * np.sqrt(1.0 / t.size + (when - np.mean(t - t[0])) ** 2
                                 / np.sum((t - np.mean(t)) ** 2))
    return float(t[0] + when), float(spread)


def trigger_levels(x, file=None, key="--trigger") -> tuple:
    """Low and high level of the trigger channel ``x`` (module docstring); ``file``, ``key``
    name the error where it does not step."""
    p1, p99 = np.percentile(x, [1.0, 99.0])
    split = 0.5 * (p1 + p99)
    below, over = x[x < split], x[x >= split]
    if not p99 - p1 > 1e-12 * max(abs(p1), abs(p99), 1.0) or not below.size:
        pulse = np.ptp(x) > 1e-12 * max(np.max(np.abs(x)), 1.0)
        raise InputError("the trigger channel is constant" + (
            " but for fewer than 1 % of its samples (a pulse or a spike, not a step)"
            if pulse else " (no step)"), file=file, key=key)
    lo, hi = float(np.median(below)), float(np.median(over))
    noise = np.sqrt(np.mean(np.diff(x, 2) ** 2) / 6.0) if x.size > 2 else 0.0
    if hi - lo < TRIGGER_STEP_NOISE * noise:
        raise InputError(f"the trigger channel does not step (its step {hi - lo:.3g} is "
                         f"less than {TRIGGER_STEP_NOISE:g} times its noise {noise:.3g})", file=file, key=key)
    return lo, hi


def _first_contact(time, above, i) -> int:
    """Sample before the first rising crossing of the bounce ending after sample ``i``."""
    changes = np.flatnonzero(above[:-1] != above[1:])
    k = int(np.searchsorted(changes, i))
    while k > 0 and time[changes[k]] - time[changes[k - 1]] < TRIGGER_BOUNCE_S:
        k -= 1
    first = changes[k]
    return int(first if above[first + 1] else i)


def _rise(x, lo, hi, i) -> tuple:
    """Last sample at most 10 % of the step up to ``i``, first at least 90 % after it."""
    before = np.flatnonzero(x[:i + 1] <= lo + 0.1 * (hi - lo))
    after = np.flatnonzero(x[i + 1:] >= lo + 0.9 * (hi - lo))
    return (int(before[-1]) if before.size else 0, int(i + 1 + after[0]) if after.size else x.size - 1)


def _rise_time(time, x, start, end, step) -> float:
    """Time [s] the step may lie anywhere in (module docstring)."""
    span = float(time[end] - time[start])
    changes = np.flatnonzero(np.diff(x) != 0)
    update = float(np.median(np.diff(time[changes]))) if changes.size > 1 else 0.0
    if 10 <= changes.size < HELD_SHARE * (x.size - 1) and update > 1.5 * (time[1] - time[0]):
        return max(update, span / (end - start))
    if end - start <= 2:
        return span / (end - start)
    straight = end - start >= 3 and np.max(np.abs(np.diff(x[start:end + 1], 2))) <= 1e-6 * step
    return step / (x[end] - x[start]) * span if straight else 0.0      # the whole step's
