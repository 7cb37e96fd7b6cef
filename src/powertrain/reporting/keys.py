"""Values of a study file checked one key at a time: each error is one line naming the study
file and the key (``compare.solver``); a library error naming only an option (``--scale``)
is re-raised naming the study file and the step's key."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from powertrain.errors import InputError


@dataclass(frozen=True)
class Where:
    """The study file being read: its path, its folder (base of its relative paths) and its
    engine."""

    path: str
    base: Path
    engine: object = None

    def error(self, message: str, key: str) -> InputError:
        """An :class:`InputError` naming this study file and ``key``."""
        return InputError(message, file=self.path, key=key)


def check_keys(table: dict, allowed, where: Where, prefix: str = "") -> None:
    """Refuse a key of ``table`` not in ``allowed``, naming it and listing the known ones."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        key = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise where.error(f"unknown key (known: {', '.join(allowed)})", key)


def string(table: dict, key: str, where: Where, prefix: str, default=None):
    """A non-empty string, or ``default`` when the key is absent."""
    if key not in table:
        return default
    value = table[key]
    if not isinstance(value, str) or not value.strip():
        raise where.error(f"expected a non-empty string, got {_short(value)}",
                          _full(prefix, key))
    return value


def strings(table: dict, key: str, where: Where, prefix: str) -> list:
    """A string or a list of strings (as a repeatable option takes them); [] when absent."""
    value = table.get(key, [])
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not all(isinstance(v, str) and v.strip() for v in items):
        raise where.error(f"expected a string or a list of strings, got {_short(value)}",
                          _full(prefix, key))
    return list(items)


def boolean(table: dict, key: str, where: Where, prefix: str, default: bool) -> bool:
    """``true`` or ``false``; ``default`` when absent."""
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise where.error(f"expected true or false, got {_short(value)}", _full(prefix, key))
    return value


def positive(table: dict, key: str, where: Where, prefix: str, default=None, *,
             integer: bool = False):
    """A finite number > 0 (an integer ≥ 1 with ``integer``); ``default`` when absent."""
    if key not in table:
        return default
    value = table[key]
    ok = (not isinstance(value, bool) and isinstance(value, (int, float))
          and math.isfinite(value) and value > 0 and (not integer or isinstance(value, int)))
    if not ok:
        what = "an integer >= 1" if integer else "a finite number > 0"
        raise where.error(f"expected {what}, got {_short(value)}", _full(prefix, key))
    return value


def choice(table: dict, key: str, where: Where, prefix: str, choices, default: str) -> str:
    """One of ``choices`` (strings); ``default`` when absent."""
    value = table.get(key, default)
    if value not in choices:
        raise where.error(f"{_short(value)} is not one of {', '.join(map(repr, choices))}",
                          _full(prefix, key))
    return value


def file_path(table: dict, key: str, where: Where, prefix: str = "", default=None):
    """A file named relative to the study file, as a path (normalised); it must exist."""
    name = string(table, key, where, prefix)
    if name is None:
        return default
    return existing(name, where, _full(prefix, key))


def existing(name: str, where: Where, key: str) -> str:
    """``name`` relative to the study file's folder, which must be an existing file."""
    path = os.path.normpath(where.base / os.path.expanduser(name))
    if not os.path.isfile(path):
        raise where.error(f"no such file: {path}", key)
    return path


def restated(exc: InputError, where: Where, step: str) -> InputError:
    """``exc`` naming the study file and ``step``'s key where it named only an option
    (``--scale`` -> ``whatif.scale``); an error naming its own file stays as it is."""
    if exc.file is not None:
        return exc
    option = (exc.key or "").lstrip("-").replace("-", "_")
    if option in ("noise_floor", "engine"):
        return where.error(exc.message, option)
    return where.error(exc.message, f"{step}.{option}" if option else step)


def _full(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
