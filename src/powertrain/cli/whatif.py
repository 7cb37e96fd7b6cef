"""``powertrain whatif``: baseline vs variants of the mount system, change in dB."""

from __future__ import annotations

import click

from powertrain.cli import main
from powertrain.cli.common import (
    check_outputs,
    runup_settings,
    speed_options,
    speed_steps,
    write_json,
)
from powertrain.results.runup import RIGID_BODY_MODES_LABEL


@main.command()
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@speed_options
@click.option("--solver", type=click.Choice(["harmonic", "newmark"]), default="harmonic",
              show_default=True,
              help="harmonic: exact steady state of the linear model, fast; newmark: time "
                   "integration as in `runup`.")
@click.option("--scale", multiple=True, metavar="MOUNT.DIR.KIND=FACTOR",
              help="Scale springs (stiffness), dampers (damping) or c, d and m together "
                   "(dynamic: K_CP(f) x FACTOR); MOUNT/DIR may be *. Repeatable.")
@click.option("--set", "set_", multiple=True, metavar="MOUNT.DIR.PARAM=VALUE",
              help="Set one parameter in its datasheet unit (c N/mm, d N*s/mm, m kg) or an "
                   "explicit unit (150N/mm). Repeatable.")
@click.option("--swap", multiple=True, metavar="MOUNT.DIR=FILE.toml",
              help="Replace one direction's model by a mount file. Repeatable.")
@click.option("--move", multiple=True, metavar="MOUNT=DX,DY,DZ",
              help="Shift a mount point [mm, engine axes]. Repeatable.")
@click.option("--rotate", multiple=True, metavar="MOUNT=AX,AY,AZ",
              help="Rotate a mount's axes about engine X, then Y, then Z [deg]. Repeatable.")
@click.option("--effect", multiple=True, metavar="NAME[:PARAM=VALUE,...]",
              help="Add an unmodelled effect of the diagnosis library, e.g. "
                   "mount_stiffness:k1=1.5 or base_compliance:c_base=400N/mm,m_base=8kg "
                   "(see `powertrain diagnose`). Repeatable.")
@click.option("--variants", "variants_file", type=click.Path(dir_okay=False),
              help="TOML file of named variants ([[variant]] name = ..., scale = [...], ...).")
@click.option("--target", multiple=True, metavar="MOUNT.DIR:CHANGE:BAND[:WIDTH]",
              help="Retune to a K_CP change over a band, e.g. left.z:+20%:100-300Hz "
                   "(blend 0.5 octave outside, or :1oct); each target is its own variant.")
@click.option("--target-out", type=click.Path(dir_okay=False),
              help="Write the fitted mount file of the (single) target.")
@click.option("--target-plot", type=click.Path(dir_okay=False),
              help="PNG of baseline, requested and fitted K_CP of the (single) target.")
