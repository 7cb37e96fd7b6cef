"""A recording of a manoeuvre against its simulation: read, lined up (:func:`align`, for
``--compare`` and ``--speed-from``), its crank speed driving the manoeuvre, its channels
compared.

Lining up: the manoeuvre's ``trigger_time`` is the trigger channel's crossing of its mid
level; without one, the shift whose recorded crank speed best matches the manoeuvre's
(:func:`powertrain.analysis.alignment.align_speed`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.alignment import (
    MIN_COVERAGE,
    TRIGGER,
    align_speed,
    align_tacho,
    coverage,
    tacho_counts,
    tacho_rpm,
    trigger_shift,
    unheld_speed,
)
from powertrain.analysis.speed import checked_pulses_per_rev, mean_speed, tacho_edges
from powertrain.analysis.trigger import TRIGGER_EDGES, TriggerCrossing, trigger_crossing
from powertrain.errors import InputError, PowertrainWarning
from powertrain.iotools.raw import IGNORED_NOTE, read_raw
from powertrain.models.manoeuvre import MAX_RPM, Manoeuvre
from powertrain.results.transient import TransientComparison

#: Most rows of a speed table taken from a recording (block means of its samples).
SPEED_ROWS = 2000
#: Longest firing interval [s] whose mean speed (--speed-average) passes without a warning.
AVERAGE_WINDOW_S = 0.1
#: Option of a recording's channel map, named in error messages.
MAP_OPTION = "--channel-map"
_RPM = np.pi / 30.0


@dataclass(frozen=True)
class Recorded:
    """A recording of a manoeuvre, read and checked (:func:`read_recording`).

    Attributes
    ----------
    time : ndarray (n,)
        From the first sample [s].
    rpm : ndarray (n,) or None
        Crank speed [rpm] per sample (rpm channel, else tacho).
    speed_source : str
        ``rpm channel``, ``tacho`` or ``""``.
    crossing : TriggerCrossing or None
        The trigger's step (None without ``--trigger``).
    ignored : list of str
        Channels the channel map leaves out.
    edges, counts : ndarray or None
        The tacho's rising edges [s] and pulses counted at each (None with an rpm channel).
    unused_trigger : bool
        The file has a channel ``trigger`` that ``--trigger`` does not name.
    """

    path: str
    time: np.ndarray
    rpm: np.ndarray | None
    speed_source: str
    crossing: TriggerCrossing | None
    trigger_name: str | None
    channels: list
    ignored: list = field(default_factory=list)
    edges: np.ndarray | None = None
    counts: np.ndarray | None = None
    pulses_per_rev: int = 1
    unused_trigger: bool = False

    @property
    def trigger(self) -> float | None:
        """Time of the trigger [s] from the first sample (None without ``--trigger``)."""
        return None if self.crossing is None else self.crossing.time


def read_recording(path, *, channel_map=None, trigger=None, pulses_per_rev=1,
                   trigger_edge="rising") -> Recorded:
    """Read and check a recording of a manoeuvre (any format of
    :func:`~powertrain.iotools.raw.read_raw`), its ``trigger`` channel marking
    ``trigger_edge`` (``rising`` or ``falling``), its tacho's ``pulses_per_rev``."""
    if trigger is not None and (not isinstance(trigger, str) or not trigger.strip()):
        raise InputError("expected the name of a channel of the recording", key="--trigger")
    pulses_per_rev = checked_pulses_per_rev(pulses_per_rev)
    if trigger_edge not in TRIGGER_EDGES:
        raise InputError(f"expected one of {', '.join(TRIGGER_EDGES)}, got {trigger_edge!r}",
                         key="--trigger-edge")
    rec = read_raw(path, channel_map, trigger=trigger, map_option=MAP_OPTION)
    t = rec.time - rec.time[0]
    crossing = None if trigger is None else trigger_crossing(
        t, rec.trigger, edge=trigger_edge, file=str(path), key=trigger)
    ignored = [n.strip() for c in rec.comments if c.startswith(IGNORED_NOTE)
               for n in c[len(IGNORED_NOTE):].split(",")]
    if pulses_per_rev != 1 and rec.rpm is not None:
        warnings.warn(RecordedSpeedWarning(
            f"{path}: the speed is the rpm channel's; --pulses-per-rev is not used"), stacklevel=2)
    edges, counts = (tacho_counts(tacho_edges(t, rec.tacho, file=str(path), key="tacho"),
                                  pulses_per_rev, file=str(path), key="tacho")
                     if rec.rpm is None and rec.tacho is not None else (None, None))
    rpm = (np.asarray(rec.rpm, float) if rec.rpm is not None
           else None if edges is None else tacho_rpm(t, edges, counts, pulses_per_rev))
    source = "rpm channel" if rec.rpm is not None else ("tacho" if rec.tacho is not None else "")
    return Recorded(str(path), t, rpm, source, crossing, trigger,
                    list(rec.channels), ignored, edges, counts, pulses_per_rev,
                    trigger is None and rec.trigger is not None)


