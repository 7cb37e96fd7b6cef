"""Retired: use ``powertrain modes --static`` (or ``powertrain modes`` for the damped modes).

Kept as a shim so older notes that call it still work; it runs ``powertrain modes --static``.

Usage: python scripts/engine_rigid_body_modes.py [ENGINE_FILE]
"""

from __future__ import annotations

import sys

from powertrain.cli import main as cli

if __name__ == "__main__":
    engine = sys.argv[1:2]
    cli(["modes", "--static"] + (["--engine", engine[0]] if engine else []))
