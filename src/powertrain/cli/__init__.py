"""Command line ``powertrain <command>``, one module per command: parses, calls the library,
prints. Exit codes: 0 success, 1 bad input (one line on stderr naming file and key), 2 usage.
"""

from __future__ import annotations

from powertrain.cli.group import COMMANDS, main

__all__ = ["COMMANDS", "main"]
