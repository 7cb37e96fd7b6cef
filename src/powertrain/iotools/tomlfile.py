"""Reading TOML data files with errors that name the file and the key."""

from __future__ import annotations

import math
import sys

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.textfile import read_text
from powertrain.units import to_si

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def read_toml(path) -> dict:
    """Parse a TOML file; unreadable or malformed files raise :class:`InputError`."""
    text = read_text(path, "TOML")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML: {exc}", file=path) from None
    except ValueError as exc:        # e.g. an integer too long to convert (> 4300 digits)
        raise InputError(f"not valid TOML: {exc}", file=path) from None


def get(table: dict, key: str, path, prefix: str = "", *, default=..., types=None):
    """``table[key]`` or an :class:`InputError` naming ``prefix.key`` when missing/mistyped."""
    full = f"{prefix}.{key}" if prefix else key
    if key not in table:
        if default is ...:
            raise InputError("missing key", file=path, key=full)
        return default
    value = table[key]
    if types is not None and not isinstance(value, types):
        raise InputError(f"expected {_type_name(types)}, got {type(value).__name__}", file=path, key=full)
    return value


def _type_name(types):
    return " or ".join(t.__name__ for t in types) if isinstance(types, tuple) else types.__name__


def number(value, path, key, *, nonneg=False, positive=False) -> float:
    """Validate a finite real number (bool rejected)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"expected a number, got {value!r}", file=path, key=key)
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"not a finite number ({value})", file=path, key=key)
    if positive and value <= 0:
        raise InputError(f"must be positive, got {value}", file=path, key=key)
    if nonneg and value < 0:
        raise InputError(f"must not be negative, got {value}", file=path, key=key)
    return value


def quantity(table: dict, key: str, dimension: str, path, prefix: str = "", *,
             default=..., nonneg=False, positive=False):
    """Read ``key = {value = ..., unit = "..."}`` and convert to SI (a list value: a list)."""
    full = f"{prefix}.{key}" if prefix else key
    raw = get(table, key, path, prefix, default=default)
    if raw is default and default is not ...:
        return default
    if not isinstance(raw, dict):
        raise InputError("expected {value = ..., unit = \"...\"}", file=path, key=full)
    if "value" not in raw:
        raise InputError("missing key", file=path, key=f"{full}.value")
    if "unit" not in raw:
        raise InputError("missing unit", file=path, key=f"{full}.unit")
    value, unit = raw["value"], raw["unit"]
    if isinstance(value, list):
        vals = [number(v, path, f"{full}.value", nonneg=nonneg, positive=positive) for v in value]
        return [to_si(v, unit, dimension, file=path, key=f"{full}.unit") for v in vals]
    value = number(value, path, f"{full}.value", nonneg=nonneg, positive=positive)
    return to_si(value, unit, dimension, file=path, key=f"{full}.unit")


def check_keys(table, allowed, path, prefix):
    """InputError naming the first key of ``table`` not in ``allowed``."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        key = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise InputError(f"unknown key (expected one of: {', '.join(sorted(allowed))})", file=path, key=key)


def subtable(doc, key, path, prefix=""):
    """The table ``doc[key]`` (InputError naming ``prefix.key`` if missing or not a table)."""
    return get(doc, key, path, prefix, types=dict)


def _raw_quantity(table, key, path, prefix):
    full = f"{prefix}.{key}" if prefix else key
    raw = get(table, key, path, prefix)
    if not isinstance(raw, dict):
        raise InputError('expected {value = ..., unit = "..."}', file=path, key=full)
    for k in ("value", "unit"):
        if k not in raw:
            raise InputError("missing key", file=path, key=f"{full}.{k}")
    extra = sorted(set(raw) - {"value", "unit"})
    if extra:
        raise InputError("unknown key (expected value, unit)", file=path, key=f"{full}.{extra[0]}")
    return raw["value"], raw["unit"], full


def array_quantity(table, key, dimension, path, prefix, shape, *, nonneg=False, positive=False):
    """A list (or nested list) quantity of the given shape, in SI."""
    value, unit, full = _raw_quantity(table, key, path, prefix)

    def flat(v):
        if isinstance(v, list):
            return [x for item in v for x in flat(item)]
        return [v]

    def nested_shape(v):
        if isinstance(v, list):
            shapes = {nested_shape(x) for x in v}
            if len(shapes) != 1:
                return None
            inner = shapes.pop() if v else ()
            return None if inner is None else (len(v),) + inner
        return ()

    got = nested_shape(value)
    want_len = shape if isinstance(shape, tuple) else None
    if got is None or got == () or (want_len is not None and got != want_len):
        raise InputError(f"expected a list of shape {shape}, got {value!r}"[:200],
                         file=path, key=f"{full}.value")
    vals = [number(v, path, f"{full}.value", nonneg=nonneg, positive=positive) for v in flat(value)]
    return np.asarray(to_si(np.array(vals, dtype=float), unit, dimension, file=path,
                            key=f"{full}.unit"), dtype=float).reshape(got)


def vector3(table, key, dimension, path, prefix):
    """A 3-vector quantity in SI."""
    return array_quantity(table, key, dimension, path, prefix, (3,))


def unit_vector(table, key, path, prefix):
    """A non-zero dimensionless 3-vector, normalised."""
    v = vector3(table, key, "dimensionless", path, prefix)
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise InputError("direction vector must not be zero", file=path, key=f"{prefix}.{key}")
    return v / n


def scalar_quantity(table, key, dimension, path, prefix, **kw):
    """One number quantity in SI (a list is an error)."""
    value = quantity(table, key, dimension, path, prefix, **kw)
    if isinstance(value, list):
        raise InputError("expected one number, got a list", file=path,
                         key=f"{prefix}.{key}.value" if prefix else f"{key}.value")
    return float(value)
