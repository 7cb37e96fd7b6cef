"""Reading a manoeuvre file (TOML): crank speed and load tables of a transient.

Sections ``[manoeuvre]`` (name, gear_ratio, crank_inertia, reversal), ``[speed]`` and
``[load]`` (time tables), optional ``[starter]``: docs/guide/transient.md. Every check runs
here, before any work; sizes are bounded (:data:`MAX_ROWS`, :data:`MAX_DURATION`,
:data:`MAX_GAP`).
"""

from __future__ import annotations

import numpy as np

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
from powertrain.units import UNITS

#: Most rows of a table.
MAX_ROWS = 4096
#: Longest manoeuvre [s] and longest interval between two rows of a table [s].
MAX_DURATION = 60.0
MAX_GAP = 5.0
#: Largest crank speed [rpm] and IMEP scale [-].
MAX_RPM = 12000.0
MAX_IMEP_SCALE = 2.0
#: Largest mean torque magnitude [N·m] and gear ratio [-].
MAX_TORQUE = 5000.0
MAX_GEAR_RATIO = 50.0

_SECTIONS = ("manoeuvre", "speed", "load", "starter")


def read_manoeuvre(path) -> Manoeuvre:
    """Read and check a manoeuvre file (docs/guide/transient.md).

    Raises
    ------
    InputError
        One line naming the file and the key: a missing or unknown key, a table whose
        times do not start at 0 or do not increase, a gap, a negative speed where no
        reversal is allowed, a profile longer than :data:`MAX_DURATION`.
    """
    path = str(path)
    doc = read_toml(path)
    check_keys(doc, _SECTIONS, path, "")
    head = subtable(doc, "manoeuvre", path)
    check_keys(head, ("name", "notes", "gear_ratio", "crank_inertia", "reversal"), path,
               "manoeuvre")
    reversal = get(head, "reversal", path, "manoeuvre", default=False, types=bool)
    time, speed = _speed_table(subtable(doc, "speed", path), path, reversal)
    load_time, load, kind = _load_table(subtable(doc, "load", path), path, time[-1])
    gear = scalar_quantity(head, "gear_ratio", "dimensionless", path, "manoeuvre",
                           default=0.0, nonneg=True)
    if gear > MAX_GEAR_RATIO:
        raise InputError(f"at most {MAX_GEAR_RATIO:g}", file=path, key="manoeuvre.gear_ratio")
    inertia = scalar_quantity(head, "crank_inertia", "inertia", path, "manoeuvre",
                              default=0.0, nonneg=True)
    starter = _starter(doc["starter"], path, time[-1]) if "starter" in doc else None
    return Manoeuvre(str(get(head, "name", path, "manoeuvre", default="manoeuvre",
                             types=str)),
                     time, speed, load_time, load, kind, gear, inertia, starter, reversal,
                     path, str(get(head, "notes", path, "manoeuvre", default="", types=str)))


def _table(section, key, dimension, path, prefix):
    """One column of a table in SI, bounded in length."""
    if not isinstance(section.get(key), dict) or not isinstance(section[key].get("value"),
                                                                 list):
        get(section, key, path, prefix)                 # missing: named
        raise InputError('expected {value = [...], unit = "..."}', file=path,
                         key=f"{prefix}.{key}")
    n = len(section[key]["value"])
    if not 2 <= n <= MAX_ROWS:
        raise InputError(f"{n} rows; 2..{MAX_ROWS} allowed", file=path,
                         key=f"{prefix}.{key}.value")
    return array_quantity(section, key, dimension, path, prefix, (n,))


def _times(section, path, prefix, rows):
    """The time column: from 0, strictly increasing, no gap, bounded."""
    t = _table(section, "time", "time", path, prefix)
    key = f"{prefix}.time"
    if t.size != rows:
        raise InputError(f"{t.size} times for {rows} values", file=path, key=key)
    if t[0] != 0.0:
        raise InputError(f"must start at 0 s, starts at {t[0]:g} s", file=path, key=key)
    step = np.diff(t)
    if np.any(step <= 0):
        i = int(np.argmax(step <= 0)) + 1
        raise InputError(f"times must increase (row {i + 1}: {t[i]:g} s after {t[i - 1]:g} s)",
                         file=path, key=key)
    if t[-1] > MAX_DURATION:
        raise InputError(f"a {t[-1]:g} s profile; at most {MAX_DURATION:g} s", file=path,
                         key=key)
    if np.max(step) > MAX_GAP:
        i = int(np.argmax(step))
        raise InputError(f"a gap of {step[i]:g} s after {t[i]:g} s; rows at most "
                         f"{MAX_GAP:g} s apart", file=path, key=key)
    return t


def _speed_table(section, path, reversal):
    check_keys(section, ("time", "speed"), path, "speed")
    speed = _table(section, "speed", "angular_speed", path, "speed")
    time = _times(section, path, "speed", speed.size)
    if not reversal and np.any(speed < 0):
        raise InputError("negative speed but the manoeuvre allows no reversal (set "
                         "manoeuvre.reversal = true)", file=path, key="speed.speed")
    top = MAX_RPM * UNITS["rpm"][1]
    if np.max(np.abs(speed)) > top:
        raise InputError(f"at most {MAX_RPM:g} rpm", file=path, key="speed.speed")
    return time, speed


def _load_table(section, path, duration):
    kinds = [k for k in LOAD_KINDS if k in section]
    check_keys(section, ("time",) + LOAD_KINDS, path, "load")
    if len(kinds) != 1:
        raise InputError(f"{'missing' if not kinds else 'two load columns'} (one of "
                         f"{', '.join(LOAD_KINDS)})", file=path, key="load")
    kind = kinds[0]
    dimension, bound = (("dimensionless", MAX_IMEP_SCALE) if kind == "imep_scale"
                        else ("torque", MAX_TORQUE))
    value = _table(section, kind, dimension, path, "load")
    time = _times(section, path, "load", value.size)
    if kind == "imep_scale" and np.any(value < 0):
        raise InputError("must not be negative", file=path, key="load.imep_scale")
    if np.max(np.abs(value)) > bound:
        raise InputError(f"at most {bound:g} in magnitude", file=path, key=f"load.{kind}")
    if time[-1] < duration - 1e-12:
        raise InputError(f"ends at {time[-1]:g} s, before the speed table's "
                         f"{duration:g} s (a gap)", file=path, key="load.time")
    return time, value, kind


def _starter(section, path, duration):
    if not isinstance(section, dict):
        raise InputError("expected a table", file=path, key="starter")
    check_keys(section, ("ratio", "reaction_point", "until"), path, "starter")
    ratio = scalar_quantity(section, "ratio", "dimensionless", path, "starter", positive=True)
    point = vector3(section, "reaction_point", "length", path, "starter")
    until = scalar_quantity(section, "until", "time", path, "starter", nonneg=True)
    if until > duration:
        raise InputError(f"after the end of the manoeuvre ({duration:g} s)", file=path,
                         key="starter.until")
    return Starter(ratio, point, until)
