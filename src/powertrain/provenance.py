"""Provenance of a result: what ran, how it was asked for, with which version and when.

:func:`provenance` is the record in every HDF5 and JSON output (``provenance``; keys in
docs/reference/outputs.md); :class:`Provenance` its short form, one line at the foot of every
figure.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import math
import shlex
import sys
from datetime import datetime, timezone

import numpy as np

from powertrain import __version__

#: Arrays longer than this are summarised (shape, min, max) instead of listed.
MAX_LISTED = 64
#: The command line of the running CLI command (:func:`recording_command`), or None.
_COMMAND_LINE: contextvars.ContextVar[tuple | None] = contextvars.ContextVar(
    "powertrain_command_line", default=None)


@contextlib.contextmanager
def recording_command(argv):
    """Within the block, :func:`command_line` is ``argv`` (as typed, program name first)."""
    token = _COMMAND_LINE.set(tuple(str(a) for a in argv))
    try:
        yield
    finally:
        _COMMAND_LINE.reset(token)


def stamp_hdf5(attrs, file_format: str) -> None:
    """Set the root ``attrs`` of every HDF5 file: ``format`` (``file_format``),
    ``format_version`` (1), ``powertrain_version``, ``created`` (UTC, ISO 8601)."""
    attrs["format"] = file_format
    attrs["format_version"] = 1
    attrs["powertrain_version"] = __version__
    attrs["created"] = datetime.now(timezone.utc).isoformat(timespec="seconds")


def command_line() -> str:
    """The command as typed (:func:`recording_command`, else ``sys.argv``)."""
    argv = _COMMAND_LINE.get() or ["powertrain", *sys.argv[1:]]
    return shlex.join(str(a) for a in argv)


def jsonable(x, depth: int = 0):
    """Plain JSON value of ``x``: dataclasses as dicts, arrays as lists, non-finite as null."""
    if depth > 8:
        return repr(x)
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {f.name: jsonable(getattr(x, f.name), depth + 1)
                for f in dataclasses.fields(x) if not f.name.startswith("_") and f.repr}
    if isinstance(x, dict):
        return {str(k): jsonable(v, depth + 1) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v, depth + 1) for v in x]
    if isinstance(x, np.ndarray):
        if x.size > MAX_LISTED:
            finite = x[np.isfinite(x)] if np.issubdtype(x.dtype, np.number) else x
            return {"shape": list(x.shape),
                    "min": jsonable(finite.min()) if finite.size else None,
                    "max": jsonable(finite.max()) if finite.size else None}
        return jsonable(x.tolist(), depth + 1)
    if isinstance(x, (np.generic,)):
        return jsonable(x.item(), depth)
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, (bool, int, str)) or x is None:
        return x
    return repr(x)


def engine_as_run(engine) -> dict:
    """The engine as simulated (SI), mount models as topology name and parameters."""
    doc = jsonable(engine)
    doc["mounts"] = [{"name": m.name, "position_m": jsonable(m.position),
                      "rotation": jsonable(m.rotation), "files": dict(m.files),
                      "directions": {d: {"model": mdl.topology.name,
                                         "params_si": jsonable(mdl.params), "source": mdl.source}
                                     for d, mdl in m.directions.items()}}
                     for m in engine.mounts]
    return doc


def provenance(engine=None, *, engine_file=None, modifications=(), effects=None) -> dict:
    """The provenance record: ``command_line``, ``powertrain_version``, ``created`` and, with
    ``engine``, ``engine_file``, ``engine_name``, ``modifications``, ``effects`` and
    ``engine_as_run`` (SI)."""
    doc = {"command_line": command_line(), "powertrain_version": __version__,
           "created": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    if engine is not None:
        doc["engine_file"] = str(engine_file or getattr(engine, "file", ""))
        doc["engine_name"] = getattr(engine, "name", "")
        doc["modifications"] = list(modifications)
        doc["effects"] = jsonable(effects or {})
        doc["engine_as_run"] = engine_as_run(engine)
    return doc


@dataclasses.dataclass(frozen=True)
class Provenance:
    """Program, command, engine and date of one result.

    Attributes
    ----------
    command : str
        The command line as typed, or a description of the library call ("" if unknown).
    engine : str
        Name, file and changes (``"EA888-like (engines/default.toml), balancers off"``);
        "" without an engine.
    version : str
        ``powertrain`` version.
    date : str
        UTC, ISO 8601 to the second (``2026-11-23T18:30:00Z``).
    """

    command: str = ""
    engine: str = ""
    version: str = ""
    date: str = ""

    @classmethod
    def now(cls, command: str = "", engine: str = "") -> Provenance:
        """A provenance stamped with the current UTC time and this version."""
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        return cls(command=command, engine=engine, version=__version__, date=stamp)

    @classmethod
    def from_record(cls, record: dict) -> Provenance:
        """The short form of a :func:`provenance` record."""
        engine = record.get("engine_name", "")
        if record.get("engine_file"):
            engine += f" ({record['engine_file']})"
        mods = list(record.get("modifications", [])) + list(record.get("effects", {}) or {})
        if mods:
            engine += ", " + ", ".join(str(m) for m in mods)
        return cls(command=record.get("command_line", ""), engine=engine.strip(),
                   version=record.get("powertrain_version", ""),
                   date=str(record.get("created", "")).replace("+00:00", "Z"))

    def line(self) -> str:
        """One line for a figure foot: ``powertrain 0.1.0 · 2026-11-23 18:30 UTC · engine:
        ... · $ command``."""
        parts = [f"powertrain {self.version or __version__}"]
        if self.date:
            parts.append(self.date.replace("T", " ").replace("Z", " UTC"))
        if self.engine:
            parts.append(f"engine: {self.engine}")
        if self.command:
            parts.append(f"$ {self.command}")
        return "  ·  ".join(parts)

    def to_dict(self) -> dict:
        """Plain dict (for JSON and HDF5 attributes)."""
        return dataclasses.asdict(self)