def recording_or_file(recording, **options) -> Recorded:
    """A :class:`Recorded` as it is, or read by :func:`read_recording` with ``options``."""
    if isinstance(recording, Recorded):
        return recording
    return read_recording(recording, **options)


def align(rec: Recorded, t_event, rpm_event, *, partial=True, trigger_at=0.0) -> tuple:
    """``(shift, how, standard error)``: the recording's time [s] of the event's time 0, by
    the trigger (at event time ``trigger_at`` [s]) or by the speed ``rpm_event`` [rpm] at
    ``t_event`` [s]; ``partial``: the recording may cover part of the event."""
    if rec.crossing is not None:
        shift = trigger_shift(rec.crossing, trigger_at, rpm_event, file=rec.path, key=rec.trigger_name)
        return shift, f"trigger {rec.trigger_name!r}", rec.crossing.error
    if rec.rpm is None:
        raise InputError("no rpm or tacho channel to line the recording up on; give "
                         "--trigger CHANNEL", file=rec.path, key="rpm")
    return _align_on_speed(rec, t_event, rpm_event, partial)


def _align_on_speed(rec: Recorded, t_event, rpm_event, partial) -> tuple:
    """:func:`align` on the tacho's pulses, else on the rpm channel."""
    trigger = TRIGGER + (" (the recording has one named 'trigger')" if rec.unused_trigger else "")
    if rec.edges is not None:
        shift, error = align_tacho(t_event, rpm_event, (rec.time[0], rec.time[-1]),
                                   rec.edges, counts=rec.counts,
                                   pulses_per_rev=rec.pulses_per_rev, file=rec.path,
                                   key="tacho", partial=partial, trigger=trigger)
        return shift, "crank angle of the tacho's pulses", error
    shift, error = align_speed(t_event, rpm_event, rec.time, rec.rpm, file=rec.path,
                               key="rpm", partial=partial, trigger=trigger)
    return shift, "crank speed", error


