"""Errors raised for bad user input: :class:`InputError` names the file, key and line, so the
command line prints one line and exits non-zero."""

from __future__ import annotations

#: Longest error line: a value quoted from a damaged file is cut, the file and key stay.
MAX_LINE = 400


class InputError(ValueError):
    """Bad input file or value.

    Parameters
    ----------
    message : str
        What is wrong, in one line.
    file : str, optional
        File in which the problem was found.
    key : str, optional
        Key (dotted path), column or parameter name.
    line : int, optional
        Line number (1-based) for tabular files.
    """

    def __init__(self, message: str, file: str | None = None, key: str | None = None,
                 line: int | None = None):
        self.message = message
        self.file = None if file is None else str(file)
        self.key = key
        self.line = line
        super().__init__(self.one_line())

    def one_line(self) -> str:
        where = []
        if self.file:
            where.append(self.file)
        if self.line is not None:
            where.append(f"line {self.line}")
        if self.key:
            where.append(f"key '{self.key}'")
        prefix = ": ".join([", ".join(where)]) if where else ""
        text = f"{prefix}: {self.message}" if prefix else self.message
        text = " ".join(text.split())
        return text if len(text) <= MAX_LINE else text[:MAX_LINE - 3] + "..."


def solved(solve, file, key):
    """``solve()``, a model that cannot be solved (singular, overflow) reported as an
    InputError naming ``file`` and ``key``."""
    import numpy as np  # deferred: keeps `import powertrain` (which loads InputError) free of numpy
    try:
        with np.errstate(all="ignore"):
            return solve()
    except InputError:
        raise
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        raise InputError(f"the model cannot be solved ({type(exc).__name__}: "
                         f"{str(exc)[:120]})", file=file, key=key) from None


def require_finite(values: dict, file, key) -> None:
    """Refuse results holding NaN or inf (``values``: name -> array), naming the input."""
    import numpy as np  # deferred: keeps `import powertrain` (which loads InputError) free of numpy
    for name, value in values.items():
        if value is not None and not np.all(np.isfinite(value)):
            raise InputError(f"the computed {name} is not finite (NaN or "
                             "inf): values out of any physical range", file=file, key=key)


class PowertrainWarning(UserWarning):
    """Base of the package's warnings (a result to read with care); the command line prints
    each as ``warning: ...``."""
