"""Command line: ``powertrain <command>``. Thin: parses, calls the library, prints.

Each command lives in its own module and imports the library lazily, so ``--help`` is fast.
Exit codes: 0 success, 1 bad input (one line on stderr naming file and key), 2 usage error.
"""

from __future__ import annotations

import sys

import click

from powertrain import __version__


class _Group(click.Group):
    """Turns :class:`powertrain.errors.InputError` into one line on stderr and exit code 1."""

    def invoke(self, ctx):
        from powertrain.errors import InputError
        try:
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
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --freq 1:400:1 --plot k.png
      powertrain fit-mount measured.csv --model triple-parallel --out fitted.toml
    """


def _register():
    from powertrain.cli import stiffness  # noqa: F401
    for name in ("fit_mount", "runup", "excitation", "compare", "diagnose", "whatif"):
        try:
            __import__(f"powertrain.cli.{name}")
        except ModuleNotFoundError as exc:  # command not built yet
            if exc.name != f"powertrain.cli.{name}":
                raise


_register()
