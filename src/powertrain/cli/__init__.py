"""Command line: ``powertrain <command>``. Thin: parses, calls the library, prints.

Each command lives in its own module and imports the library lazily, so ``--help`` is fast.
Exit codes: 0 success, 1 bad input (one line on stderr naming file and key), 2 usage error.
"""

from __future__ import annotations

from powertrain.cli.group import main

__all__ = ["main"]


def _register():
    """Import the command modules: each adds its command to :func:`main`."""
    from powertrain.cli import (  # noqa: F401
        compare,
        diagnose,
        examples,
        excitation,
        fit_mount,
        modes,
        runup,
        static,
        stiffness,
        track,
        whatif,
    )


_register()
