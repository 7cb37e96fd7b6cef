"""The ``[combustion]`` section of an engine file, in SI: ``model = "single-zone"`` with its
parameters and ``[combustion.full_load]``, or ``model = "measured"`` with ``traces`` (a
pressure-trace CSV relative to the engine file, :mod:`powertrain.iotools.pressure_csv`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.pressure_csv import read_pressure_traces
from powertrain.iotools.tomlfile import array_quantity, check_keys, get, quantity, scalar_quantity, subtable
from powertrain.models.combustion import FullLoadCurve, SingleZoneCombustion

#: ``[combustion]`` single-zone key -> (model field, dimension, check of the number).
_SINGLE_ZONE = {
    "ambient_pressure": ("ambient_pressure", "pressure", "positive"),
    "start": ("start", "angle", None),
    "duration": ("duration", "angle", "positive"),
    "wiebe_a": ("wiebe_a", "dimensionless", "positive"),
    "wiebe_m": ("wiebe_m", "dimensionless", "nonneg"),
    "polytropic_compression": ("n_compression", "dimensionless", "positive"),
    "polytropic_expansion": ("n_expansion", "dimensionless", "positive"),
    "exhaust_valve_opening": ("exhaust_valve_opening", "angle", None),
    "blowdown_end": ("blowdown_end", "angle", None),
    "valve_overlap": ("valve_overlap", "angle", "positive"),
    "exhaust_pressure_ratio": ("exhaust_pressure_ratio", "dimensionless", "positive"),
    "intake_pressure_min": ("intake_pressure_min", "pressure", "positive"),
    "intake_pressure_max": ("intake_pressure_max", "pressure", "positive"),
    "indicated_efficiency": ("indicated_efficiency", "dimensionless", "positive"),
    "volumetric_efficiency": ("volumetric_efficiency", "dimensionless", "positive"),
    "air_fuel_ratio": ("air_fuel_ratio", "dimensionless", "positive"),
    "heating_value": ("heating_value", "specific_energy", "positive"),
    "intake_temperature": ("intake_temperature", "temperature", "positive"),
}
#: Keys of each combustion model's table.
KEYS = {"single-zone": {"model", "imep_factors", "full_load", *_SINGLE_ZONE}, "measured": {"model", "traces"},
        "full_load": {"speed", "torque", "fmep"}}
P = "combustion"


def read_combustion(t: dict, path, crank):
    """The combustion model of the ``[combustion]`` table ``t`` for ``crank``'s cylinders."""
    model = get(t, "model", path, P, types=str)
    if model == "measured":
        return _read_measured(t, path, crank)
    if model != "single-zone":
        raise InputError(f"unknown model {model!r} (known: single-zone, measured)",
                         file=path, key=f"{P}.model")
    check_keys(t, KEYS["single-zone"], path, P)
    factors = array_quantity(t, "imep_factors", "dimensionless", path, P, (crank.n_cylinders,), nonneg=True)
    full_load = _read_full_load(subtable(t, "full_load", path, P), path)
    values = {name: scalar_quantity(t, key, dim, path, P, **({check: True} if check else {}))
              for key, (name, dim, check) in _SINGLE_ZONE.items()}
    c = SingleZoneCombustion(full_load=full_load, imep_factors=factors, **values)
    _check_single_zone(c, path)
    return c


def _read_measured(t, path, crank):
    check_keys(t, KEYS["measured"], path, P)
    full = Path(path).parent / get(t, "traces", path, P, types=str)
    if not full.is_file():
        raise InputError(f"pressure-trace file not found: {full}", file=path, key=f"{P}.traces")
    return read_pressure_traces(full, crank.n_cylinders)


def _read_full_load(fl, path) -> FullLoadCurve:
    fp = f"{P}.full_load"
    check_keys(fl, KEYS["full_load"], path, fp)
    speed = np.asarray(quantity(fl, "speed", "angular_speed", path, fp, positive=True), float)
    if speed.ndim != 1 or speed.size < 2 or np.any(np.diff(speed) <= 0):
        raise InputError("expected at least two strictly increasing speeds", file=path, key=f"{fp}.speed")
    torque = np.asarray(quantity(fl, "torque", "torque", path, fp, nonneg=True), float)
    fmep = np.asarray(quantity(fl, "fmep", "pressure", path, fp, nonneg=True), float)
    for key, arr in (("torque", torque), ("fmep", fmep)):
        if arr.shape != speed.shape:
            raise InputError(f"expected {speed.size} values (one per speed)", file=path, key=f"{fp}.{key}")
    return FullLoadCurve(speed=speed, torque=torque, fmep=fmep)


def _check_single_zone(c: SingleZoneCombustion, path) -> None:
    """The parameters together: valve timing in order, exponents and efficiencies sane."""
    deg = math.pi / 180
    for key, ok, why in (
            ("polytropic_compression", c.n_compression > 1, "must exceed 1"),
            ("polytropic_expansion", c.n_expansion > 1, "must exceed 1"),
            ("start", -180 * deg < c.start < 90 * deg, "must lie between -180 and 90 deg"),
            ("exhaust_valve_opening", c.start + c.duration <= c.exhaust_valve_opening,
             "must not precede the end of combustion (start + duration)"),
            ("blowdown_end", c.exhaust_valve_opening < c.blowdown_end
             <= 2 * math.pi - c.valve_overlap, "must lie between exhaust valve opening and "
             "the start of the valve overlap"),
            ("valve_overlap", c.valve_overlap < math.pi / 2, "must be below 90 deg"),
            ("intake_pressure_max", c.intake_pressure_max >= c.intake_pressure_min,
             "must not be below intake_pressure_min"),
            ("indicated_efficiency", c.indicated_efficiency < 1, "must be below 1")):
        if not ok:
            raise InputError(why, file=path, key=f"{P}.{key}")
