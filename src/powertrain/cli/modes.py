"""``powertrain modes``: the rigid-body modes of the powertrain on its mounts."""

from __future__ import annotations

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    say,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.iotools.engine_file import engine_or_default
from powertrain.workflows.modes import modes as solve_modes


@main.command()
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml); only [engine], "
                   "[body] and [mounts.*] are needed.")
@click.option("--static", is_flag=True,
              help="Static (0 Hz) mount stiffness, undamped (default: each mode with the "
                   "networks' dynamic stiffness at its own frequency, damped).")
@click.option("--json", "json_file", type=click.Path(dir_okay=False), help="Write the modes as JSON.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write the kinetic-energy distribution per mode (PNG).")
@quiet_option
def modes(engine_file, static, json_file, plot, quiet):
    """Six rigid-body modes: frequency, damping ratio, dominant coordinate, kinetic-energy
    distribution [%] over x, y, z, rx, ry, rz about the CG in engine axes, and the angle of
    each mode's rotation axis to the torque-roll axis.

    \b
    Examples:
      powertrain modes
      powertrain modes --engine engines/default-torque-rod.toml --json modes.json
      powertrain modes --static --plot modes.png
    """
    check_outputs(json=json_file, plot=plot)
    engine = engine_or_default(engine_file)
    result = solve_modes(engine, static=static)
    if json_file:
        result.write_json(json_file)
    if plot:
        prov = cli_provenance(engine_description(engine, engine.file))
        write_plot(lambda p: result.plot(path=p, provenance=prov), plot)
    say(result.to_text(), quiet)
    if json_file or plot:
        say(wrote(json_file, plot), quiet)
