r"""The run-up: engine -> assembled model -> solver -> order results.

:func:`runup` (``powertrain runup``) checks the engine and settings, applies balancers and
effects, then runs a stepped run-up (:func:`run_runup`) or a continuous one (``sweep``,
tracked like a measurement). Per speed step the load over one engine cycle drives the
periodic steady state: Newmark over :data:`CYCLES` cycles, :data:`PROCESSED_CYCLES` processed
by FFT (thesis sec. 4.4), or the frequency-domain solve (``harmonic``). docs/guide/runup.md.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import replace

import numpy as np
from scipy.linalg import block_diag

from powertrain.analysis.orders import ORDERS
from powertrain.effects import EFFECTS, check_scenario
from powertrain.errors import InputError, PowertrainWarning, require_finite, solved
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, engine_or_default, read_engine
from powertrain.parallel import single_blas_thread
from powertrain.progress import activity, progress_bar
from powertrain.results.runup import RunupResult, SweepRunup
from powertrain.results.static import StaticResult
from powertrain.solvers.equivalent_linear import AmplitudeNotConverged
from powertrain.solvers.modes import COORDINATES, kinetic_energy_percent
from powertrain.solvers.operating_point import has_static_curves, operating_points, static_factors
from powertrain.solvers.speed_ramp import simulate_sweep
from powertrain.solvers.steppers import NEWMARK_STEPPERS, SOLVERS, Cycles, choose_stepper
from powertrain.workflows import arguments as args
from powertrain.workflows.arguments import default_rpm
from powertrain.workflows.operations import effect_scenario
from powertrain.workflows.tracking import track_recording
from powertrain.workflows.variants import parse_operations

#: Default crank-angle increment [deg]; halving it moves the results < 0.1 %.
ANGLE_STEP_DEG = 1.0
#: Cycles simulated per speed step and cycles processed (thesis sec. 4.4).
CYCLES = 6
PROCESSED_CYCLES = 2
#: Periodicity above which a warning is raised.
PERIODICITY_LIMIT = 1e-3
#: Finest and coarsest crank-angle step [deg] (72 steps a cycle resolve order 8).
MIN_ANGLE_STEP_DEG = 0.05
MAX_ANGLE_STEP_DEG = 10.0
#: Tracking of a continuous run-up: 50 rpm grid; speed, phase from its tacho (TDC offset 0).
SWEEP_TRACKING = {"rpm_step": 50.0, "pulses_per_rev": 1, "tdc_offset_deg": 0.0}


class PeriodicityWarning(PowertrainWarning):
    """The processed window is not periodic to the stated limit."""


def _cycle_loads(engine, rpm, n_per_cycle):
    """Generalized load over one engine cycle at every speed, (n_speeds, n_per_cycle, 6)."""
    theta = np.arange(n_per_cycle) * (4 * np.pi / n_per_cycle)
    load = np.asarray(engine.load_table(rpm, theta), float)
    if load.shape != (len(rpm), n_per_cycle, 6) or not np.all(np.isfinite(load)):
        raise ValueError("engine.load_table must return finite (n_speeds, n, 6) values")
    return load


def run_runup(engine, rpm=None, *, solver="newmark", angle_step_deg=ANGLE_STEP_DEG,
              cycles=CYCLES, processed_cycles=PROCESSED_CYCLES, progress=False,
              system=None, stepper="auto") -> RunupResult:
    """Simulate a run-up: steady state at each speed, order analysis of the mount points.

    Parameters
    ----------
    engine : Engine
        Provides ``body`` (mass, cg, inertia), ``mounts`` and ``load_table``.
    rpm : array_like, optional
        Speed steps [rpm]; default 1000..6000 step 500.
    solver : {"newmark", "harmonic"}
        Time integration or frequency-domain solve.
    angle_step_deg : float
        Crank-angle increment [deg]; must divide 720 into an even number of steps.
    cycles, processed_cycles : int
        Engine cycles simulated and processed (Newmark only).
    progress : bool
        Progress bar over the speed steps.
    system : AssembledSystem, optional
        Pre-assembled model (default: assembled from ``engine``).
    stepper : {"auto", "modal", "dense"}
        Newmark implementation: ``modal`` (diagonalised once, needs a regular mass matrix),
        ``dense`` or ``auto`` (modal when possible).
    """
    rpm = _speeds(rpm)
    grid = _cycles(angle_step_deg, cycles, processed_cycles)
    bar = {"desc": f"run-up ({solver})", "unit": "speed", "enabled": bool(progress)}
    with single_blas_thread():
        if system is None:
            system = engine.assemble()
        step = choose_stepper(system, solver, stepper, grid)
        loads = list(_cycle_loads(engine, rpm, grid.n_cycle))
        points = operating_points(engine, rpm) if has_static_curves(engine) else None
        speeds, seconds = _solve_speeds(engine, step, rpm, loads, points, bar)
        _warn_periodicity(rpm, [o.periodicity for o in speeds])
        return _result(engine, system, step, rpm, speeds, step.setup_seconds + seconds,
                       None if points is None else _static_result(engine, points))


def _static_result(engine, points) -> StaticResult:
    return StaticResult(points, engine.mount_names, engine.name)


def _speeds(rpm) -> np.ndarray:
    rpm = default_rpm() if rpm is None else np.atleast_1d(np.asarray(rpm, float))
    if np.any(rpm <= 0):
        raise ValueError("speeds must be positive")
    return rpm


def _cycles(angle_step_deg, cycles, processed_cycles) -> Cycles:
    n_cycle = 720.0 / angle_step_deg
    if abs(n_cycle - round(n_cycle)) > 1e-9 or round(n_cycle) % 2:
        raise ValueError("angle step must divide 720 deg into an even number of steps")
    if processed_cycles < 1 or cycles < processed_cycles:
        raise ValueError("need cycles >= processed_cycles >= 1")
    return Cycles(int(round(n_cycle)), angle_step_deg, cycles, processed_cycles)


def _solve_speeds(engine, step, rpm, loads, points, bar):
    """Every speed's :class:`SpeedOrders` and the solver time; with operating ``points``,
    each speed on the model assembled at its operating point."""
    speeds, total = [], 0.0
    for i in progress_bar(range(rpm.size), **bar):
        if points is not None:
            step = step.on_system(engine.assemble(points[i].static_factor))
            total += step.setup_seconds
        speeds.append(step.solve(loads[i], rpm[i] * 2 * np.pi / 60.0))
        total += speeds[-1].seconds
    return speeds, total


def _warn_periodicity(rpm, periodicity):
    for n_rpm, p in zip(rpm, periodicity):
        if p > PERIODICITY_LIMIT:
            warnings.warn(f"{n_rpm:g} rpm: processed window periodic only to "
                          f"{100 * p:.3g} % (> 0.1 %)", PeriodicityWarning, stacklevel=3)


def _result(engine, system, step, rpm, speeds, solver_seconds, operating_point) -> RunupResult:
    def stack(name):
        return np.array([getattr(o, name) for o in speeds])

    chassis = system.chassis
    modes_hz, _ = system.rigid_body_modes()
    force = stack("force")
    paths = None
    if chassis is not None and not chassis.is_rigid and chassis.points:
        paths = path_contributions(system, rpm, force)
    return RunupResult(rpm=rpm, orders=ORDERS.copy(), channels=list(system.channels),
                       displacement=stack("displacement"), velocity=stack("velocity"),
                       acceleration=stack("acceleration"), mount_force=force,
                       mean_mount_force=stack("mean_force"),
                       periodicity=stack("periodicity"), settings=step.settings(),
                       solver_seconds=solver_seconds, rigid_body_modes_hz=modes_hz,
                       path_contribution=paths, operating_point=operating_point,
                       meta={"engine": getattr(engine, "name", ""),
                             "chassis": "rigid" if chassis is None else chassis.model,
                             "points": list(chassis.points) if chassis is not None else [],
                             "nonlinear_mounts": system.port_forces() is not None})


def path_contributions(system, rpm, force) -> np.ndarray:
    r"""Velocity at every body-point channel carried by each mount path (mount × local
    direction) per speed and order [m/s]: :math:`\hat v_{P,(m,d)} = i\omega\,\mathbf
    G_{Pm}(\omega)\,\mathbf e_d\,(\mathbf e_d\cdot\hat{\mathbf f}_m)`, with the mount force
    on the body :math:`\hat{\mathbf f}_m` and the body's receptance :math:`\mathbf G_{Pm}`.

    Returns
    -------
    ndarray complex (n_rpm, 3 n_points, 3 n_mounts, n_orders)
    """
    ch = system.chassis
    mounts = system.mount_names
    n_a = system.n_mount_channels
    out = np.zeros((len(rpm), 3 * len(ch.points), n_a, ORDERS.size), complex)
    E = block_diag(*system.mount_axes)          # column p: local axis of path p, at its mount
    w = np.outer(np.asarray(rpm, float) * 2 * np.pi / 60.0, ORDERS)      # (n_rpm, n_orders)
    G = ch.receptances(w, list(ch.points), mounts).reshape(w.shape + (3 * len(ch.points), n_a))
    GE = G @ E                                                     # (n_rpm, n_o, 3 n_p, n_a)
    f_local = np.einsum("ap,ika->ikp", E, np.moveaxis(force[:, :n_a, :], 1, 2))   # e_p . f
    out[:] = np.moveaxis(1j * w[..., None, None] * GE * f_local[:, :, None, :], 1, 3)
    return out


def runup_with_effects(engine, rpm, scenario: dict, **options):
    """:func:`run_runup` (``**options``) of ``engine`` with the effects of ``scenario``
    (``{effect: {parameter: value}}``, SI), recorded in ``settings["effects"]``.

    Engine-model effects change the engine, in registry order; sensor effects change the
    channels' displacement, velocity and acceleration (not the forces).
    """
    sc = check_scenario(scenario, engine)
    rpm = np.atleast_1d(np.asarray(rpm, float))
    for name, eff in EFFECTS.items():
        if name in sc and eff.engine_change:
            engine = eff.apply(engine, **sc[name])
    result = run_runup(engine, rpm, **options)
    read = {}
    for name, p in sc.items():
        if EFFECTS[name].response_only:
            for attr in ("displacement", "velocity", "acceleration"):
                read[attr] = EFFECTS[name].reading(read.get(attr, getattr(result, attr)), p)
    return replace(result, **read, settings={**result.settings, "effects": sc})


def runup(engine=None, rpm=None, *, solver="newmark", stepper="auto",
          angle_step_deg=ANGLE_STEP_DEG, balancers=True, effects=(), sweep=None,
          sample_rate=8192.0, progress=False):
    """A run-up of ``engine`` as the ``powertrain runup`` command runs it.

    Parameters
    ----------
    engine : Engine, str or Path, optional
        The engine, or its file (default: the shipped ``engines/default.toml``).
    rpm : array_like or str, optional
        Speed steps [rpm], or as ``"1000:6000:500"`` (the default); a ``sweep`` ramps from
        the first to the last.
    solver, stepper, angle_step_deg :
        As in :func:`run_runup`.
    balancers : bool
        False switches the balancer shafts off.
    effects : sequence of str or dict
        ``--effect`` strings (``"base_compliance:c_base=400N/mm"``) or a scenario
        ``{effect: {parameter: value}}`` [SI].
    sweep : float, optional
        Continuous run-up at this rate [rpm/s], tracked like measured data (no effects).
    sample_rate : float
        With ``sweep``: sampling rate [Hz].
    progress : bool
        Progress bar on stderr.

    Returns
    -------
    RunupResult, or SweepRunup with ``sweep``
        ``to_text()`` is what the command prints; ``plot(ax=None)``, ``to_csv``, ``to_hdf5``.

    Raises
    ------
    InputError
        Naming the engine file and key, or the option, of bad input.
    """
    options = _checked_options(solver, stepper, angle_step_deg, balancers, sweep, sample_rate, progress)
    engine = engine_or_default(engine)
    engine.require_excitation()
    modifications = []
    if not options["balancers"]:
        engine = engine.with_balancers(enabled=False)
        modifications.append("balancer shafts switched off (--no-balancers)")
    if options["sweep"] is not None:
        return _sweep_runup(engine, rpm, options["sweep"], options["sample_rate"], effects,
                            options["progress"])
    rpm = args.speeds(rpm)
    scenario = effects if isinstance(effects, dict) else effect_scenario(
        parse_operations({"effect": args.texts(effects, "--effect")}, engine=engine))
    check_runup_settings(engine, rpm, options["angle_step_deg"])
    result = _stepped(engine, rpm, scenario, options["progress"], solver=solver,
                      angle_step_deg=options["angle_step_deg"], stepper=stepper)
    return _with_engine(result, engine, rpm, modifications)


def _with_engine(result, engine, rpm, modifications) -> RunupResult:
    """The run-up with the engine, its modifications, operating points, file and each
    mode's dominant coordinate."""
    operating_point = result.operating_point
    if operating_point is None:
        operating_point = _static_result(engine, operating_points(engine, rpm))
    dominant = mode_coordinates(engine, result.rigid_body_modes_hz)
    return replace(result, engine=engine, modifications=modifications, operating_point=operating_point,
                   meta={**result.meta, "engine_file": str(engine.file),
                         "rigid_body_mode_dominant": dominant})


