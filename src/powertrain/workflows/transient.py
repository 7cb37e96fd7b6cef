"""A transient manoeuvre on an engine (``powertrain transient``): the manoeuvre file checked,
the model integrated over it (:func:`powertrain.solvers.transient.simulate_transient`), the
peaks and, at a seat point, the ISO 2631-1 weighted RMS and VDV
(:mod:`powertrain.analysis.comfort`).
"""

from __future__ import annotations

import os
import time

import numpy as np

from powertrain.analysis.comfort import AXIS_WEIGHTING, vibration_dose_value, weighted, weighted_rms
from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.iotools.manoeuvre_file import read_manoeuvre
from powertrain.models.manoeuvre import Manoeuvre
from powertrain.parallel import single_blas_thread
from powertrain.results.transient import TransientResult
from powertrain.solvers.transient import simulate_transient
from powertrain.workflows.arguments import number
from powertrain.workflows.transient_recording import speed_from_recording

#: Default crank angle per integration step at the top speed [deg].
ANGLE_STEP_DEG = 1.0


def manoeuvre_or_file(manoeuvre) -> Manoeuvre:
    """A :class:`Manoeuvre` as it is, or read from its file."""
    if isinstance(manoeuvre, (str, os.PathLike)):
        return read_manoeuvre(manoeuvre)
    if not isinstance(manoeuvre, Manoeuvre):
        raise InputError(f"expected a Manoeuvre or a manoeuvre file, got "
                         f"{type(manoeuvre).__name__}", key="MANOEUVRE")
    return manoeuvre


def transient(manoeuvre, engine=None, *, angle_step_deg=ANGLE_STEP_DEG, seat=None,
              system=None, speed_from=None, trigger=None, channel_map=None,
              speed_average=False, pulses_per_rev=1, trigger_edge="rising") -> TransientResult:
    """Simulate a transient manoeuvre as the ``powertrain transient`` command does.

    Parameters
    ----------
    manoeuvre : Manoeuvre, str or Path
        The manoeuvre or its TOML file.
    engine : Engine, str or Path, optional
        Default: the shipped ``engines/default.toml``.
    angle_step_deg : float
        Crank angle per integration step at the top speed [deg] (0.01..10).
    seat : str, optional
        Body point of the ISO 2631-1 values (default: the first named ``seat...``).
    system : AssembledSystem, optional
        The assembled model (default ``engine.assemble()``).
    speed_from : str, Path or Recorded, optional
        Recording whose crank speed replaces the manoeuvre's
        (:func:`~powertrain.workflows.transient_recording.speed_from_recording`).
    trigger, channel_map, pulses_per_rev, trigger_edge : optional
        With ``speed_from``: how the recording is read and lined up
        (:func:`~powertrain.workflows.transient_recording.read_recording`).
    speed_average : bool
        With ``speed_from``: the recorded speed's mean over each firing interval (a speed
        resolved within the cycle), not the speed as recorded.

    Returns
    -------
    TransientResult
        ``to_text()``, ``plot(ax=None)``, ``save(path)``.
    """
    step = number(angle_step_deg, "--angle-step", unit="deg", minimum=0.01, maximum=10.0)
    if seat is not None and not isinstance(seat, str):
        raise InputError(f"expected a body point name, got {type(seat).__name__}", key="--seat")
    m = manoeuvre_or_file(manoeuvre)
    engine = engine_or_default(engine)
    seat = seat_point(engine, seat)
    if not isinstance(speed_average, (bool, np.bool_)):
        raise InputError(f"expected true or false, got {speed_average!r}", key="--speed-average")
    m, speed_note = _driven(m, speed_from, dict(
        trigger=trigger, channel_map=channel_map, pulses_per_rev=pulses_per_rev, trigger_edge=trigger_edge,
        firing_interval=engine.crank.firing_interval if speed_average else None), engine)
    t0 = time.process_time()
    with single_blas_thread():
        run = simulate_transient(engine, m, system=system, angle_step_deg=step)
    return _result(m, engine, run, seat, time.process_time() - t0, speed_note)


