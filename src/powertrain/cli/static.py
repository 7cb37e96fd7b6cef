"""``powertrain static``: the static operating point of the powertrain on its mounts per
speed."""

from __future__ import annotations

import click

from powertrain.cli.common import check_outputs, quiet_option, say, write_json, wrote
from powertrain.cli.group import main
from powertrain.iotools.engine_file import engine_or_default
from powertrain.provenance import provenance
from powertrain.workflows.arguments import speeds
from powertrain.workflows.static import static as solve


@main.command()
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@click.option("--rpm", "rpm_list", metavar="LIST",
              help="Speeds [rpm]: a comma list or start:stop:step, e.g. 1000:6000:500 "
                   "(default: the run-up's, 1000 to 6000 step 500).")
@click.option("--json", "json_file", type=click.Path(dir_okay=False),
              help="Write the operating points as JSON.")
@quiet_option
def static(engine_file, rpm_list, json_file, quiet):
    """Static operating point per speed: the body under its weight and the mean
    drive-torque reaction (gear ratio of [drive] times the mean brake torque) on the
    mounts' static curves (a direction without [static] acts with its network's static
    stiffness). Prints the body's displacement [mm] and rotation [deg] at the CG and each
    mount's deflection [mm], force [N], tangent stiffness [N/mm] and static factor per
    local direction.

    \b
    Examples:
      powertrain static
      powertrain static --rpm 1000,3000,6000 --json static.json
    """
    rpm = speeds(rpm_list)
    check_outputs(json=json_file)
    engine = engine_or_default(engine_file)
    result = solve(engine, rpm)
    if json_file:
        write_json(json_file, result.to_json(), provenance(engine))
    say(result.to_text(), quiet)
    if json_file:
        say(wrote(json_file), quiet)