def _checked_options(solver, stepper, angle_step_deg, balancers, sweep, sample_rate, progress) -> dict:
    """The options of :func:`runup` checked."""
    args.choice(solver, tuple(SOLVERS), "--solver")
    args.choice(stepper, tuple(NEWMARK_STEPPERS), "--stepper")
    return {"angle_step_deg": args.real(angle_step_deg, "--angle-step", unit="deg"),
            "balancers": args.flag(balancers, "--no-balancers"),
            "sweep": args.real(sweep, "--sweep", unit="rpm/s", optional=True),
            "sample_rate": args.real(sample_rate, "--sample-rate", unit="Hz"),
            "progress": args.flag(progress, "progress")}


def _stepped(engine, rpm, scenario, progress, **options) -> RunupResult:
    """The stepped run-up, with the effects of ``scenario`` if any, checked finite."""
    if not scenario:
        return checked_runup(engine, engine.file, run_runup, rpm, progress=progress, **options)
    with activity(f"run-up with effects ({options['solver']})", enabled=progress):
        return checked_runup(engine, engine.file, runup_with_effects, rpm, scenario, **options)


def _sweep_runup(engine, rpm, rate, sample_rate, effects, progress) -> SweepRunup:
    """Simulate the speed ramp and track it (COT, orders 0.5..8, as velocity)."""
    if effects:
        raise InputError("effects are not simulated in a sweep (use stepped run-ups)", key="--effect")
    rpm = args.speeds(rpm, increasing=False)
    factors = (lambda r: static_factors(engine, r)) if has_static_curves(engine) else None
    rec = simulate_sweep(engine, rpm[0], rpm[-1], rate, sample_rate, progress=progress,
                         static_factors=factors)
    try:
        tracked = track_recording(rec, **SWEEP_TRACKING, progress=progress).as_velocity()
    except InputError as exc:
        raise InputError(f"the {rec.time[-1] - rec.time[0]:.3g} s sweep cannot be order-"
                         f"tracked ({exc.message}); a slower sweep or a wider speed range",
                         key="--sweep") from None
    return SweepRunup(recording=rec, tracked=tracked, rate_rpm_per_s=float(rate), engine=engine)


