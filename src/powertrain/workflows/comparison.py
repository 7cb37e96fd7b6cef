r"""Comparison of a simulated run-up with a measured one (``powertrain compare``).

Per mount, direction and quantity on both sides: the level gap
:math:`20\log_{10}(v_\mathrm{sim}/v_\mathrm{meas})` [dB] at the measured speeds and the
metrics of :mod:`powertrain.analysis.compare` (FRAC, CSAC, CSF, FRFSM-like). The simulation
is interpolated in rpm and log level, never extrapolated; points at the noise floor and
"measured, not modelled" are counted, not scored. Rules: docs/guide/compare.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from powertrain.analysis import compare as cm
from powertrain.analysis.noise_floor import at_floor, below_floor
from powertrain.analysis.orders import quantity_sort_key
from powertrain.errors import InputError
from powertrain.iotools.channel_map import split_unit
from powertrain.iotools.measured import MeasuredRunup, read_measured
from powertrain.iotools.raw import detect_format
from powertrain.results.comparison import (
    EXPECTED_QUANTITIES,
    MIN_CHANNELS_CSAC,
    ChannelComparison,
    ComparisonResult,
    json_number,
)
from powertrain.solvers.steppers import SOLVERS
from powertrain.workflows.arguments import MAX_SPEEDS, choice, default_rpm, nonnegative, real
from powertrain.workflows.runup import checked_runup, engine_and_file, run_runup

#: Default RMS noise floor of the measured order curves [m/s] (0.001 mm/s, see README).
DEFAULT_NOISE_FLOOR = 1e-6
#: Speeds closer than this are the same speed when pooling channels [rpm].
RPM_TOL = 1e-6


def compare(measured, *, engine=None, simulated=None, solver="newmark", step=None,
            noise_floor=DEFAULT_NOISE_FLOOR, progress=False) -> ComparisonResult:
    """Compare a simulated run-up with a measured one (``powertrain compare``).

    Parameters
    ----------
    measured : str, Path or MeasuredRunup
        Measured order curves (long-format CSV or run-up HDF5; not raw time data).
    engine : Engine, str, Path or None
        Engine simulated at the measured speeds (default ``engines/default.toml``).
    simulated : str, Path, MeasuredRunup or RunupResult, optional
        A simulation to compare instead of ``engine``'s.
    solver : {"newmark", "harmonic"}
        Solver of the simulation run here.
    step : float, optional
        Simulate on a grid of this step [rpm] and interpolate (default: every measured speed).
    noise_floor : float
        RMS noise floor of the measured curves [m/s].
    progress : bool
        Progress bar of the simulation.

    Returns
    -------
    ComparisonResult
        ``run`` tells what ran; ``to_text()`` is the command's report.
    """
    t0 = time.perf_counter()
    if simulated is not None and engine is not None:
        raise InputError("give --sim or --engine, not both", key="--sim")
    choice(solver, tuple(SOLVERS), "--solver")
    noise_floor = nonnegative(noise_floor, "--noise-floor", "m/s")
    step = real(step, "--step", unit="rpm", optional=True)
    if step is not None and not (math.isfinite(step) and step > 0):
        raise InputError("must be > 0 [rpm]", key="--step")
    if simulated is not None:
        sim, meas, run = _given_simulation(simulated, measured)
    else:
        engine, engine_file = engine_and_file(engine)
        meas = _read_curves(measured, list(engine.mount_names))
        sim = _simulate(engine, engine_file, meas, step, solver, progress)
        run = {"engine": engine, "engine_file": engine_file, "solver": solver}
    run["simulation_seconds"] = time.perf_counter() - t0
    comp = compare_runup(sim, meas, noise_floor=noise_floor)
    if not comp.channels and not comp.not_modelled:
        raise InputError("nothing to compare: no channel and quantity has a point above the "
                         f"noise floor ({noise_floor * 1e3:g} mm/s) inside the simulated speed "
                         "range", file=meas.source if isinstance(measured, MeasuredRunup)
                         else measured, key="--noise-floor")
    return replace(comp, run={**run, "seconds": time.perf_counter() - t0})


def _given_simulation(simulated, measured):
    """The given simulation's curves, the measured ones and ``run``."""
    name = None
    if isinstance(simulated, MeasuredRunup):
        sim = simulated
    elif hasattr(simulated, "velocity"):
        sim = MeasuredRunup.from_result(simulated, source="simulation")
    else:
        name = str(simulated)
        sim = _read_curves(simulated)
    meas = _read_curves(measured, sorted({m for m, _ in sim.channels}))
    if meas.signal != sim.signal:
        if not isinstance(simulated, (str, Path)):
            sim = MeasuredRunup.from_result(simulated, source="simulation", signal=meas.signal)
        else:
            raise InputError(f"measured {meas.signal} curves need a simulation of the same "
                             "quantity; run without --sim (the simulation is run here)", file=name)
    return sim, meas, {"engine": None, "simulation_file": name or sim.source}


