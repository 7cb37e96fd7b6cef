r"""What-if: run the baseline and variants of the mount system, report the change in dB.

:func:`whatif` parses the variants (:mod:`powertrain.workflows.variants`); :func:`run_whatif`
runs the baseline and each variant (:func:`powertrain.workflows.sweeps.run_sweep`) into a
:class:`~powertrain.results.whatif.WhatIfResult`.
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.channel import Channel
from powertrain.analysis.orders import ORDERS
from powertrain.effects import RESPONSE_EFFECTS
from powertrain.errors import InputError
from powertrain.iotools.engine_checks import check_support
from powertrain.iotools.measured import MeasuredRunup, normalise_quantity, read_measured
from powertrain.parallel import check_scheduler
from powertrain.results.transient import TransientRanking
from powertrain.results.whatif import QUANTITIES, VariantRun, WhatIfResult
from powertrain.solvers.steppers import SOLVERS
from powertrain.workflows.arguments import choice, default_rpm, integer, path_or, real, speeds, texts
from powertrain.workflows.operations import Origin, Target, Variant, effect_scenario
from powertrain.workflows.retune import retuned_swap
from powertrain.workflows.runup import check_runup_settings, engine_and_file
from powertrain.workflows.sweeps import SweepTask, run_sweep
from powertrain.workflows.transient import manoeuvre_or_file, transient
from powertrain.workflows.variants import parse_operations, parse_target, read_variants

#: Signals a what-if compares (``--signal``).
SIGNALS = ("velocity", "mount_force")
#: Keywords of a run-up what-if that a what-if over a manoeuvre refuses -> what they are.
RUNUP_ONLY = {"rpm": "the run-up's speed steps", "rpm_from": "the run-up's first speed",
              "rpm_to": "the run-up's last speed", "rpm_step": "the run-up's speed step",
              "solver": "the run-up's solver", "signal": "the run-up's compared signal",
              "objective": "a run-up objective (a manoeuvre ranks by its peaks)",
              "measured": "a measured run-up",
              "executor": "a scheduler (a manoeuvre's runs are made here, in turn)",
              "scheduler": "a scheduler (a manoeuvre's runs are made here, in turn)",
              "workers": "a number of processes (a manoeuvre's runs are made here, in turn)",
              "target_out": "a retune target's fitted mount file (of a run-up what-if)",
              "target_plot": "a retune target's fit figure (of a run-up what-if)"}


def describe_engine(engine, solver: str, rpm) -> dict:
    """Baseline description for the JSON output."""
    return {"name": "baseline", "engine": engine.name, "engine_file": engine.file,
            "solver": solver, "rpm": [float(r) for r in rpm],
            "balancers_enabled": bool(engine.balancer.enabled),
            "mounts": {m.name: {"position_mm": [1e3 * float(x) for x in m.position], "files": dict(m.files),
                                "models": {d: mdl.topology.name for d, mdl in m.directions.items()}}
                       for m in engine.mounts}}


def whatif(engine=None, *, scale=(), set=(), swap=(), move=(), rotate=(), effects=(),
           targets=(), variants=None, rpm=None, solver=None, signal=None,
           objective=None, measured=None, executor=None, workers=None, progress=False,
           rpm_step=None, manoeuvre=None) -> WhatIfResult | TransientRanking:
    """What-if: the baseline and variants of the mount system, the change in dB (``whatif``),
    or their peaks over a transient manoeuvre (``whatif --manoeuvre``).

    Parameters
    ----------
    engine : Engine, str, Path or None
        Baseline (default: the shipped ``engines/default.toml``).
    scale, set, swap, move, rotate, effects : str or sequence of str
        Operations as the command line writes them (``left.z.stiffness=1.2``...), together
        the variant ``command line``.
    targets : str or sequence of str
        Retune targets (``left.z:+20%:100-300Hz``), each a variant.
    variants : str or Path, optional
        TOML file of named variants.
    rpm : array_like or str, optional
        Speed steps [rpm], or ``"1000:6000:500"`` (the default).
    solver, signal : str, optional
        ``harmonic`` (default) or ``newmark``; ``velocity`` (default) or ``mount_force``.
    objective : str, optional
        ``CHANNEL.DIR:QUANTITY:FROM-TO`` to rank the variants by (:func:`parse_objective`).
    measured : str, Path or MeasuredRunup, optional
        Measurement overlaid and compared.
    executor, workers, progress : optional
        Executor or scheduler (:func:`powertrain.parallel.executor`); local processes;
        progress bar.
    rpm_step : float, optional
        The speed step [rpm] the report names (default: that of ``rpm``).
    manoeuvre : str, Path or Manoeuvre, optional
        Over this manoeuvre instead of a run-up; the keywords of :data:`RUNUP_ONLY` are
        refused then.

    Returns
    -------
    WhatIfResult, or TransientRanking with ``manoeuvre``
    """
    ops = {"scale": scale, "set": set, "swap": swap, "move": move, "rotate": rotate, "effect": effects}
    if manoeuvre is not None:
        refuse_runup_options(dict(rpm=rpm, solver=solver, signal=signal, objective=objective,
                                  measured=measured, rpm_step=rpm_step, executor=executor, workers=workers))
        engine, _ = engine_and_file(engine)
        return whatif_manoeuvre(engine, _variants(engine, ops, targets, variants), manoeuvre)
    return _runup_whatif(engine, ops, targets, variants, rpm=rpm, solver=solver or "harmonic",
                         signal=signal or "velocity", objective=objective, measured=measured,
                         executor=executor, workers=workers, progress=progress, rpm_step=rpm_step)


def _runup_whatif(engine, ops, targets, variants, *, rpm, solver, signal, objective,
                  measured, executor, workers, progress, rpm_step) -> WhatIfResult:
    """:func:`whatif` over a run-up: the arguments checked, then :func:`run_whatif`."""
    workers = _checked(solver, signal, workers, executor)
    engine, _ = engine_and_file(engine)
    rpm = speeds(rpm)
    check_runup_settings(engine, rpm, 1.0)
    runs = _variants(engine, ops, targets, variants)
    goal = parse_objective(objective, engine.assemble().channels, rpm) if objective else None
    return run_whatif(engine, runs, rpm, solver=solver, executor=executor, workers=workers,
                      measured=_measured(measured, engine), signal=signal, progress=progress, objective=goal,
                      rpm_step=real(rpm_step, "--step", unit="rpm", optional=True))


def _variants(engine, ops: dict, targets, variants) -> list:
    """:func:`command_variants` of ``ops`` (option -> spec strings), targets and file."""
    ops = {key: texts(value, f"--{key}") for key, value in ops.items()}
    return command_variants(engine, ops, texts(targets, "--target"), variants)


def refuse_runup_options(given: dict, what: str = "manoeuvre", keys=None) -> None:
    """Refuse the first run-up option (:data:`RUNUP_ONLY`) set in ``given`` (keyword ->
    value or None) over a manoeuvre asked for by ``what``; ``keys``: keyword -> name shown."""
    for name, value in given.items():
        if value is not None:
            raise InputError(f"{RUNUP_ONLY.get(name, 'a run-up option')} has no meaning "
                             f"with {what}; leave it out", key=(keys or {}).get(name, name))


def whatif_manoeuvre(engine, variants, manoeuvre) -> TransientRanking:
    """The baseline and every variant over ``manoeuvre``, ranked by peak seat acceleration,
    else peak mount deflection (:class:`~powertrain.results.transient.TransientRanking`)."""
    m = manoeuvre_or_file(manoeuvre)
    engines = [engine] + [variant_engine(engine, v)[0] for v in variants]
    runs = [transient(m, e) for e in engines]
    return TransientRanking(m.name, ["baseline"] + [v.name for v in variants], runs)


def _measured(measured, engine):
    """The measurement to overlay: None, a MeasuredRunup, or its file read."""
    if measured is None or isinstance(measured, MeasuredRunup):
        return measured
    path_or(measured, (), "--measured", "a MeasuredRunup or its file")
    return read_measured(measured, mounts=engine.mount_names)


def _checked(solver, signal, workers, executor=None):
    """Solver, signal and scheduler checked; ``--workers`` as an int >= 1 (or None)."""
    if isinstance(executor, str) or executor is None:
        check_scheduler(executor)
    choice(solver, tuple(SOLVERS), "--solver")
    choice(signal, SIGNALS, "--signal")
    workers = integer(workers, "--workers", optional=True)
    if workers is not None and workers < 1:
        raise InputError("must be >= 1", key="--workers")
    return workers


def command_variants(engine, ops: dict, targets=(), variants_file=None) -> list:
    """The variants: ``ops`` (``{"scale": [...], ...}``) as ``command line``, each target,
    then those of ``variants_file``."""
    out = []
    parsed = parse_operations(ops, engine=engine)
    if parsed:
        out.append(Variant("command line", parsed))
    out += [Variant(f"target {t}", (parse_target(t, Origin("--target")),)) for t in targets]
    if variants_file:
        out += read_variants(variants_file)
    if not out:
        raise InputError("no variant given (use --scale, --set, --swap, --move, --rotate, "
                         "--effect, --target or --variants)", key="--variants")
    names = [v.name for v in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"duplicate variant name {dup[0]!r}", file=variants_file, key="variant.name")
    return out


def parse_objective(text, channels, rpm):
    """``CHANNEL.DIR:QUANTITY:FROM-TO`` checked against ``channels`` and the speeds ``rpm``:
    ``(channel, direction, quantity, rpm_lo, rpm_hi)``."""
    form = "CHANNEL.DIR:QUANTITY:FROM-TO, e.g. seat_rail.z:order_2:1500-3000"
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3 or "." not in parts[0] or "-" not in parts[2]:
        raise InputError(f"expected {form}, got {text!r}", key="--objective")
    name, d = parts[0].rsplit(".", 1)
    d = d.lower()
    if (name, d) not in channels:          # left.passive.z: node left/passive
        try:
            name = Channel.parse(parts[0]).node
        except ValueError:
            pass
    if (name, d) not in channels:
        known = sorted({m for m, _ in channels})
        raise InputError(f"unknown channel {parts[0]!r} (channels: {', '.join(known)}; "
                         "directions x, y, z)", key="--objective")
    try:
        q = normalise_quantity(parts[1])
        if q != "synthesis" and not np.any(np.isclose(ORDERS, float(q.split("_", 1)[1]))):
            raise ValueError(q)
        lo, hi = (float(x) for x in parts[2].lower().removesuffix("rpm").split("-"))
    except (ValueError, KeyError):
        raise InputError(f"expected {form}, got {text!r}", key="--objective") from None
    if not (lo <= hi) or not any(lo - 1e-9 <= r <= hi + 1e-9 for r in rpm):
        raise InputError(f"no speed step in {lo:g}-{hi:g} rpm", key="--objective")
    return (name, d, q, lo, hi)


def variant_engine(engine, variant, **fit_kwargs):
    """``(engine, fits)`` of ``variant``: its operations applied in order (a target fitted
    against the engine before it); each stage must carry the body."""
    stages, fits = [], []
    for op in variant.operations:
        retuned = isinstance(op, Target)
        if retuned:
            op, fit = retuned_swap(engine, op, **fit_kwargs)
            fits.append(fit)
        engine = op.apply(engine)
        if not retuned:
            stages.append((op, engine))
    for op, stage in stages:
        try:
            check_support(stage, None)
        except InputError as exc:
            raise op.origin.error(f"variant {variant.name!r}: {exc.message}") from None
    return engine, fits


def run_whatif(engine, variants, rpm=None, *, solver: str = "harmonic", executor=None,
               workers: int | None = None, measured=None, quantities=QUANTITIES,
               signal: str = "velocity", progress: bool = False, fit_kwargs: dict | None = None,
               runup_options: dict | None = None, objective=None,
               rpm_step: float | None = None) -> WhatIfResult:
    """Run the baseline and every variant; return their changes.

    Parameters
    ----------
    engine : Engine
        Baseline.
    variants : sequence of Variant
        Names unique and not ``baseline``; targets are fitted here, before the sweep.
    rpm : array_like, optional
        Speed steps [rpm] (default 1000..6000 step 500).
    solver : {"harmonic", "newmark"}
        Solver of the run-ups.
    executor, workers
        Where they run (:func:`powertrain.workflows.sweeps.run_sweep`).
    measured : MeasuredRunup, optional
        Overlaid in the plot; gaps reported.
    quantities : tuple of str
        Quantities reported.
    signal : str
        ``velocity``, ``mount_force``, ``displacement`` or ``acceleration``.
    fit_kwargs : dict, optional
        Passed to :func:`powertrain.workflows.fitting.fit_mount` for targets.
    runup_options : dict, optional
        Further keyword arguments of :func:`powertrain.workflows.runup.run_runup`.
    objective : tuple, optional
        The response to rank the variants by (:func:`parse_objective`).
    rpm_step : float, optional
        The speed step the report names [rpm] (default: that of ``rpm``).
    """
    rpm = default_rpm() if rpm is None else np.atleast_1d(np.asarray(rpm, float))
    names = [v.name for v in variants]
    if len(set(names)) != len(names) or "baseline" in names:
        raise ValueError("variant names must be unique and not 'baseline'")
    opts = dict(runup_options or {})
    tasks = [SweepTask("baseline", engine.replace(), rpm, solver, opts)]   # fresh caches
    fits = []
    for v in variants:
        varied, f = variant_engine(engine, v, **(fit_kwargs or {}))
        fits += f
        tasks.append(SweepTask(v.name, varied, rpm, solver, opts,
                               effect_scenario(v.operations, RESPONSE_EFFECTS)))
    results = run_sweep(tasks, executor, workers=workers, progress=progress)
    runs = [VariantRun(v.name, v.specs, r) for v, r in zip(variants, results[1:])]
    if rpm_step is None and rpm.size > 1:
        rpm_step = float(rpm[1] - rpm[0])
    return WhatIfResult(baseline=results[0], variants=runs, description=describe_engine(engine, solver, rpm),
                        quantities=tuple(quantities), measured=measured, target_fits=fits,
                        signal=signal, objective=objective, rpm_step=rpm_step)
