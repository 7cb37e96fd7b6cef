"""Command line: ``powertrain <command>``. Thin: parses, calls the library, prints.

Each command lives in its own module.
Exit codes: 0 success, 1 bad input (one line on stderr naming file and key), 2 usage error.
"""

from __future__ import annotations

from powertrain.cli.group import COMMANDS, main

__all__ = ["COMMANDS", "main"]
