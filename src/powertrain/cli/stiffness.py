"""``powertrain stiffness``: dynamic stiffness of a mount model."""

from __future__ import annotations

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    plot_form_options,
    quiet_option,
    say,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.errors import InputError
from powertrain.workflows.stiffness import stiffness as run


@main.command()
@click.argument("mount_file", required=False)  # checked by read_mount: one-line errors, exit 1
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Take the mount model from an engine file instead (with --mount).")
@click.option("--mount", "mount_dir", metavar="MOUNT.DIR",
              help="Mount and local direction of --engine, e.g. torque_rod.x (network file or "
                   "inline spring-damper).")
@click.option("--freq", default="1:400:1", show_default=True,
              help="Frequencies [Hz]: list 5,10,20 and/or range start:stop:step.")
@click.option("--method", type=click.Choice(["frequency", "time"]), default="frequency", show_default=True,
              help="frequency: condensed network (eq. 39); time: Newmark integration + FFT.")
@click.option("--format", "fmt", type=click.Choice(["table", "csv"]), default="table", show_default=True,
              help="Printed output: the table of every frequency, or CSV (with --plot and "
                   "no --format: a short summary instead).")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write a K*(f) plot (PNG); prints a summary (|K*| range, loss-angle peak) "
                   "and the path instead of the full table unless --format is given.")
@plot_form_options
@click.option("--amplitude", metavar="LIST",
              help="Displacement test amplitudes in the mount file's x unit (mm by default), "
                   "e.g. 0.05,0.1,0.5: K*(f, X) per amplitude with the amplitude law and "
                   "friction; the CSV gains a first column amplitude_mm.")
@click.option("--engine-mass", type=float, help="Engine mass on the mount [kg] (verification set-up).")
@click.option("--force", type=float, help="Harmonic force amplitude on the engine mass [N].")
@quiet_option
def stiffness(mount_file, engine_file, mount_dir, freq, method, fmt, plot, form, freq_axis,
              amplitude, engine_mass, force, quiet):
    """Cross-point dynamic stiffness K*(f) of MOUNT_FILE: real, imaginary, magnitude, loss angle.

    With --engine-mass and --force it reproduces the thesis's verification set-up (a harmonic
    force on an engine mass carried by the mount, Kovarik 2016 sec. 3.2) and adds the
    engine-mass displacement x1 and the transmitted force F_T. The engine mass moves under the
    input-point stiffness; the ground sees the cross-point one.

    \b
    Examples:
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --freq 1:400:1 --plot k.png
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --plot k.png \\
          --form real-imag --freq-axis linear
      powertrain stiffness mounts/thesis-appendix-a.toml --freq 5,10,12,15,17,20,25,30,40 \\
          --engine-mass 100 --force 100 --method time --format csv
      powertrain stiffness --engine engines/default-torque-rod.toml --mount torque_rod.x
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --amplitude 0.05,0.1,0.5 \\
          --method time --freq 1:100:1 --plot k.png
    """
    check_outputs(plot=plot)
    mount = _mount(mount_file, engine_file, mount_dir)
    result = run(mount, engine=engine_file, freq=freq, method=method,
                 engine_mass=engine_mass, force=force, amplitude=amplitude)
    _report(result, fmt, plot, form, freq_axis, quiet)


def _report(result, fmt, plot, form, freq_axis, quiet):
    """Write the plot (when asked); print the table, the CSV or the plot's summary."""
    if plot:
        prov = cli_provenance()
        write_plot(lambda p: result.plot(path=p, form=form, freq_axis=freq_axis, provenance=prov), plot)
    explicit = click.get_current_context().get_parameter_source("fmt").name != "DEFAULT"
    if plot and not explicit:
        say(result.summary(), quiet)
    else:
        say(result.to_csv() if fmt == "csv" else result.to_text(), quiet, nl=False)
    if plot:   # on stderr when stdout carries CSV (often redirected to a file)
        say(wrote(plot), quiet, err=explicit and fmt == "csv")


def _mount(mount_file, engine_file, mount_dir):
    """The ``mount`` of the stiffness workflow: MOUNT_FILE, or --mount of --engine."""
    if (mount_file is None) == (engine_file is None):
        raise InputError("give either MOUNT_FILE or --engine with --mount", key="MOUNT_FILE")
    if mount_file is not None and mount_dir:
        raise InputError("--mount goes with --engine", key="--mount")
    return mount_file if mount_file is not None else mount_dir
