"""Provenance of a result: what ran, how it was asked for, with which version and when.

Written into every HDF5 (attribute ``provenance``) and JSON (key ``provenance``) output:

* ``command_line``: the command as typed (``powertrain runup --no-balancers ...``);
* ``powertrain_version``, ``created`` (UTC, ISO 8601);
* ``engine_file``: the engine file read;
* ``engine_as_run``: the engine that actually ran, in SI, after the command's modifications
  (``--no-balancers`` shows as ``balancer.enabled = false``), every mount model by topology
  and parameters;
* ``modifications``: what the command changed on the engine as read, and ``effects``: the
  unmodelled effects applied (name and SI parameters).
"""

from __future__ import annotations

import dataclasses
import math
import shlex
import sys
from datetime import datetime, timezone

import numpy as np

#: Arrays longer than this are summarised (shape, min, max) instead of listed.
MAX_LISTED = 64

#: The command line of the running CLI command (set by :mod:`powertrain.cli`).
COMMAND_LINE: list[str] = []


def command_line() -> str:
    """The command as typed: the CLI's record, else ``sys.argv``."""
    argv = COMMAND_LINE or ["powertrain", *sys.argv[1:]]
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
                      "directions": {d: {"model": mdl.topology.name, "params_si": jsonable(mdl.params),
                                         "source": mdl.source}
                                     for d, mdl in m.directions.items()}}
                     for m in engine.mounts]
    return doc


def provenance(engine=None, *, engine_file=None, modifications=(), effects=None) -> dict:
    """The provenance record (see the module docstring)."""
    from powertrain import __version__
    doc = {"command_line": command_line(), "powertrain_version": __version__,
           "created": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    if engine is not None:
        doc["engine_file"] = str(engine_file or getattr(engine, "file", ""))
        doc["engine_name"] = getattr(engine, "name", "")
        doc["modifications"] = list(modifications)
        doc["effects"] = jsonable(effects or {})
        doc["engine_as_run"] = engine_as_run(engine)
    return doc