def _read_curves(path, mounts=None):
    """Order curves of ``path``; raw time data refused with a pointer to ``track``."""
    if isinstance(path, MeasuredRunup):
        return path
    kind = detect_format(path)
    if kind in ("mdf", "uff"):
        raise InputError(f"raw time data ({kind.upper()}), not order curves: track it first "
                         f"('powertrain track {path} --csv curves.csv'), then compare curves.csv", file=path)
    try:
        return read_measured(path, mounts=mounts)
    except InputError as exc:
        if _is_raw_csv(exc):
            raise InputError("raw time data (a 'time' column), not order curves: track it "
                             f"first ('powertrain track {path} --csv curves.csv'), then "
                             "compare curves.csv", file=path, line=exc.line, key=exc.key) from None
        raise


def _is_raw_csv(exc) -> bool:
    """True if the order-curve reader refused a wide raw CSV (its time column)."""
    return bool(exc.key) and split_unit(str(exc.key))[0].strip().lower() == "time" \
        and exc.message.startswith("unknown column")


def _simulate(engine, engine_file, meas, rpm_step, solver, progress):
    """Run the engine at the measured speeds (or on a ``rpm_step`` grid over them)."""
    rpm = simulation_speeds(engine, meas, rpm_step)
    grid = (f"{rpm[0]:g}..{rpm[-1]:g} rpm step {rpm_step:g}, interpolated" if rpm_step
            else f"at the {rpm.size} measured speeds {rpm[0]:g}..{rpm[-1]:g} rpm")
    result = checked_runup(engine, engine_file, run_runup, rpm, solver=solver, progress=progress)
    return MeasuredRunup.from_result(result, source=f"{engine_file} ({solver}, {grid})", signal=meas.signal)


def simulation_speeds(engine, meas, rpm_step=None):
    """Speeds to simulate [rpm]: the measured ones in the engine's range, or a ``rpm_step``
    grid over both ranges' intersection."""
    lo, hi = meas.rpm_range()
    e_lo, e_hi = engine.speed_range_rpm()
    if hi < e_lo or lo > e_hi:
        raise InputError(f"measured speeds {lo:g}..{hi:g} rpm outside the engine's range "
                         f"{e_lo:g}..{e_hi:g} rpm", file=meas.source, key="rpm")
    if rpm_step is None:
        rpm = np.unique(np.concatenate([r for r, _ in meas.curves.values()]))
        rpm = rpm[(rpm >= e_lo - 1e-6) & (rpm <= e_hi + 1e-6)]
        if rpm.size > MAX_SPEEDS:
            raise InputError(f"{rpm.size} distinct measured speeds; at most {MAX_SPEEDS} are "
                             "simulated one by one: give --step to simulate a grid",
                             file=meas.source, key="rpm")
        return rpm
    start = max(math.floor(lo / rpm_step + 1e-9) * rpm_step, math.ceil(e_lo / rpm_step - 1e-9) * rpm_step)
    stop = min(math.ceil(hi / rpm_step - 1e-9) * rpm_step, math.floor(e_hi / rpm_step + 1e-9) * rpm_step)
    if stop < start or start <= 0:
        raise InputError(f"{rpm_step:g} rpm leaves no speed step inside both the measured "
                         f"({lo:g}..{hi:g}) and the engine's ({e_lo:g}..{e_hi:g}) range", key="--step")
    if (stop - start) / rpm_step + 1 > MAX_SPEEDS:
        raise InputError(f"{(stop - start) / rpm_step + 1:.3g} speed steps over the "
                         f"measured range; at most {MAX_SPEEDS}", key="--step")
    rpm = default_rpm(start, stop, rpm_step)
    if rpm[0] > hi or rpm[-1] < lo:
        raise InputError(f"{rpm_step:g} rpm puts no simulated speed at or around the measured "
                         f"{lo:g}..{hi:g} rpm (grid {rpm[0]:g}..{rpm[-1]:g} rpm inside the "
                         f"engine's {e_lo:g}..{e_hi:g}): give a smaller step", key="--step")
    return rpm


