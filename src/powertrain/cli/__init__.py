"""Command line: ``powertrain <command>``. Thin: parses, calls the library, prints.

Each command lives in its own module.
Exit codes: 0 success, 1 bad input (one line on stderr naming file and key), 2 usage error.
"""

from __future__ import annotations

from powertrain.cli import (
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
from powertrain.cli.group import main

__all__ = ["main"]


#: The command modules: importing each adds its commands to :func:`main` (``@main.command``).
COMMAND_MODULES = (compare, diagnose, examples, excitation, fit_mount, modes, runup, static,
                   stiffness, track, whatif)
