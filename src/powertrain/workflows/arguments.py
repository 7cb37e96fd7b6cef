"""The arguments of a study, checked alike for the command line and the Python API.

Lists as the options write them (``1000:6000:500``, ``5,10,20``, ``1:10:1,20,40``) or arrays,
numbers, choices and strings; every check raises :class:`~powertrain.errors.InputError`
naming the option (``--rpm``).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterator

import numpy as np

from powertrain.errors import InputError

#: Largest speed grid a run-up accepts.
MAX_SPEEDS = 2000
#: Most frequencies one option may ask for, and the highest frequency [Hz] (a typo must not
#: hang the run).
MAX_FREQUENCIES = 100_000
MAX_FREQUENCY_HZ = 1e5
#: How a speed and a frequency list are written (quoted in the errors).
SPEED_EXAMPLE, FREQUENCY_EXAMPLE = "1000,2000 or 1000:6000:500", "5,10,20 or 1:400:1"


def default_rpm(start=1000.0, stop=6000.0, step=500.0) -> np.ndarray:
    """Speed steps ``start, start + step, ... <= stop`` [rpm] (default: the thesis's 1000 to
    6000 rpm in 500 rpm steps, sec. 4.4)."""
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    return start + step * np.arange(n)


def frequencies(value, key: str = "--freq") -> np.ndarray:
    """Frequencies [Hz] as ``--freq`` writes them or numbers: finite, in 0..
    :data:`MAX_FREQUENCY_HZ`, strictly increasing."""
    arr = _numbers(value, key, "frequency", FREQUENCY_EXAMPLE, MAX_FREQUENCIES)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0) or np.any(arr > MAX_FREQUENCY_HZ):
        raise InputError(f"frequencies must be finite, >= 0 and <= {MAX_FREQUENCY_HZ:g} Hz", key=key)
    if np.any(np.diff(arr) <= 0):
        raise InputError("frequencies must be strictly increasing", key=key)
    return arr


def speeds(value, key: str = "--rpm", *, increasing: bool = True) -> np.ndarray:
    """Speeds [rpm] as ``--rpm`` writes them or numbers: finite, > 0, at most
    :data:`MAX_SPEEDS`, (``increasing``) strictly increasing; None: :func:`default_rpm`."""
    if value is None:
        return default_rpm()
    arr = _numbers(value, key, "speed", SPEED_EXAMPLE, MAX_SPEEDS)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError("speeds must be finite and > 0 [rpm]", key=key)
    if increasing and np.any(np.diff(arr) <= 0):
        raise InputError("speeds must be strictly increasing", key=key)
    return arr


def speed_steps(rpm_from: float, rpm_to: float, rpm_step: float) -> np.ndarray:
    """Speed steps [rpm] of the ``--from/--to/--step`` options, checked."""
    for value, key in ((rpm_from, "--from"), (rpm_to, "--to"), (rpm_step, "--step")):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"must be a finite speed > 0 [rpm], got {value:g}", key=key)
    if rpm_to < rpm_from:
        raise InputError(f"{rpm_to:g} rpm is below --from {rpm_from:g} rpm", key="--to")
    ratio = (rpm_to - rpm_from) / rpm_step
    if not math.isfinite(ratio) or ratio + 1 > MAX_SPEEDS:
        raise InputError(f"{ratio + 1:.3g} speed steps from --from/--to/--step; at most "
                         f"{MAX_SPEEDS}", key="--step")
    return default_rpm(rpm_from, rpm_to, rpm_step)


def _numbers(value, option, noun, example, most) -> np.ndarray:
    """A comma list with ``start:stop:step`` items (a string) or numbers, as floats."""
    read = _parse_list if isinstance(value, str) else floats
    return read(value, option, noun, example, most)


def floats(value, option: str, noun: str, example: str, most: int) -> np.ndarray:
    """A number or a sequence of numbers as a flat float array of 1..``most`` values."""
    items = [value] if is_number(value) else value
    try:
        items = np.ravel(np.asarray(list(items) if isinstance(items, Iterator) else items, dtype=object))
    except (TypeError, ValueError):
        items = np.array([value], dtype=object)
    if items.size > most:
        raise InputError(f"{items.size} values; at most {most}", key=option)
    try:
        values = [_real(v) for v in items]
    except (TypeError, ValueError):
        raise InputError(f"cannot read {noun} {_short(value)} (use {example})", key=option) from None
    if not values:
        raise InputError(f"no {noun} given", key=option)
    return np.array(values, dtype=float)


def _parse_list(text: str, option: str, noun: str, example: str, most: int) -> np.ndarray:
    """Numbers (1..``most``) of a comma list whose items may be ``start:stop:step``."""
    values: list[float] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if ":" in part:
                values.extend(_range(part, option, most, len(values)))
            else:
                values.append(float(part))
        except InputError:
            raise
        except ValueError:
            raise InputError(f"cannot read {noun} {part!r} (use {example})", key=option) from None
    arr = np.array(values, dtype=float)
    if arr.size == 0:
        raise InputError(f"no {noun} given", key=option)
    if arr.size > most:
        raise InputError(f"{arr.size} values; at most {most}", key=option)
    return arr


def _range(part: str, option: str, most: int, have: int) -> np.ndarray:
    """The values of one ``start:stop:step`` item (ValueError when it is not one), at most
    ``most`` with the ``have`` read before."""
    fields = [float(x) for x in part.split(":")]
    if len(fields) != 3 or fields[2] <= 0 or fields[1] < fields[0]:
        raise ValueError
    start, stop, step = fields
    if not all(math.isfinite(x) for x in fields):
        raise ValueError
    ratio = (stop - start) / step
    if not math.isfinite(ratio) or ratio + 1 + have > most:
        raise InputError(f"{part!r} asks for {ratio + 1:.3g} values; at most {most}", key=option)
    return start + step * np.arange(math.floor(ratio + 1e-9) + 1)


def is_number(value) -> bool:
    """True for a real number (int, float, numpy's), not a bool."""
    return isinstance(value, (numbers.Real, np.number)) and not isinstance(value, (bool, np.bool_))


def _real(value) -> float:
    """A real number, or a string of one, as a float (TypeError or ValueError otherwise)."""
    if isinstance(value, str):
        return float(value)
    if not is_number(value):
        raise TypeError(type(value).__name__)
    return float(value)


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def real(value, key: str, *, unit: str = "", optional: bool = False):
    """``value`` (a number or a string of one) as a float, NaN and inf passed; None passes
    when ``optional``."""
    if value is None and optional:
        return None
    try:
        return _real(value)
    except (TypeError, ValueError):
        raise InputError(f"must be a number{f' [{unit}]' if unit else ''}, got "
                         f"{_short(value)}", key=key) from None


def number(value, key: str, *, unit: str = "", minimum=None, above=None, maximum=None,
           optional: bool = False):
    """``value`` (a number or a string of one) as a finite float with ``minimum`` <= value,
    ``above`` < value, value <= ``maximum`` where given; None passes when ``optional``."""
    if value is None and optional:
        return None
    x = real(value, key, unit=unit)
    unit_text = f" [{unit}]" if unit else ""
    low = "" if minimum is None else f" >= {minimum:g}"
    low = low if above is None else f" > {above:g}"
    high = "" if maximum is None else f"{' and' if low else ''} <= {maximum:g}"
    if (not math.isfinite(x) or (minimum is not None and x < minimum)
            or (above is not None and x <= above) or (maximum is not None and x > maximum)):
        raise InputError(f"must be a finite number{low}{high}{unit_text}, got {x:g}", key=key)
    return x


def nonnegative(value, key: str, unit: str) -> float:
    """``value`` as a finite float >= 0 [``unit``] (``--noise-floor``)."""
    x = real(value, key, unit=unit)
    if not (math.isfinite(x) and x >= 0):
        raise InputError(f"must be a finite number >= 0 [{unit}]", key=key)
    return x


def integer(value, key: str, *, minimum=None, maximum=None, optional: bool = False):
    """``value`` (an integral number or string) as an int in ``minimum..maximum``; None
    passes when ``optional``."""
    if value is None and optional:
        return None
    if isinstance(value, str):
        try:
            value = int(value)
        except ValueError:
            pass
    if not isinstance(value, (numbers.Integral, np.integer)) or isinstance(value, (bool, np.bool_)):
        raise InputError(f"must be an integer, got {_short(value)}", key=key)
    n = int(value)
    if (minimum is not None and n < minimum) or (maximum is not None and n > maximum):
        span = f"{'' if minimum is None else minimum}..{'' if maximum is None else maximum}"
        raise InputError(f"must be an integer {span}, got {n}", key=key)
    return n


def choice(value, choices, key: str) -> str:
    """``value`` if it is one of ``choices`` (strings), else an error listing them."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"{_short(value)} is not one of {', '.join(map(repr, choices))}", key=key)
    return value


def flag(value, key: str) -> bool:
    """``value`` as a bool (True, False, or numpy's)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"must be True or False, got {_short(value)}", key=key)
    return bool(value)


def texts(value, key: str) -> list:
    """One string or a sequence of strings as a list (None: empty)."""
    if value is None:
        return []
    items = [value] if isinstance(value, str) else value
    try:
        items = list(items)
    except TypeError:
        items = [items]
    bad = [v for v in items if not isinstance(v, str)]
    if bad:
        raise InputError(f"expected a string or a list of strings, got {_short(bad[0])}", key=key)
    return items


def names(value, key: str) -> list:
    """Comma-separated names (``"a,b"``) or a sequence of them, blanks dropped."""
    items = texts(value, key)
    return [n.strip() for item in items for n in item.split(",") if n.strip()]


def path_or(value, kinds, key: str, what: str):
    """``value`` if a path or an instance of ``kinds``, else an error expecting ``what``."""
    if isinstance(value, (str, os.PathLike)) or isinstance(value, kinds):
        return value
    raise InputError(f"expected {what}, got {type(value).__name__}", key=key)