def compare_runup(simulated, measured: MeasuredRunup, *, noise_floor=DEFAULT_NOISE_FLOOR,
                  sigma_db=cm.FRFSM_SIGMA_DB) -> ComparisonResult:
    """Compare simulated with measured run-up order curves.

    Parameters
    ----------
    simulated : RunupResult or MeasuredRunup
        The simulation.
    measured : MeasuredRunup
        Measured curves [m/s RMS].
    noise_floor : float
        RMS noise floor of the measured curves [m/s]; points at it are counted, not scored.
    sigma_db : float
        Kernel width of the FRFSM-like score [dB].
    """
    if not isinstance(simulated, MeasuredRunup):
        simulated = MeasuredRunup.from_result(simulated, source="simulation", signal=measured.signal)
    if not (np.isfinite(noise_floor) and noise_floor >= 0):
        raise ValueError("noise floor must be finite and >= 0")
    channel_order = list(simulated.channels)
    channel_order += [c for c in measured.channels if c not in channel_order]
    quantities = sorted(set(EXPECTED_QUANTITIES) | set(measured.quantities), key=quantity_sort_key)
    sim_rpm = np.unique(np.concatenate([r for r, _ in simulated.curves.values()]))
    channels, missing, not_modelled = [], [], []
    for mount, direction in channel_order:
        for q in quantities:
            where = {"mount": mount, "direction": direction, "quantity": q}
            key = (mount, direction, q)
            if key not in measured.curves or key not in simulated.curves:
                side = "measured data" if key not in measured.curves else "simulation"
                missing.append({**where, "reason": f"not in the {side}"})
                continue
            c = _compare_channel(where, measured.curves[key], simulated.curves[key],
                                 noise_floor, sigma_db, measured.phases.get(key), simulated.phases.get(key))
            if c.not_modelled.any():
                not_modelled.append({**where, **_points(c, c.not_modelled)})
            if c.scored.any():
                channels.append(c)
            elif not c.not_modelled.any():
                missing.append({**where, "reason": f"no comparable point ({int(c.outside.sum())} outside the "
                                f"simulated range, {int(c.at_floor.sum())} at the noise floor)"})
    per_rpm = _per_rpm(channels)
    return ComparisonResult(channels, per_rpm, missing, measured, simulated,
                            float(noise_floor), sim_rpm, sigma_db, not_modelled=not_modelled)


def _compare_channel(where, measured_curve, simulated_curve, noise_floor, sigma_db,
                     measured_phase=None, simulated_phase=None):
    """Classify and score the measured points of one channel and quantity (and phase)."""
    rpm_m, lev_m = measured_curve
    rpm_s, lev_s = simulated_curve
    sim, inside = cm.interpolate_log(rpm_s, lev_s, rpm_m)
    floor = inside & at_floor(lev_m, noise_floor)
    unmodelled = inside & ~floor & below_floor(sim, noise_floor)
    zero = unmodelled & ~(sim > 0)
    scored = inside & ~floor & ~unmodelled
    at_node = np.isin(np.round(rpm_m / RPM_TOL), np.round(np.asarray(rpm_s) / RPM_TOL))
    gap = cm.level_gap_db(sim[scored], lev_m[scored])
    stats = cm.gap_statistics(rpm_m[scored], gap)
    if scored.any():
        stats["frac"] = cm.frac(sim[scored], lev_m[scored])
        stats["frfsm"] = cm.frfsm_score(gap, sigma_db)
    phase_gap = _phase_gap(stats, rpm_m[scored], sim[scored], lev_m[scored], measured_phase,
                           simulated_phase, rpm_s, scored)
    return ChannelComparison(where["mount"], where["direction"], where["quantity"], rpm_m,
                             lev_m, sim, ~inside, floor, zero, unmodelled, inside & ~at_node,
                             scored, gap, stats, phase_gap)


def _phase_gap(stats, rpm, simulated, measured, measured_phase, simulated_phase, rpm_s, scored):
    """Phase gap per scored point (None without both phases); its statistics go to ``stats``."""
    if measured_phase is None or simulated_phase is None or not scored.any():
        return None
    sim = cm.interpolate_phase(rpm_s, simulated_phase, rpm)
    more = cm.phase_statistics(simulated, measured, sim, np.asarray(measured_phase, float)[scored])
    phase_gap = more.pop("phase_gap_deg")
    stats.update(more)
    return phase_gap


def _points(c: ChannelComparison, mask) -> dict:
    """Speeds and both levels of ``c``'s points in ``mask`` (JSON-ready)."""
    return {"rpm": [json_number(x) for x in c.rpm[mask]],
            "measured_m_per_s": [json_number(x) for x in c.measured[mask]],
            "simulated_m_per_s": [json_number(x) for x in c.simulated[mask]]}


def _per_rpm(channels) -> list:
    """CSAC and CSF across the channels at each compared speed, per quantity."""
    out = []
    for q in sorted({c.quantity for c in channels}, key=quantity_sort_key):
        pts = {}
        for c in (c for c in channels if c.quantity == q):
            for r, s, m in zip(c.rpm[c.scored], c.simulated[c.scored], c.measured[c.scored]):
                pts.setdefault(round(float(r) / RPM_TOL) * RPM_TOL, []).append((s, m))
        for r in sorted(pts):
            sm = np.array(pts[r])
            entry = {"quantity": q, "rpm": round(r, 6), "n_channels": int(sm.shape[0]),
                     "csac": None, "csf": None}
            if sm.shape[0] >= MIN_CHANNELS_CSAC:
                entry["csac"] = json_number(cm.csac(sm[:, 0], sm[:, 1]))
                entry["csf"] = json_number(cm.csf(sm[:, 0], sm[:, 1]))
            out.append(entry)
    return out
