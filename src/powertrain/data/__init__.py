"""Files shipped with the package: the default engine, the mount files and the examples.

In a source checkout ``engines/``, ``mounts/`` and ``examples/`` at the top of the repository
are the single copy; ``src/powertrain/data/{engines,mounts,examples}`` are symbolic links to
them, and the wheel carries the files themselves (``[tool.setuptools.package-data]``). Found
with :mod:`importlib.resources`, so an installed package finds them from any directory. The
engine file names its mount files relative to itself (``../mounts/...``), which holds in both
layouts.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: Folders shipped as package data.
FOLDERS = ("engines", "mounts", "examples")


def shipped_path(*parts: str) -> Path:
    """Path of a shipped file, e.g. ``shipped_path("engines", "default.toml")``."""
    return Path(str(resources.files(__name__).joinpath(*parts)))


def default_engine_path() -> Path:
    """The shipped default engine, ``engines/default.toml``."""
    return shipped_path("engines", "default.toml")


def shipped_files(folder: str) -> list[Path]:
    """Sorted files of one shipped folder (``engines``, ``mounts`` or ``examples``)."""
    if folder not in FOLDERS:
        raise ValueError(f"no shipped folder {folder!r}; one of {', '.join(FOLDERS)}")
    return sorted(p for p in shipped_path(folder).iterdir() if p.is_file())