def check_runup_settings(engine, rpm, angle_step: float) -> None:
    """Check a run-up's speeds against the engine's range and the crank-angle step."""
    lo, hi = engine.speed_range_rpm()
    if rpm[0] < lo - 1e-6:
        raise InputError(f"{rpm[0]:g} rpm is below the engine's range {lo:g}..{hi:g} rpm", key="--from")
    if rpm[-1] > hi + 1e-6:
        raise InputError(f"{rpm[-1]:g} rpm is above the engine's range {lo:g}..{hi:g} rpm", key="--to")
    n_cycle = 720.0 / angle_step if math.isfinite(angle_step) and angle_step > 0 else 0.0
    if not (MIN_ANGLE_STEP_DEG <= angle_step <= MAX_ANGLE_STEP_DEG
            and abs(n_cycle - round(n_cycle)) < 1e-9 and round(n_cycle) % 2 == 0):
        raise InputError(f"{angle_step:g} deg: must divide 720 deg into an even number of "
                         f"steps, {MIN_ANGLE_STEP_DEG:g}..{MAX_ANGLE_STEP_DEG:g} deg "
                         "(e.g. 0.5, 1, 2)", key="--angle-step")


def check_path_plot(engine, order) -> None:
    """A path-contribution plot needs body points, and ``order`` must be an analysed one."""
    if not getattr(engine.chassis, "points", ()):
        raise InputError("needs body points ([chassis.points.NAME] with a modal or frf "
                         "chassis)", file=engine.file, key="--path-plot")
    if not np.any(np.isclose(ORDERS, order)):
        raise InputError(f"order {order:g} not analysed (0.5 to 8 in steps of 0.5)", key="--path-order")


