"""Reading text data files and their cells with errors that name file, line and column."""

from __future__ import annotations

import math

from powertrain.errors import InputError


def read_text(path, kind: str = "text") -> str:
    """Whole content of a UTF-8 text file.

    Parameters
    ----------
    path : str or Path
    kind : str
        What the file should be (``"CSV"``, ``"TOML"``), for the error message.

    Raises
    ------
    InputError
        Missing, unreadable, a directory, or not UTF-8 — one line naming the file.
    """
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            return fh.read()
    except FileNotFoundError:
        raise InputError("file not found", file=path) from None
    except IsADirectoryError:
        raise InputError("is a directory, expected a file", file=path) from None
    except PermissionError:
        raise InputError("file not readable (permission denied)", file=path) from None
    except UnicodeDecodeError:
        raise InputError(f"not a UTF-8 {kind} file", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc})", file=path) from None


def parse_number(text, path, line, column, *, nonneg: bool = False) -> float:
    """A finite float from a table cell.

    Parameters
    ----------
    text : str
        Cell content.
    path : str
        File, for the error message.
    line : int
        1-based line number, for the error message.
    column : str
        Column name, for the error message.
    nonneg : bool
        Reject negative values.

    Raises
    ------
    InputError
        Not a number, NaN/infinite, or negative when ``nonneg``.
    """
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise InputError(f"not a number: {str(text).strip()!r}", file=path, line=line,
                         key=column) from None
    if not math.isfinite(value):
        raise InputError(f"not a finite number ({str(text).strip()})", file=path, line=line,
                         key=column)
    if nonneg and value < 0:
        raise InputError(f"must not be negative, got {str(text).strip()}", file=path,
                         line=line, key=column)
    return value
