"""Reading text data files and their cells with errors that name file, line and column."""

from __future__ import annotations

import math
import os
import stat

from powertrain.errors import InputError

#: Largest input file read [bytes]; larger files are refused before reading.
MAX_FILE_BYTES = 512 * 2 ** 20


def check_regular_file(path) -> None:
    """Refuse, without opening it, anything but a path to a regular file of at most
    :data:`MAX_FILE_BYTES` (a FIFO or device would block; an int is a file descriptor)."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"expected a file path, got {type(path).__name__} {str(path)[:40]!r}")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise InputError("file not found", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc})", file=path) from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError("is a directory, expected a file", file=path)
    if not stat.S_ISREG(st.st_mode):
        raise InputError("not a regular file (FIFO, socket or device)", file=path)
    if st.st_size > MAX_FILE_BYTES:
        raise InputError(f"file of {st.st_size / 2 ** 20:.0f} MiB, more than the "
                         f"{MAX_FILE_BYTES // 2 ** 20} MiB accepted", file=path)


def read_text(path, kind: str = "text") -> str:
    """Whole content of a UTF-8 text file (:class:`InputError` naming the file if unreadable).

    Parameters
    ----------
    path : str or Path
        The file.
    kind : str
        What the file should be (``"CSV"``, ``"TOML"``), for the error message.
    """
    check_regular_file(path)
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            text = fh.read()
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
    if kind == "CSV":
        _check_line_lengths(text, path)
    return text


#: Longest line of a CSV file [characters] (the csv module's cell limit is 128 kB).
MAX_CSV_LINE = 65536


def _check_line_lengths(text: str, path) -> None:
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        raise InputError("NUL character: not a text CSV file", file=path, line=line)
    for lineno, line in enumerate(text.splitlines(), start=1):
        if len(line) > MAX_CSV_LINE:
            raise InputError(f"line of {len(line)} characters, more than the "
                             f"{MAX_CSV_LINE} accepted", file=path, line=lineno)


def parse_number(text, path, line, column, *, nonneg: bool = False) -> float:
    """A finite float from a table cell.

    Parameters
    ----------
    text : str
        Cell content.
    path, line, column : str, int, str
        File, 1-based line number and column name, named by the error.
    nonneg : bool
        Reject negative values.
    """
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise InputError(f"not a number: {str(text).strip()!r}", file=path, line=line, key=column) from None
    if not math.isfinite(value):
        raise InputError(f"not a finite number ({str(text).strip()})", file=path, line=line, key=column)
    if nonneg and value < 0:
        raise InputError(f"must not be negative, got {str(text).strip()}", file=path, line=line, key=column)
    return value
