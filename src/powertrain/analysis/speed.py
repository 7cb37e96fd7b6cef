r"""Shaft speed and crank angle of a run-up, from an rpm channel or a tacho pulse train.

**rpm channel**: smoothed by a cubic Savitzky–Golay filter over ``smooth_s`` seconds (a
parabolic ramp passes unchanged); the angle is its trapezoidal integral
:math:`\theta(t) = \int_0^t 2\pi n/60\,d\tau`.

**Tacho** (``N`` pulses per revolution): rising edges by a Schmitt trigger between the 2nd
and 98th percentile levels, missing teeth counted and spikes dropped (:func:`count_teeth`);
the edge angles :math:`2\pi\,\mathrm{count}/N` are fitted by a least-squares cubic spline
with knots ``smooth_s`` apart. The **reference pulse** (the order phases' origin,
:mod:`powertrain.analysis.phase`) is every pulse of a once-per-revolution tacho, or the first
after a missing-tooth gap; an rpm channel has none.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_lsq_spline
from scipy.ndimage import median_filter
from scipy.signal import savgol_filter

from powertrain.errors import InputError

#: Schmitt-trigger thresholds as fractions of the tacho swing.
TRIGGER_HIGH = 0.6
TRIGGER_LOW = 0.4
#: Interval ratio tolerance for counting missing teeth; ratio below which it is a spike.
MISSING_TOOTH_TOLERANCE = 0.3
SPIKE_RATIO = 0.3
#: Fewest tacho edges a speed profile is fitted to; most pulses per revolution accepted.
MIN_TACHO_EDGES = 8
MAX_PULSES_PER_REV = 100_000


@dataclass
class SpeedProfile:
    """Speed and angle at every sample of a recording.

    Attributes
    ----------
    time, rpm, angle : ndarray (n,)
        Times [s], smoothed speed [rpm], crank angle from the first sample or edge [rad].
    valid : tuple of int
        First and last sample index where speed and angle are measured, not extrapolated.
    source : str
        ``rpm channel`` or ``tacho (N pulses/rev)``.
    notes : list of str
    reference : float or None
        Angle [rad] of a once-per-revolution reference pulse (modulo 2π), or None.
    """

    time: np.ndarray
    rpm: np.ndarray
    angle: np.ndarray
    valid: tuple
    source: str
    notes: list = field(default_factory=list)
    reference: float | None = None


def _savgol_window(time, smooth_s):
    dt = (time[-1] - time[0]) / (time.size - 1)
    n = int(round(smooth_s / dt)) | 1
    return max(5, min(n, time.size if time.size % 2 else time.size - 1))


def speed_from_rpm(time, rpm, *, smooth_s=0.1, file=None, key="rpm") -> SpeedProfile:
    """Speed profile from an rpm channel (module docstring).

    Parameters
    ----------
    time : ndarray (n,)
        Uniform sample times [s].
    rpm : ndarray (n,)
        Measured speed [rpm].
    smooth_s : float
        Smoothing window [s].
    file, key : str, optional
        Named in error messages.
    """
    time, rpm = np.asarray(time, float), np.asarray(rpm, float)
    window = _savgol_window(time, smooth_s)
    # long windows: filter means of k samples, interpolate back, extrapolate the end slopes
    k = max(1, window // 64)
    n_blocks = rpm.size // k
    if k > 1 and n_blocks >= 16:
        means = rpm[:n_blocks * k].reshape(n_blocks, k).mean(axis=1)
        t_means = time[:n_blocks * k].reshape(n_blocks, k).mean(axis=1)
        sm = savgol_filter(means, _savgol_window(t_means, smooth_s), 3, mode="interp")
        smooth = np.interp(time, t_means, sm)
        lo, hi = time < t_means[0], time > t_means[-1]
        smooth[lo] = sm[0] + (sm[1] - sm[0]) / (t_means[1] - t_means[0]) * (time[lo] - t_means[0])
        smooth[hi] = sm[-1] + (sm[-1] - sm[-2]) / (t_means[-1] - t_means[-2]) * (time[hi] - t_means[-1])
    else:
        smooth = savgol_filter(rpm, window, 3, mode="interp") if window > 4 else rpm
    if np.any(smooth <= 0):
        raise InputError("speed must stay > 0 (a stopped or reversing shaft cannot be "
                         "order tracked)", file=file, key=key)
    omega = smooth * (2.0 * np.pi / 60.0)
    angle = np.concatenate([[0.0], np.cumsum(0.5 * (omega[1:] + omega[:-1]) * np.diff(time))])
    return SpeedProfile(time, smooth, angle, (0, time.size - 1), "rpm channel",
                        [f"rpm smoothed over {window} samples (Savitzky-Golay, cubic)"])


#: Longest window of :func:`mean_speed` [s] (towards standstill).
MEAN_SPEED_WINDOW_S = 0.2


def mean_speed(time, rpm, interval) -> np.ndarray:
    r"""Crank speed ``rpm`` at every sample ``time`` [s] averaged over the time the crank
    turns ``interval`` [rad] (the firing interval), centred, kept inside the record, at most
    :data:`MEAN_SPEED_WINDOW_S`: :math:`\bar n = (\Theta(t + T/2) - \Theta(t - T/2)) / T`,
    :math:`\Theta` the speed's integral, :math:`T = \Phi/|\omega|` from the once-averaged
    speed."""
    t, n = np.asarray(time, float), np.asarray(rpm, float)
    angle = np.r_[0.0, np.cumsum(0.5 * (n[1:] + n[:-1]) * np.diff(t))]
    out = n
    for _ in range(2):
        window = np.minimum(interval / np.maximum(np.abs(out) * np.pi / 30.0, 1e-12), MEAN_SPEED_WINDOW_S)
        window = np.minimum(window, t[-1] - t[0])
        lo = np.clip(t - 0.5 * window, t[0], t[-1] - window)
        out = (np.interp(lo + window, t, angle) - np.interp(lo, t, angle)) / window
    return out


def tacho_edges(time, tacho, *, file=None, key="tacho", what="tacho"):
    """Rising-edge times [s] of the pulse train ``tacho`` at ``time`` (Schmitt trigger,
    interpolated); ``file``, ``key``, ``what`` name it in error messages."""
    x = np.asarray(tacho, float)
    lo, hi = np.percentile(x, [2.0, 98.0])
    swing = hi - lo
    if not swing > 1e-12 * max(abs(hi), abs(lo), 1.0):
        raise InputError(f"{what} has no edges (constant signal)", file=file, key=key)
    up, down = lo + TRIGGER_HIGH * swing, lo + TRIGGER_LOW * swing
    # 1 above `up`, 0 below `down`, else the last state (forward fill)
    marker = np.where(x > up, 1, np.where(x < down, 0, -1))
    idx = np.where(marker >= 0, np.arange(x.size), 0)
    np.maximum.accumulate(idx, out=idx)
    state = marker[idx]
    state[marker[idx] < 0] = 0
    rise = np.flatnonzero((state[1:] == 1) & (state[:-1] == 0)) + 1
    if rise.size < MIN_TACHO_EDGES:
        raise InputError(f"{what} has too few edges ({rise.size} rising edges found, at least "
                         f"{MIN_TACHO_EDGES} needed)", file=file, key=key)
    i1 = rise                    # the first sample above `up`: interpolate the crossing
    i0 = np.maximum(rise - 1, 0)
    x0, x1 = x[i0], x[i1]
    frac = np.clip((up - x0) / np.where(x1 > x0, x1 - x0, 1.0), 0.0, 1.0)
    return time[i0] + frac * (time[i1] - time[i0])


def drop_spikes(edge_times) -> tuple:
    """``edge_times`` [s] without spikes (an interval under :data:`SPIKE_RATIO` of the running
    median: the edge whose removal leaves one nearer the median), and notes."""
    t = np.asarray(edge_times, float)
    notes = []
    for _ in range(3):                       # drop spikes, then re-evaluate the median
        d = np.diff(t)
        med = median_filter(d, size=min(9, d.size) | 1, mode="nearest")
        short = np.flatnonzero(d < SPIKE_RATIO * med)
        if not short.size:
            break
        before = np.where(short > 0, d[np.maximum(short - 1, 0)] + d[short], np.inf)
        after = np.where(short + 1 < d.size, d[short] + d[np.minimum(short + 1, d.size - 1)], np.inf)
        first = np.abs(before - med[short]) < np.abs(after - med[short])
        t = np.delete(t, np.unique(np.where(first, short, short + 1)))
        notes.append(f"{short.size} tacho spike(s) dropped")
    return t, notes


def count_teeth(edge_times, *, file=None, key="tacho"):
    """Pulse count at each of ``edge_times`` [s], missing teeth counted, spikes dropped;
    ``file``, ``key`` name errors.

    Returns
    -------
    times, counts : ndarray
        Edge times [s] kept and the cumulative pulse count at each (0 at the first).
    notes : list of str
    """
    t, notes = drop_spikes(edge_times)
    d = np.diff(t)
    med = median_filter(d, size=min(9, d.size) | 1, mode="nearest")
    ratio = d / med
    k = np.maximum(np.round(ratio), 1.0)
    bad = np.abs(ratio - k) > MISSING_TOOTH_TOLERANCE * k
    if np.mean(bad) > 0.05:
        raise InputError("tacho edges too irregular to count (more than 5 % of the intervals "
                         "are not a whole number of pulses)", file=file, key=key)
    missing = int(np.sum(k[k > 1] - 1))
    if missing:
        notes.append(f"{missing} missing tacho pulse(s) counted")
    counts = np.concatenate([[0.0], np.cumsum(k)])
    return t, counts, notes


def reference_count(counts, pulses_per_rev):
    """Count (of :func:`count_teeth`'s ``counts``) of the reference pulse, or None: 0 for one
    pulse per revolution (``pulses_per_rev``), else the first after a gap if every gap is on
    the same tooth."""
    if pulses_per_rev == 1:
        return 0.0
    after_gap = counts[1:][np.diff(counts) > 1]
    if after_gap.size == 0:
        return None
    teeth = np.mod(after_gap, pulses_per_rev)
    return float(teeth[0]) if np.all(teeth == teeth[0]) else None


def checked_pulses_per_rev(pulses_per_rev) -> int:
    """``pulses_per_rev`` as an int 1..:data:`MAX_PULSES_PER_REV`, else an InputError."""
    if not (isinstance(pulses_per_rev, (int, float, np.integer, np.floating))
            and not isinstance(pulses_per_rev, bool)
            and 1 <= pulses_per_rev <= MAX_PULSES_PER_REV
            and float(pulses_per_rev).is_integer()):
        raise InputError(f"must be a whole number 1..{MAX_PULSES_PER_REV}, got "
                         f"{pulses_per_rev!r}", key="--pulses-per-rev")
    return int(pulses_per_rev)


def speed_from_tacho(time, tacho, pulses_per_rev, *, smooth_s=0.1, file=None, key="tacho") -> SpeedProfile:
    """Speed profile from the pulse train ``tacho`` at ``time`` [s] of ``pulses_per_rev``
    pulses per revolution, knots ``smooth_s`` [s] apart (module docstring)."""
    time = np.asarray(time, float)
    checked_pulses_per_rev(pulses_per_rev)
    edges = tacho_edges(time, tacho, file=file, key=key)
    t_e, counts, notes = count_teeth(edges, file=file, key=key)
    if t_e.size < MIN_TACHO_EDGES:
        raise InputError(f"{t_e.size} usable tacho edges; at least {MIN_TACHO_EDGES} needed "
                         "for a speed profile", file=file, key=key)
    theta_e = counts * (2.0 * np.pi / pulses_per_rev)
    n_int = int(max(0, min((t_e[-1] - t_e[0]) / smooth_s, (t_e.size - 4) / 4)))
    inner = np.linspace(t_e[0], t_e[-1], n_int + 2)[1:-1]
    knots = np.concatenate([[t_e[0]] * 4, inner, [t_e[-1]] * 4])
    spline = make_lsq_spline(t_e, theta_e, knots, k=3)
    valid = (int(np.searchsorted(time, t_e[0])), int(np.searchsorted(time, t_e[-1]) - 1))
    tc = np.clip(time, t_e[0], t_e[-1])
    angle, omega = spline(tc), spline.derivative()(tc)
    angle = angle + omega * (time - tc)          # linear outside the edges (`valid`)
    if np.any(omega[valid[0]:valid[1] + 1] <= 0):
        raise InputError("speed from the tacho is not > 0 throughout", file=file, key=key)
    rpm = omega * (60.0 / (2.0 * np.pi))
    notes = [f"{t_e.size} tacho edges, {pulses_per_rev:g} pulses/rev; angle fitted by a "
             f"cubic spline with {n_int} interior knots"] + notes
    ref = reference_count(counts, pulses_per_rev)
    return SpeedProfile(time, rpm, angle, valid, f"tacho ({pulses_per_rev:g} pulses/rev)",
                        notes, None if ref is None else ref * 2.0 * np.pi / pulses_per_rev)
