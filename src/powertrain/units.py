"""The table of units accepted in data files, and conversion to SI.

Data files may use datasheet units (N/mm, N·s/mm, kg, bar, mm, rpm, deg); every quantity
declares its unit and the loaders convert it once, here. Inside the package all is SI.
"""

from __future__ import annotations

import math

from powertrain.errors import InputError

#: unit string -> (dimension, factor to SI). Aliases spell the same unit differently.
UNITS: dict[str, tuple[str, float]] = {
    "N/m": ("stiffness", 1.0), "N/mm": ("stiffness", 1e3), "kN/mm": ("stiffness", 1e6),
    "N*s/m": ("damping", 1.0), "Ns/m": ("damping", 1.0), "N·s/m": ("damping", 1.0),
    "N*s/mm": ("damping", 1e3), "Ns/mm": ("damping", 1e3), "N·s/mm": ("damping", 1e3),
    "kg": ("mass", 1.0), "g": ("mass", 1e-3), "t": ("mass", 1e3),
    "m": ("length", 1.0), "mm": ("length", 1e-3), "cm": ("length", 1e-2),
    "m^3": ("volume", 1.0), "cm^3": ("volume", 1e-6), "L": ("volume", 1e-3),
    "Pa": ("pressure", 1.0), "kPa": ("pressure", 1e3), "MPa": ("pressure", 1e6),
    "bar": ("pressure", 1e5),
    "rad": ("angle", 1.0), "deg": ("angle", math.pi / 180.0),
    "rad/s": ("angular_speed", 1.0), "rpm": ("angular_speed", 2.0 * math.pi / 60.0),
    "1/min": ("angular_speed", 2.0 * math.pi / 60.0),
    "U/min": ("angular_speed", 2.0 * math.pi / 60.0),        # Umdrehungen pro Minute
    "kg*m^2": ("inertia", 1.0), "kg*mm^2": ("inertia", 1e-6),
    "kg*m": ("unbalance", 1.0), "kg*mm": ("unbalance", 1e-3), "g*mm": ("unbalance", 1e-6),
    "N*m": ("torque", 1.0), "Nm": ("torque", 1.0),
    "m/s": ("velocity", 1.0), "mm/s": ("velocity", 1e-3),
    "m/s^2": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0),
    "m/s²": ("acceleration", 1.0), "mm/s^2": ("acceleration", 1e-3),
    "mm/s2": ("acceleration", 1e-3), "mm/s²": ("acceleration", 1e-3),
    "um": ("length", 1e-6), "µm": ("length", 1e-6),
    "V": ("voltage", 1.0), "mV": ("voltage", 1e-3),
    "N": ("force", 1.0), "kN": ("force", 1e3),
    "Hz": ("frequency", 1.0),
    "s": ("time", 1.0), "ms": ("time", 1e-3),
    "J/kg": ("specific_energy", 1.0), "MJ/kg": ("specific_energy", 1e6),
    "K": ("temperature", 1.0),                                # absolute only
    "1": ("dimensionless", 1.0), "-": ("dimensionless", 1.0), "%": ("dimensionless", 1e-2),
}

#: Standard gravity [m/s^2] (CGPM 1901), the ``g`` of accelerometer data.
STANDARD_GRAVITY = 9.80665

#: Symbols whose meaning depends on the dimension expected: ``g`` is a gram where a mass is
#: expected and standard gravity where an acceleration is expected.
UNITS_BY_DIMENSION: dict[tuple[str, str], float] = {("g", "acceleration"): STANDARD_GRAVITY}


def dimension_of(unit: str, candidates=None):
    """Dimension of ``unit`` (None if unknown), preferring one of ``candidates`` for
    ambiguous symbols (``g``)."""
    for cand in candidates or ():
        if (unit, cand) in UNITS_BY_DIMENSION or UNITS.get(unit, ("",))[0] == cand:
            return cand
    return UNITS[unit][0] if unit in UNITS else None


def to_si(value, unit: str, dimension: str, *, file=None, key=None):
    """Convert ``value`` given in ``unit`` to SI, checking the unit measures ``dimension``.

    Parameters
    ----------
    value : float or array_like
        Value(s) in the declared unit.
    unit : str
        Unit string, one of :data:`UNITS`.
    dimension : str
        Expected dimension (e.g. ``"stiffness"``).
    file, key : str, optional
        Where the value came from, for the error message.

    Returns
    -------
    float or ndarray
        Value(s) in SI.

    Raises
    ------
    InputError
        Unknown unit or unit of the wrong dimension.
    """
    if isinstance(unit, str) and (unit, dimension) in UNITS_BY_DIMENSION:
        return value * UNITS_BY_DIMENSION[(unit, dimension)]
    if not isinstance(unit, str) or unit not in UNITS:
        known = ", ".join([u for u, (dim, _) in UNITS.items() if dim == dimension]
                          + [u for u, dim in UNITS_BY_DIMENSION if dim == dimension])
        raise InputError(f"unknown unit {unit!r} (expected one of: {known})", file=file, key=key)
    dim, factor = UNITS[unit]
    if dim != dimension:
        raise InputError(f"unit {unit!r} measures {dim}, expected {dimension}", file=file, key=key)
    return value * factor


def from_si(value, unit: str, dimension: str | None = None):
    """Convert an SI value to ``unit`` (for writing datasheet-unit files and tables)."""
    if (unit, dimension) in UNITS_BY_DIMENSION:
        return value / UNITS_BY_DIMENSION[(unit, dimension)]
    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}")
    return value / UNITS[unit][1]