def checked_runup(engine, engine_path, run, *args, **kwargs):
    """``run(engine, *args, **kwargs)`` (a run-up) checked solved and finite; errors name the
    engine file (or the mount file)."""
    def run_naming_mounts():
        try:
            return run(engine, *args, **kwargs)
        except AmplitudeNotConverged as exc:
            raise InputError(str(exc), *engine.mount_section(exc.element)) from None
    file, key = _blamed_input(engine, engine_path)
    result = solved(run_naming_mounts, file, key)
    values = {name.replace("_", " "): getattr(result, name) for name in (
        "displacement", "velocity", "acceleration", "mount_force", "mean_mount_force")}
    with np.errstate(over="ignore"):   # finite amplitudes whose squares overflow: absurd levels
        values["synthesis velocity"] = result.synthesis_rms("velocity")
    require_finite(values, file, key)
    return result


def _blamed_input(engine, engine_path):
    """``(file, key)`` an unsolvable run-up blames: an FRF body's receptances, else the engine."""
    receptance = getattr(engine.chassis, "receptance", None)
    if getattr(engine.chassis, "coupled_by_admittance", False) and getattr(receptance, "file", ""):
        return receptance.file, None
    return engine_path, "engine"


def mode_coordinates(engine, frequencies_hz) -> list:
    """The dominant coordinate (largest kinetic-energy share) of each mode of ``engine``
    matched to ``frequencies_hz``; ``""`` where none matches."""
    system = engine.assemble()
    f_sys, shapes = system.rigid_body_modes()
    out = []
    for f in frequencies_hz:
        k = int(np.argmin(np.abs(f_sys - f)))
        energy = kinetic_energy_percent(system.M[:6, :6], shapes[:, k])
        out.append(COORDINATES[int(np.argmax(energy))] if abs(f_sys[k] - f) <= 1e-6 * max(f, 1.0) else "")
    return out


def engine_and_file(engine=None):
    """``(engine, file)`` of an Engine, a path, or None (``engines/default.toml``)."""
    if engine is None or isinstance(engine, (str, os.PathLike)):
        path = str(engine or DEFAULT_ENGINE_PATH)
        return read_engine(path), path
    engine = engine_or_default(engine)
    return engine, engine.file
