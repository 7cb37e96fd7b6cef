"""``powertrain whatif``: baseline vs variants of the mount system, change in dB."""

from __future__ import annotations

import click
from click.core import ParameterSource

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    speed_options,
    write_json,
    write_plot,
)
from powertrain.cli.group import main
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.mount_file import write_mount
from powertrain.provenance import provenance
from powertrain.workflows.arguments import speed_steps
from powertrain.workflows.whatif import RUNUP_ONLY, refuse_runup_options
from powertrain.workflows.whatif import whatif as run_whatif


@main.command()
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@speed_options
@click.option("--solver", type=click.Choice(["harmonic", "newmark"]), default="harmonic", show_default=True,
              help="harmonic: exact steady state of the linear model, fast; newmark: time "
                   "integration as in `runup`.")
@click.option("--scale", multiple=True, metavar="MOUNT.DIR.KIND=FACTOR",
              help="Scale springs (stiffness), dampers (damping) or c, d and m together "
                   "(dynamic: K_CP(f) x FACTOR), or a law of the mount file "
                   "(left.z.amplitude.exponent=0.5, friction.max_force, static.force...); "
                   "MOUNT/DIR may be *. Repeatable.")
@click.option("--set", "set_", multiple=True, metavar="MOUNT.DIR.PARAM=VALUE",
              help="Set one parameter in its datasheet unit (c N/mm, d N*s/mm, m kg) or an "
                   "explicit unit (150N/mm), or a law value in the mount file's units "
                   "(left.z.friction.max_force=20 [N], amplitude.reference [mm], "
                   "amplitude.limits=0.2,5; creates [amplitude]/[friction]). Repeatable.")
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
@click.option("--target", multiple=True, metavar="MOUNT.DIR:CHANGE:BAND[:WIDTH][:AMPLITUDE]",
              help="Retune to a K_CP change over a band, e.g. left.z:+20%:100-300Hz "
                   "(blend 0.5 octave outside, or :1oct; at an amplitude of a mount with "
                   "an amplitude law or friction: :0.3mm); each target is its own variant.")
@click.option("--target-out", type=click.Path(dir_okay=False),
              help="Write the fitted mount file of the (single) target.")
@click.option("--target-plot", type=click.Path(dir_okay=False),
              help="PNG of baseline, requested and fitted K_CP of the (single) target.")