def speed_from_recording(manoeuvre: Manoeuvre, recording, *, firing_interval=None, **options) -> tuple:
    """``(manoeuvre, note)``: ``manoeuvre`` with its speed table replaced by the recording's
    crank speed, lined up by :func:`align`, as recorded or (``firing_interval`` [rad]) its
    mean over each firing interval (:func:`~powertrain.analysis.speed.mean_speed`), on at
    most :data:`SPEED_ROWS` rows; negative speeds cut to 0 unless reversal is allowed.
    ``options``: :func:`read_recording`'s. The recording must cover the manoeuvre."""
    rec = recording_or_file(recording, **options)
    if rec.rpm is None:
        raise InputError("no rpm or tacho channel to take the speed from", file=rec.path, key="rpm")
    duration = manoeuvre.duration
    tol = rec.time[1] - rec.time[0]
    if rec.time[-1] < duration - tol:
        raise InputError(f"the recording is {rec.time[-1]:.6g} s long, the manoeuvre "
                         f"{duration:.6g} s; --speed-from needs all of it", file=rec.path, key="time")
    shift, how, error = align(rec, manoeuvre.time, manoeuvre.speed / _RPM, partial=False,
                              trigger_at=manoeuvre.trigger_time)
    first, last = coverage(0.0, duration, rec.time[0], rec.time[-1], shift)
    if first > tol or last < duration - tol:
        raise InputError(f"after alignment ({how}: the manoeuvre starts at {shift:.4f} s of "
                         f"the recording) the recording covers {first:.6g} to {last:.6g} s of "
                         f"the manoeuvre's 0 to {duration:.6g} s; --speed-from needs all of it",
                         file=rec.path, key="time")
    rpm = unheld_speed(rec.time, rec.rpm)[1]
    if firing_interval is not None:
        rpm = mean_speed(rec.time, rpm, firing_interval)
    tt, rr = _speed_rows(rec.time - shift, rpm, duration)
    _warn_speed(manoeuvre, rec, rr, firing_interval)
    if not manoeuvre.reversal:
        rr = np.maximum(rr, 0.0)
    if not np.all(np.isfinite(rr)) or np.max(np.abs(rr)) > MAX_RPM:
        raise InputError(f"speed not finite or above {MAX_RPM:g} rpm", file=rec.path, key="rpm")
    mean = ("" if firing_interval is None
            else f", its mean over {np.degrees(firing_interval):.0f} deg of crank")
    note = (f"crank speed from {rec.path} ({rec.speed_source}{mean}): the manoeuvre starts "
            f"at {shift:.4f} s of the recording (aligned on the {how}, standard error {error * 1e3:.2g} ms)")
    return manoeuvre.with_speed(tt, rr * _RPM), note


class RecordedSpeedWarning(PowertrainWarning):
    """A recorded speed that cannot be read as asked (unsigned, averaged too long, or an
    rpm channel's given pulses per revolution)."""


def _warn_speed(manoeuvre, rec, rpm, firing_interval) -> None:
    """Warn of an unsigned speed where reversal is allowed, or one averaged too slow."""
    if manoeuvre.reversal and np.min(rec.rpm) >= 0:
        warnings.warn(RecordedSpeedWarning(
            f"{rec.path}: the manoeuvre lets the crank turn back, but the recorded speed "
            f"({rec.speed_source}) is never negative: a crank turning back reads as turning "
            "forward"), stacklevel=3)
    slow = firing_interval / AVERAGE_WINDOW_S * 30.0 / np.pi if firing_interval else 0.0
    if np.min(np.abs(rpm)) < slow:
        warnings.warn(RecordedSpeedWarning(
            f"{rec.path}: below {slow:.0f} rpm a firing interval lasts more than "
            f"{AVERAGE_WINDOW_S * 1e3:g} ms, and its mean (--speed-average) smooths the "
            "speed's own changes, a start's flare among them; it suits a running engine"), stacklevel=3)