@click.option("--measured", "measured_file", type=click.Path(dir_okay=False),
              help="Measured run-up (CSV or HDF5, as for `compare`) to overlay.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="PNG overlay of baseline, variants (and measurement).")
@click.option("--delta-plot", type=click.Path(dir_okay=False),
              help="PNG of each variant's change against the baseline, 20 log10(v/v0) [dB].")
@click.option("--json", "json_file", type=click.Path(dir_okay=False),
              help="Write the changes as JSON.")
@click.option("--signal", type=click.Choice(["velocity", "mount_force"]), default="velocity",
              show_default=True,
              help="Compared signal: mount-point velocity or force transmitted to ground.")
@click.option("--objective", metavar="CHANNEL.DIR:QUANTITY:FROM-TO",
              help="Response to minimise, e.g. seat_rail.z:order_2:1500-3000 (a body point), "
                   "left/passive.z:synthesis:1000-6000 (body side of a mount) or left.z:...; "
                   "ranks the variants by the mean change over the band [rpm].")
@click.option("--workers", type=int, default=None,
              help="Processes for the variants (default: all local cores; 1 = serial).")
@click.option("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
              help="Run the variants on dask.distributed: 'local' (a LocalCluster on this "
                   "machine's cores) or an existing scheduler's address; also 'processes' "
                   "or 'serial'. Default: a local process pool (--workers). Same results.")
@click.option("--quiet", is_flag=True, help="No progress bar and no table.")
def whatif(engine_file, rpm_from, rpm_to, rpm_step, solver, scale, set_, swap, move, rotate,
           effect, variants_file, target, target_out, target_plot, measured_file, plot, json_file,
           delta_plot, signal, objective, workers, scheduler, quiet):
    """What-if: run the baseline and variants of the mount system, print the change in dB.

    The command-line operations (--scale/--set/--swap/--move/--rotate/--effect) form one
    variant,
    "command line"; each --target is a variant of its own; --variants adds the variants of
    a file. For each channel (mount x engine X/Y/Z) and quantity (synthesis, 2nd, 4th order)
    the change 20 log10(v_variant/v_baseline) is averaged over the speed steps (mean) and
    its largest magnitude reported (max|d|).

    \b
    Examples:
      powertrain whatif --scale left.z.stiffness=1.2
      powertrain whatif --scale "*.*.dynamic=0.9" --set right.y.c2=150 --json out.json
      powertrain whatif --move gearbox=0,0,10 --rotate left=0,0,5 --plot whatif.png
      powertrain whatif --target left.z:+20%:100-300Hz --target-out left-z-retuned.toml
      powertrain whatif --variants variants.toml --measured measured.csv --plot w.png
      powertrain whatif --effect mount_stiffness:k1=1.5,k2=1.5 --effect sensor_error:g3=2
      powertrain whatif --engine engines/default-modal-body.toml --scale left.z.stiffness=0.8 \\
          --objective seat_rail.z:order_2:1500-3000
    """
    from powertrain.errors import InputError
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.workflows.variants import (
        Origin,
        Variant,
        check_operations,
        parse_operations,
        parse_target,
        read_variants,
    )

    rpm = speed_steps(rpm_from, rpm_to, rpm_step)
    if workers is not None and workers < 1:
        raise InputError("must be >= 1", key="--workers")
    check_outputs(target_out=target_out, target_plot=target_plot, plot=plot, json=json_file,
                  delta_plot=delta_plot)
    engine = read_engine(engine_file or DEFAULT_ENGINE_PATH)
    runup_settings(engine, rpm, 1.0)

    variants = []
    ops = parse_operations({"scale": scale, "set": set_, "swap": swap, "move": move,
                            "rotate": rotate, "effect": effect})
    if ops:
        variants.append(Variant("command line", ops))
    for text in target:
        op = parse_target(text, Origin("--target"))
        variants.append(Variant(f"target {text}", (op,)))
    if variants_file:
        variants += read_variants(variants_file)
    if not variants:
        raise InputError("no variant given (use --scale, --set, --swap, --move, --rotate, "
                         "--effect, --target or --variants)", key="--variants")
    names = [v.name for v in variants]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"duplicate variant name {dup[0]!r}", file=variants_file,
                         key="variant.name")
    for v in variants:
        check_operations(engine, v.operations)
        _check_variant_support(engine, v)
    n_targets = sum(len(v.targets) for v in variants)
    for opt, value in (("--target-out", target_out), ("--target-plot", target_plot)):
        if value and n_targets != 1:
            raise InputError(f"needs exactly one target, {n_targets} given", key=opt)
    measured = None
    if measured_file:
        from powertrain.iotools.measured import read_measured
        measured = read_measured(measured_file, mounts=engine.mount_names)

    goal = _objective(objective, engine.assemble().channels, rpm) if objective else None
    from powertrain.workflows.whatif import run_whatif
    if scheduler:
        from powertrain.parallel import check_scheduler, executor
        with executor(check_scheduler(scheduler), workers=workers,
                      n_jobs=len(variants) + 1) as ex:
            result = run_whatif(engine, variants, rpm, solver=solver, executor=ex,
                                workers=workers, measured=measured, signal=signal,
                                progress=not quiet)
    else:
        result = run_whatif(engine, variants, rpm, solver=solver, workers=workers,
                            measured=measured, signal=signal, progress=not quiet)
    if goal is not None:
        result.objective = goal

    written = []
    if target_out:
        from powertrain.iotools.mount_file import write_mount
        tf = result.target_fits[0]
        write_mount(tf.model, target_out, comment=f"powertrain whatif: {tf.summary()}")
        written.append(target_out)
    from powertrain.cli.common import cli_provenance, engine_description, write_plot
    prov = cli_provenance(engine_description(engine, engine.file))
    if target_plot:
        write_plot(lambda p: result.target_fits[0].plot(path=p, provenance=prov), target_plot)
        written.append(target_plot)
    if json_file:
        from powertrain.provenance import provenance
        write_json(json_file, result.to_json(),
                   provenance(engine, engine_file=engine_file or DEFAULT_ENGINE_PATH))
        written.append(json_file)
    if plot:
        write_plot(lambda p: result.plot(path=p, provenance=prov), plot)
        written.append(plot)
    if delta_plot:
        write_plot(lambda p: result.plot(path=p, provenance=prov, view="delta"), delta_plot)
        written.append(delta_plot)
    if quiet:
        return
    modes = ", ".join(f"{f:.2f}" for f in result.baseline.rigid_body_modes_hz)
    click.echo(f"baseline: {engine.name} ({engine.file}), solver {solver}, "
               f"{rpm[0]:g}-{rpm[-1]:g} rpm step {rpm_step:g}")
    click.echo(f"baseline {RIGID_BODY_MODES_LABEL}: {modes}")
    for tf in result.target_fits:
        click.echo(tf.summary())
    click.echo(f"change of RMS {signal.replace('_', ' ')} vs baseline, 20 log10(v/v0) [dB]: "
               "mean over speeds / max |d|")
    click.echo(result.table())
    if result.objective is not None:
        click.echo(result.objective_text())
    if written:
        click.echo(f"wrote {', '.join(written)}")


def _objective(text, channels, rpm):
    """Parse ``CHANNEL.DIR:QUANTITY:FROM-TO`` against the model's channels."""
    import numpy as np

    from powertrain.analysis.orders import ORDERS
    from powertrain.errors import InputError
    from powertrain.iotools.measured import normalise_quantity
    form = "CHANNEL.DIR:QUANTITY:FROM-TO, e.g. seat_rail.z:order_2:1500-3000"
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 3 or "." not in parts[0] or "-" not in parts[2]:
        raise InputError(f"expected {form}, got {text!r}", key="--objective")
    name, d = parts[0].rsplit(".", 1)
    d = d.lower()
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


def _check_variant_support(engine, variant) -> None:
    """Each mount operation must leave mounts that carry the body (finite, plausible
    rigid-body modes); the error names the option or variants-file key at fault."""
    from powertrain.errors import InputError
    from powertrain.iotools.engine_checks import check_support
    from powertrain.workflows.variants import Target
    for op in variant.operations:
        if isinstance(op, Target) or not hasattr(op, "apply"):
            continue
        engine = op.apply(engine)
        try:
            check_support(engine, None)
        except InputError as exc:
            raise op.origin.error(f"variant {variant.name!r}: {exc.message}") from None
