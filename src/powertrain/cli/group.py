"""The ``powertrain`` command group: every command runs in one output transaction, and bad
input becomes one line on stderr and exit code 1 (imported by every command module)."""

from __future__ import annotations

import importlib
import sys

import click

from powertrain import __version__
from powertrain.cli.common import terminate_as_exit
from powertrain.errors import InputError
from powertrain.outputs import OutputTransaction
from powertrain.provenance import recording_command

#: Every command and the module of :mod:`powertrain.cli` that defines it (``@main.command``).
COMMANDS = {"compare": "compare", "diagnose": "diagnose", "examples": "examples",
            "excitation": "excitation", "fit-mount": "fit_mount", "modes": "modes",
            "report": "report", "runup": "runup", "static": "static", "stiffness": "stiffness",
            "synth": "diagnose", "track": "track", "transient": "transient", "whatif": "whatif"}


class _Group(click.Group):
    """Runs every command in one :class:`~powertrain.outputs.OutputTransaction`, an
    :class:`~powertrain.errors.InputError` as one line on stderr and exit code 1; loads a
    command's module only when it is asked for (:data:`COMMANDS`)."""

    def list_commands(self, ctx):
        return sorted(COMMANDS)

    def get_command(self, ctx, name):
        if name in COMMANDS and name not in self.commands:
            importlib.import_module(f"powertrain.cli.{COMMANDS[name]}")    # registers it
        return super().get_command(ctx, name)

    def main(self, args=None, *posargs, **kwargs):
        with recording_command(["powertrain", *(sys.argv[1:] if args is None else args)]):
            return super().main(args, *posargs, **kwargs)

    def invoke(self, ctx):
        try:
            with terminate_as_exit(), OutputTransaction():
                return super().invoke(ctx)
        except InputError as exc:
            click.echo(f"error: {exc.one_line()}", err=True)
            sys.exit(1)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="powertrain")
def main():
    """powertrain: powertrain mount vibration (NVH) simulator.

    \b
    Examples:
      powertrain examples .      # copies the shipped engines/, mounts/, examples/ here
      powertrain runup --from 1000 --to 6000 --step 500 --csv runup.csv --plot runup.png
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --freq 1:400:1 --plot k.png
      powertrain fit-mount measured.csv --model triple-parallel --out fitted.toml
      powertrain compare examples/measured-runup.csv --plot compare.png --json compare.json
      powertrain whatif --scale left.z.stiffness=1.2 --json whatif.json
      powertrain diagnose examples/measured-runup.csv --report diagnosis/
      powertrain modes --engine engines/default-torque-rod.toml --json modes.json
      powertrain track run.csv --csv tracked.csv --plot orders.png
      powertrain transient examples/start.toml --plot start.png --json start.json
      powertrain report examples/study.toml --out report.html
    """
