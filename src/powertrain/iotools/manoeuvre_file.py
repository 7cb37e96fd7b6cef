"""Manoeuvre files (TOML, docs/guide/transient.md): the crank speed and load tables of a
transient. Keys, units and table sizes are checked here, the values by
:class:`~powertrain.models.manoeuvre.Manoeuvre`.
"""

from __future__ import annotations

from powertrain.errors import InputError
from powertrain.iotools.tomlfile import (
    array_quantity,
    check_keys,
    get,
    read_toml,
    scalar_quantity,
    subtable,
    vector3,
)
from powertrain.models.manoeuvre import LOAD_KINDS, Manoeuvre, Starter

#: Most rows of a table.
MAX_ROWS = 4096

_SECTIONS = ("manoeuvre", "speed", "load", "starter")


def read_manoeuvre(path) -> Manoeuvre:
    """Read and check a manoeuvre file (docs/guide/transient.md).

    Raises
    ------
    InputError
        Naming the file and the key of the first problem (a table over :data:`MAX_ROWS`
        rows, any check of :class:`~powertrain.models.manoeuvre.Manoeuvre`).
    """
    path = str(path)
    doc = read_toml(path)
    check_keys(doc, _SECTIONS, path, "")
    head = subtable(doc, "manoeuvre", path)
    check_keys(head, ("name", "notes", "gear_ratio", "crank_inertia", "reversal",
                      "trigger_time"), path, "manoeuvre")
    reversal = get(head, "reversal", path, "manoeuvre", default=False, types=bool)
    time, speed = _columns(subtable(doc, "speed", path), ("speed",), "angular_speed", path, "speed")[:2]
    load_section = subtable(doc, "load", path)
    load_time, load, kind = _load_table(load_section, path)
    motored = (scalar_quantity(load_section, "motored_intake_pressure", "pressure", path,
                               "load", positive=True) if "motored_intake_pressure" in load_section else None)
    gear = scalar_quantity(head, "gear_ratio", "dimensionless", path, "manoeuvre", default=0.0, nonneg=True)
    inertia = scalar_quantity(head, "crank_inertia", "inertia", path, "manoeuvre", default=0.0, nonneg=True)
    trigger = scalar_quantity(head, "trigger_time", "time", path, "manoeuvre", default=0.0, nonneg=True)
    starter = _starter(doc["starter"], path) if "starter" in doc else None
    return Manoeuvre(str(get(head, "name", path, "manoeuvre", default="manoeuvre", types=str)),
                     time, speed, load_time, load, kind, gear, inertia, starter, reversal,
                     path, str(get(head, "notes", path, "manoeuvre", default="", types=str)),
                     motored, trigger)


def _table(section, key, dimension, path, prefix):
    """One column of a table in SI, bounded in length."""
    if not isinstance(section.get(key), dict) or not isinstance(section[key].get("value"), list):
        get(section, key, path, prefix)                 # missing: named
        raise InputError('expected {value = [...], unit = "..."}', file=path, key=f"{prefix}.{key}")
    n = len(section[key]["value"])
    if not 2 <= n <= MAX_ROWS:
        raise InputError(f"{n} rows; 2..{MAX_ROWS} allowed", file=path, key=f"{prefix}.{key}.value")
    return array_quantity(section, key, dimension, path, prefix, (n,))


def _columns(section, names, dimension, path, prefix):
    """``(time, value, name)`` of a table whose value column is the one of ``names``
    present (SI; the semantic checks are the model's, :class:`Manoeuvre`)."""
    check_keys(section, ("time",) + names + (("motored_intake_pressure",)
                                             if prefix == "load" else ()), path, prefix)
    present = [k for k in names if k in section]
    if len(present) > 1:
        raise InputError(f"two load columns (one of {', '.join(names)})", file=path, key=prefix)
    name = present[0] if present else names[0]
    if not present and len(names) > 1:
        raise InputError(f"missing (one of {', '.join(names)})", file=path, key=prefix)
    value = _table(section, name, dimension if isinstance(dimension, str) else dimension[name], path, prefix)
    time = _table(section, "time", "time", path, prefix)
    if time.size != value.size:
        raise InputError(f"{time.size} times for {value.size} values", file=path, key=f"{prefix}.time")
    return time, value, name


def _load_table(section, path):
    return _columns(section, LOAD_KINDS, {"imep_scale": "dimensionless",
                                          "mean_torque": "torque"}, path, "load")


def _starter(section, path):
    if not isinstance(section, dict):
        raise InputError("expected a table", file=path, key="starter")
    check_keys(section, ("ratio", "reaction_point", "until"), path, "starter")
    ratio = scalar_quantity(section, "ratio", "dimensionless", path, "starter", positive=True)
    point = vector3(section, "reaction_point", "length", path, "starter")
    until = scalar_quantity(section, "until", "time", path, "starter", nonneg=True)
    return Starter(ratio, point, until, path)