@click.option("--measured", "measured_file", type=click.Path(dir_okay=False),
              help="Measured run-up (CSV or HDF5, as for `compare`) to overlay.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="PNG overlay of baseline, variants (and measurement).")
@click.option("--delta-plot", type=click.Path(dir_okay=False),
              help="PNG of each variant's change against the baseline, 20 log10(v/v0) [dB]; "
                   "with --manoeuvre the change of its peaks [%].")
@click.option("--json", "json_file", type=click.Path(dir_okay=False), help="Write the changes as JSON.")
@click.option("--signal", type=click.Choice(["velocity", "mount_force"]), default="velocity",
              show_default=True, help="Compared signal: mount-point velocity or force transmitted to ground.")
@click.option("--objective", metavar="CHANNEL.DIR:QUANTITY:FROM-TO",
              help="Response to minimise, e.g. seat_rail.z:order_2:1500-3000 (a body point), "
                   "left.passive.z:synthesis:1000-6000 (body side of a mount; left/passive.z "
                   "is read too) or left.z:...; ranks the variants by the mean change over the band [rpm].")
@click.option("--workers", type=int, default=None,
              help="Processes for the variants (default: all local cores; 1 = serial).")
@click.option("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
              help="Run the variants on dask.distributed: 'local' (a LocalCluster on this "
                   "machine's cores) or an existing scheduler's address; also 'processes' "
                   "or 'serial'. Default: a local process pool (--workers). Same results.")
@click.option("--manoeuvre", "manoeuvre_file", type=click.Path(dir_okay=False),
              help="Run baseline and variants over this transient manoeuvre (TOML, as for "
                   "`transient`) instead of a run-up; ranks them by peak seat acceleration "
                   "(else peak mount deflection). The run-up's options (--from, --to, --step, "
                   "--solver, --signal, --objective, --measured, --workers, --scheduler, "
                   "--target-out, --target-plot) are refused with it.")
@quiet_option
def whatif(engine_file, rpm_from, rpm_to, rpm_step, solver, scale, set_, swap, move, rotate,
           effect, variants_file, target, target_out, target_plot, measured_file, plot, json_file,
           delta_plot, signal, objective, workers, scheduler, manoeuvre_file, quiet):
    """What-if: run the baseline and variants of the mount system, print the change in dB.

    The command-line operations (--scale/--set/--swap/--move/--rotate/--effect) form one
    variant, "command line"; each --target is a variant of its own; --variants adds the
    variants of a file. For each channel (mount x engine X/Y/Z) and quantity (synthesis, 2nd, 4th order)
    the change 20 log10(v_variant/v_baseline) is averaged over the speed steps (mean) and
    its largest magnitude reported (max|d|).

    \b
    Examples:
      powertrain whatif --scale left.z.stiffness=1.2
      powertrain whatif --scale "*.*.dynamic=0.9" --set right.y.c2=150 --json out.json
      powertrain whatif --move gearbox=0,0,10 --rotate left=0,0,5 --plot whatif.png
      powertrain whatif --target left.z:+20%:100-300Hz --target-out left-z-retuned.toml
      powertrain whatif --set left.z.amplitude.exponent=0.15 --set "*.z.friction.max_force=30"
      powertrain whatif --variants variants.toml --measured measured.csv --plot w.png
      powertrain whatif --effect mount_stiffness:k1=1.5,k2=1.5 --effect sensor_error:g3=2
      powertrain whatif --engine engines/default-modal-body.toml --scale left.z.stiffness=0.8 \\
          --objective seat_rail.z:order_2:1500-3000
      powertrain whatif --manoeuvre examples/start.toml --variants variants.toml
    """
    outputs = (target_out, target_plot, json_file, plot, delta_plot)
    _refuse_runup_options(click.get_current_context(), manoeuvre_file)
    check_outputs(target_out=target_out, target_plot=target_plot, plot=plot, json=json_file,
                  delta_plot=delta_plot)
    engine, rpm = _baseline(engine_file, rpm_from, rpm_to, rpm_step)
    runup = {} if manoeuvre_file else dict(
        rpm=rpm, solver=solver, signal=signal, objective=objective, measured=measured_file,
        executor=scheduler, workers=workers, rpm_step=rpm_step)
    result = run_whatif(engine, scale=scale, set=set_, swap=swap, move=move, rotate=rotate,
                        effects=effect, targets=target, variants=variants_file,
                        progress=not quiet, manoeuvre=manoeuvre_file, **runup)
    fit = result.target_fit("--target-out" if target_out else "--target-plot") \
        if target_out or target_plot else None
    _write(result, fit, engine, engine_file, *outputs)
    if not quiet:
        click.echo(result.to_text(written=outputs))


def _refuse_runup_options(ctx, manoeuvre_file) -> None:
    """With ``--manoeuvre``: a one-line error naming the first run-up option given on the
    command line (:data:`~powertrain.workflows.whatif.RUNUP_ONLY`), before any work."""
    if not manoeuvre_file:
        return
    names = {"measured_file": "measured"}
    given, keys = {}, {}
    for param in ctx.command.params:
        name = names.get(param.name, param.name)
        if name in RUNUP_ONLY and ctx.get_parameter_source(param.name) not in (
                ParameterSource.DEFAULT, ParameterSource.DEFAULT_MAP):
            given[name], keys[name] = True, max(param.opts, key=len)
    refuse_runup_options(given, "--manoeuvre", keys)


def _baseline(engine_file, rpm_from, rpm_to, rpm_step):
    """The baseline engine and the speed steps (checked against its range by the what-if)."""
    rpm = speed_steps(rpm_from, rpm_to, rpm_step)
    return read_engine(engine_file or DEFAULT_ENGINE_PATH), rpm


def _write(result, fit, engine, engine_file, target_out, target_plot, json_file, plot, delta_plot) -> None:
    """Write the files asked for, each atomically."""
    prov = cli_provenance(engine_description(engine, engine.file))
    if target_out:
        write_mount(fit.model, target_out, comment=f"powertrain whatif: {fit.summary()}")
    if target_plot:
        write_plot(lambda p: fit.plot(path=p, provenance=prov), target_plot)
    if json_file:
        write_json(json_file, result.to_json(),
                   provenance(engine, engine_file=engine_file or DEFAULT_ENGINE_PATH))
    if plot:
        write_plot(lambda p: result.plot(path=p, provenance=prov), plot)
    if delta_plot:
        write_plot(lambda p: result.plot(path=p, provenance=prov, view="delta"), delta_plot)