def _speed_rows(t, rpm, duration) -> tuple:
    """Times [s] 0..``duration`` and speeds [rpm]: block means on at most :data:`SPEED_ROWS`
    rows, the ends interpolated."""
    inside = np.flatnonzero((t > 0.0) & (t < duration))
    k = max(1, -(-inside.size // SPEED_ROWS))
    rows = inside.size // k
    sel = inside[:rows * k]
    tt = np.r_[0.0, t[sel].reshape(rows, k).mean(axis=1), duration]
    rr = np.r_[np.interp(0.0, t, rpm), rpm[sel].reshape(rows, k).mean(axis=1), np.interp(duration, t, rpm)]
    return tt, rr


def compared_channels(rec: Recorded, labels) -> tuple:
    """The recording's channels matching the simulation's ``labels`` and why others do not:
    ``([(label, RawChannel)], {name: reason})``; an error when none matches."""
    labels = list(labels)
    mounts = sorted({c.rpartition(".")[0] for c in labels if "/" not in c})
    pairs, skipped = [], {n: "not in the channel map" for n in rec.ignored}
    for ch in rec.channels:
        label = f"{ch.channel.node}.{ch.direction}"       # left.x, left/passive.x, seat.z
        if ch.quantity != "acceleration":
            skipped[ch.name] = f"{ch.quantity} (only accelerations are compared)"
        elif label in labels:
            pairs.append((label, ch))
        elif ch.side == "passive" and f"{ch.mount}.{ch.direction}" in labels:
            skipped[ch.name] = "body side: the model has none (its mounts stand on rigid ground)"
        else:
            skipped[ch.name] = (f"no mount or body point {ch.mount!r} in the model (it has "
                                f"{', '.join(mounts)}; rename with {MAP_OPTION})")
    if not pairs:
        why = "; ".join(f"{n}: {r}" for n, r in skipped.items())
        raise InputError(f"no acceleration channel of the simulation in the recording "
                         f"({why})", file=rec.path, key="channels")
    return pairs, skipped


def compare_transient(result, raw, *, trigger=None, channel_map=None, pulses_per_rev=1,
                      trigger_edge="rising") -> TransientComparison:
    """A simulated manoeuvre against a recorded one.

    Parameters
    ----------
    result : TransientResult
        The simulation.
    raw : str, Path or Recorded
        The recording (any format of :func:`~powertrain.iotools.raw.read_raw`).
    trigger : str, optional
        Trigger channel (default: aligned on the crank speed, :func:`align`).
    channel_map : ChannelMap, str or Path, optional
        The recording's channel names -> mount, side, direction, quantity.
    pulses_per_rev : int
        The recording's tacho pulses per revolution.
    trigger_edge : str
        The edge the trigger marks: ``rising`` or ``falling``.

    Returns
    -------
    TransientComparison
        Every recorded acceleration channel the simulation has, over the covered part.
    """
    rec = recording_or_file(raw, channel_map=channel_map, trigger=trigger,
                            pulses_per_rev=pulses_per_rev, trigger_edge=trigger_edge)
    pairs, skipped = compared_channels(rec, result.channels)
    shift, how, error = align(rec, result.time, result.rpm, trigger_at=result.trigger_time)
    t0, t1 = float(result.time[0]), float(result.time[-1])
    first, last = _covered(rec, t0, t1, shift, how)
    sel = (result.time >= first) & (result.time <= last)
    t = result.time[sel]
    measured = np.array([np.interp(t + shift, rec.time, ch.values) for _, ch in pairs]).T
    simulated = result.acceleration[np.ix_(sel, [result.channel(lb) for lb, _ in pairs])]
    return TransientComparison(result.name, rec.path, float(shift), t,
                               [lb for lb, _ in pairs], measured, simulated, aligned_on=how,
                               event=(t0, t1), not_compared=skipped, shift_error=float(error))


def _covered(rec: Recorded, t0, t1, shift, how) -> tuple:
    """The event times in ``t0..t1`` [s] the recording covers (at least :data:`MIN_COVERAGE`)."""
    first, last = coverage(t0, t1, rec.time[0], rec.time[-1], shift)
    if not last - first >= MIN_COVERAGE * (t1 - t0):
        raise InputError(f"after alignment ({how}: the simulation starts at {shift:.4f} s of "
                         f"the recording) the recording covers {max(last - first, 0.0):.4g} "
                         f"s of the {t1 - t0:.4g} s event, less than {MIN_COVERAGE:.0%}",
                         file=rec.path, key="time")
    return first, last


def check_recordings(manoeuvre: Manoeuvre, labels, *, firing_interval=None, compare=None, speed=None) -> None:
    """Check the recordings of ``--compare`` and ``--speed-from`` before the simulation:
    channels against ``labels``, alignment and coverage (``firing_interval`` [rad] as
    :func:`speed_from_recording`'s)."""
    with warnings.catch_warnings():          # the run and the comparison warn once
        warnings.simplefilter("ignore", PowertrainWarning)
        _check(manoeuvre, labels, firing_interval, compare, speed)


def _check(manoeuvre, labels, firing_interval, compare, speed) -> None:
    """:func:`check_recordings`' checks."""
    if speed is not None:
        manoeuvre, _ = speed_from_recording(manoeuvre, speed, firing_interval=firing_interval)
    if compare is not None:
        compared_channels(compare, labels)
        shift, how, _ = align(compare, manoeuvre.time, manoeuvre.speed / _RPM,
                              trigger_at=manoeuvre.trigger_time)
        _covered(compare, 0.0, manoeuvre.duration, shift, how)
