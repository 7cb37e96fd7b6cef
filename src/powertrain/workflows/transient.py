"""A transient manoeuvre on an engine: file -> model -> time integration -> result.

:func:`transient` is the public entry (``powertrain transient`` calls it): the manoeuvre
file read and checked before any work (:mod:`powertrain.iotools.manoeuvre_file`), the
engine's model integrated over it (:func:`powertrain.solvers.transient.simulate_transient`),
then the per-channel peaks and, at a seat point of a modal body, the ISO 2631-1 weighted RMS
and vibration dose value (:mod:`powertrain.analysis.comfort`).
"""

from __future__ import annotations

import os
import time

import numpy as np

from powertrain.analysis.comfort import (
    AXIS_WEIGHTING,
    vibration_dose_value,
    weighted,
    weighted_rms,
)
from powertrain.analysis.speed import tacho_edges
from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.iotools.manoeuvre_file import read_manoeuvre
from powertrain.iotools.raw import read_raw
from powertrain.models.manoeuvre import MAX_RPM, Manoeuvre
from powertrain.parallel import single_blas_thread
from powertrain.results.transient import TransientComparison, TransientResult
from powertrain.solvers.transient import simulate_transient
from powertrain.workflows.arguments import number

#: Default crank angle per integration step at the top speed [deg].
ANGLE_STEP_DEG = 1.0
#: Most rows of a speed table taken from a recording (block means of its samples).
SPEED_ROWS = 2000
_RPM = np.pi / 30.0


def manoeuvre_or_file(manoeuvre) -> Manoeuvre:
    """A :class:`Manoeuvre` as it is, or read from its file."""
    if isinstance(manoeuvre, (str, os.PathLike)):
        return read_manoeuvre(manoeuvre)
    if not isinstance(manoeuvre, Manoeuvre):
        raise InputError(f"expected a Manoeuvre or a manoeuvre file, got "
                         f"{type(manoeuvre).__name__}", key="MANOEUVRE")
    return manoeuvre


def recorded_rpm(rec, path) -> np.ndarray:
    """Crank speed [rpm] at every sample of the recording ``rec``: its rpm channel, else
    the speed between successive rising edges of its once-per-revolution tacho."""
    if rec.rpm is not None:
        return np.asarray(rec.rpm, float)
    if rec.tacho is not None:
        t = rec.time - rec.time[0]
        edges = tacho_edges(t, rec.tacho, file=str(path), key="tacho")
        return np.interp(t, 0.5 * (edges[1:] + edges[:-1]), 60.0 / np.diff(edges))
    raise InputError("no rpm or tacho channel to take the speed from", file=str(path),
                     key="rpm")