def _result(m, engine, run, seat, seconds, speed_note) -> TransientResult:
    """The result of ``run``, the manoeuvre ``m`` simulated on ``engine``."""
    labels = [f"{c}.{d}" for c, d in run.channels]
    load = run.load
    return TransientResult(
        m.name, m.file, engine.name, load.t, load.omega * 30.0 / np.pi,
        {"engine": load.engine_torque, "starter": load.starter_torque, "driveline": load.driveline_torque},
        run.body, labels, run.displacement, run.velocity, run.acceleration, run.force,
        run.networks, run.deflection, _seat(engine, run, labels, seat), run.method, seconds,
        [m.notes] if m.notes else [], speed_note, m.trigger_time)


def _driven(m, speed_from, options, engine) -> tuple:
    """``(manoeuvre, note)`` driven by a recorded speed (``options`` of
    :func:`~powertrain.workflows.transient_recording.speed_from_recording`)."""
    if speed_from is None:
        for key, given in (("--trigger", options["trigger"] is not None),
                           ("--channel-map", options["channel_map"] is not None),
                           ("--speed-average", options["firing_interval"] is not None),
                           ("--pulses-per-rev", options["pulses_per_rev"] != 1),
                           ("--trigger-edge", options["trigger_edge"] != "rising")):
            if given:
                raise InputError("goes with a recording (speed_from)", key=key)
        return m, ""
    driven, note = speed_from_recording(m, speed_from, **options)
    _check_recorded_top(driven, speed_from, engine)
    return driven, note


def _check_recorded_top(m, speed_from, engine) -> None:
    """Refuse a recorded speed above the engine's combustion model (the recording's error)."""
    top = engine.speed_range_rpm()[1]
    if speed_from is not None and m.max_speed * 30.0 / np.pi > top + 1e-6:
        tacho = getattr(speed_from, "speed_source", "") == "tacho"
        raise InputError(f"the recorded speed reaches {m.max_speed * 30.0 / np.pi:g} rpm, "
                         f"above the engine's combustion model ({top:g} rpm)",
                         file=str(getattr(speed_from, "path", speed_from)), key="tacho" if tacho else "rpm")


def seat_point(engine, seat) -> str | None:
    """The ISO 2631-1 body point: ``seat`` checked, else the first ``seat...``, else None."""
    points = list(getattr(engine.chassis, "points", ()) or ())
    if seat is None:
        return next((p for p in points if p.startswith("seat")), None)
    if seat not in points:
        raise InputError(f"no body point {seat!r} (the chassis has: "
                         f"{', '.join(points) or 'none'})", key="--seat")
    return seat


def figure_channels(system, channels) -> list | None:
    """The figure's channels (``mount.direction`` labels or a comma list) checked; None: default."""
    if not channels:
        return None
    if isinstance(channels, str):
        channels = [c.strip() for c in channels.split(",")]
    labels = [f"{c}.{d}" for c, d in system.channels]
    missing = [c for c in channels if c not in labels]
    if missing or not channels:
        raise InputError(f"no channel {', '.join(missing) or 'given'} (the model has: "
                         f"{', '.join(labels)})", key="--channels")
    return list(channels)


def _seat(engine, run, labels, seat):
    """ISO 2631-1 values at the seat point (None without one)."""
    if seat is None:
        return None
    fs = 1.0 / (run.load.t[1] - run.load.t[0])
    rms, vdv = {}, {}
    for a, w in AXIS_WEIGHTING.items():
        aw = weighted(run.acceleration[:, labels.index(f"{seat}.{a}")], fs, w)
        rms[a], vdv[a] = weighted_rms(aw, fs), vibration_dose_value(aw, fs)
    return {"point": seat, "rms": rms, "vdv": vdv, "weighting": dict(AXIS_WEIGHTING)}