def speed_from_recording(manoeuvre, path) -> Manoeuvre:
    """``manoeuvre`` driven by the crank speed recorded in the raw file ``path``
    (:func:`~powertrain.iotools.raw.read_raw`): its rpm channel, else its once-per-revolution
    tacho (speed between successive rising edges), from the file's first sample, as block
    means on at most :data:`SPEED_ROWS` rows, cut where the load table ends; negative speeds
    are cut to 0 unless the manoeuvre allows a reversal."""
    rec = read_raw(path)
    t = rec.time - rec.time[0]
    rpm = recorded_rpm(rec, path)
    n = int(np.count_nonzero(t <= manoeuvre.load_time[-1]))
    k = max(1, -(-n // SPEED_ROWS))
    rows = n // k
    if rows < 2:
        raise InputError("fewer than two samples within the manoeuvre's load table",
                         file=str(path), key="time")
    tt = np.r_[0.0, t[:rows * k].reshape(rows, k).mean(axis=1)[1:], t[rows * k - 1]]
    rr = np.r_[rpm[0], rpm[:rows * k].reshape(rows, k).mean(axis=1)[1:], rpm[rows * k - 1]]
    if not manoeuvre.reversal:
        rr = np.maximum(rr, 0.0)
    if not np.all(np.isfinite(rr)) or np.max(np.abs(rr)) > MAX_RPM:
        raise InputError(f"speed not finite or above {MAX_RPM:g} rpm", file=str(path),
                         key="rpm")
    keep = np.r_[True, np.diff(tt) > 0]
    return manoeuvre.with_speed(tt[keep], rr[keep] * _RPM)


def transient(manoeuvre, engine=None, *, angle_step_deg=ANGLE_STEP_DEG, seat=None,
              system=None, speed_from=None) -> TransientResult:
    """Simulate a transient manoeuvre as the ``powertrain transient`` command does.

    Parameters
    ----------
    manoeuvre : Manoeuvre, str or Path
        The manoeuvre or its TOML file (:mod:`powertrain.iotools.manoeuvre_file`).
    engine : Engine, str or Path, optional
        Default: the shipped ``engines/default.toml``.
    angle_step_deg : float
        Crank angle per integration step at the top speed [deg] (0.01..10).
    seat : str, optional
        Body point whose ISO 2631-1 values are reported (default: a body point whose name
        starts with ``seat``, if the chassis has one).
    system : AssembledSystem, optional
        The assembled model (default ``engine.assemble()``; a what-if passes its variant's).
    speed_from : str or Path, optional
        Raw recording whose crank speed replaces the manoeuvre's speed table
        (:func:`speed_from_recording`).

    Returns
    -------
    TransientResult
        ``to_text()``, ``plot(ax=None)``, ``save(path)`` (``.csv``, ``.json``, ``.h5``,
        ``.png``).

    Raises
    ------
    InputError
        A bad manoeuvre file, engine or option, before any work.
    """
    step = number(angle_step_deg, "--angle-step", unit="deg", minimum=0.01, maximum=10.0)
    if seat is not None and not isinstance(seat, str):
        raise InputError(f"expected a body point name, got {type(seat).__name__}", key="--seat")
    m = manoeuvre_or_file(manoeuvre)
    if speed_from is not None:
        m = speed_from_recording(m, speed_from)
    engine = engine_or_default(engine)
    t0 = time.process_time()
    with single_blas_thread():
        run = simulate_transient(engine, m, system=system, angle_step_deg=step)
    labels = [f"{c}.{d}" for c, d in run.channels]
    load = run.load
    return TransientResult(
        m.name, m.file, engine.name, load.t, load.omega * 30.0 / np.pi,
        {"engine": load.engine_torque, "starter": load.starter_torque,
         "driveline": load.driveline_torque},
        run.body, labels, run.displacement, run.velocity, run.acceleration, run.force,
        run.networks, run.deflection, _seat(engine, run, labels, seat), run.method,
        time.process_time() - t0, [m.notes] if m.notes else [])


def _seat(engine, run, labels, seat):
    """ISO 2631-1 values at the seat point (None without one)."""
    points = list(getattr(engine.chassis, "points", ()) or ())
    if seat is None:
        seat = next((p for p in points if p.startswith("seat")), None)
        if seat is None:
            return None
    elif seat not in points:
        raise InputError(f"no body point {seat!r} (the chassis has: "
                         f"{', '.join(points) or 'none'})", key="--seat")
    fs = 1.0 / (run.load.t[1] - run.load.t[0])
    rms, vdv = {}, {}
    for a, w in AXIS_WEIGHTING.items():
        aw = weighted(run.acceleration[:, labels.index(f"{seat}.{a}")], fs, w)
        rms[a], vdv[a] = weighted_rms(aw, fs), vibration_dose_value(aw, fs)
    return {"point": seat, "rms": rms, "vdv": vdv, "weighting": dict(AXIS_WEIGHTING)}


def compare_transient(result, raw) -> TransientComparison:
    """A simulated manoeuvre against a recorded one (the raw file ``raw``, any format of
    :func:`~powertrain.iotools.raw.read_raw`): the recording aligned on its crank speed
    (rpm channel or tacho; the time shift that best matches the simulated speed,
    :func:`align`), then every recorded engine-side acceleration channel the simulation has
    compared over the simulated event (:class:`TransientComparison`)."""
    rec = read_raw(raw)
    t_rec = rec.time - rec.time[0]
    shift = align(result.time, result.rpm, t_rec, recorded_rpm(rec, raw))
    pairs = []
    for ch in rec.channels:
        label = f"{ch.mount}.{ch.direction}"
        if ch.side == "active" and ch.quantity == "acceleration" and label in result.channels:
            measured = np.interp(result.time + shift, t_rec, ch.values)
            pairs.append((label, measured, result.acceleration[:, result.channel(label)]))
    if not pairs:
        raise InputError("no engine-side acceleration channel of the simulation in the "
                         "recording", file=str(raw), key="channels")
    return TransientComparison(result.name, str(raw), float(shift), result.time,
                               [p[0] for p in pairs], np.array([p[1] for p in pairs]).T,
                               np.array([p[2] for p in pairs]).T)


def align(t_sim, rpm_sim, t_rec, rpm_rec) -> float:
    """Time shift [s] of the recording against the simulation: ``rpm_rec(t + shift)``
    closest to ``rpm_sim(t)`` in the least-squares sense over the simulated event (a grid
    of shifts over the recording's length, then refined to a sample of the recording)."""
    t = np.linspace(t_sim[0], t_sim[-1], 400)
    target = np.interp(t, t_sim, rpm_sim)

    def best(shifts):
        cost = [np.sum((np.interp(t + s, t_rec, rpm_rec) - target) ** 2) for s in shifts]
        return float(shifts[int(np.argmin(cost))])
    span = t_rec[-1] - (t_sim[-1] - t_sim[0])
    shifts = np.linspace(min(0.0, span), max(0.0, span), 801)
    shift = best(shifts)
    step = shifts[1] - shifts[0]
    return best(shift + np.linspace(-2.0, 2.0, 201) * step) if step > 0 else shift
