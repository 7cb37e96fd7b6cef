"""Where a result or figure came from: program version, command line, engine, date.

A :class:`Provenance` is a small immutable value. The command line fills it
(:func:`powertrain.cli.common.cli_provenance`); library users make one with
:meth:`Provenance.now`. Plot functions print it as one line at the foot of every figure
(:func:`powertrain.plotting.style.add_provenance`); result objects may carry one in a
``provenance`` attribute, which their ``plot`` methods use when none is passed.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import asdict, dataclass, replace

from powertrain import __version__


@dataclass(frozen=True)
class Provenance:
    """Program, command, engine and date of one result.

    Attributes
    ----------
    command : str
        The command line as typed (``powertrain runup --from 1000 ...``), or a description of
        the library call; empty when unknown.
    engine : str
        The engine that ran: name and file, and what was changed on the command line
        (e.g. ``"EA888-like (engines/default.toml), balancers off"``); empty when the result
        has no engine (a mount stiffness).
    version : str
        ``powertrain`` version.
    date : str
        UTC date and time, ISO 8601 to the second (``2026-11-23T18:30:00Z``).
    """

    command: str = ""
    engine: str = ""
    version: str = __version__
    date: str = ""

    @classmethod
    def now(cls, command: str = "", engine: str = "") -> Provenance:
        """A provenance stamped with the current UTC time and this version."""
        stamp = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)
        return cls(command=command, engine=engine, version=__version__,
                   date=stamp.strftime("%Y-%m-%dT%H:%M:%SZ"))

    def with_engine(self, engine: str) -> Provenance:
        """Copy with ``engine`` set."""
        return replace(self, engine=engine)

    def line(self) -> str:
        """One line for a figure foot: ``powertrain 0.1.0 · 2026-11-23 18:30 UTC · engine:
        ... · $ command``."""
        parts = [f"powertrain {self.version}"]
        if self.date:
            parts.append(self.date.replace("T", " ").replace("Z", " UTC"))
        if self.engine:
            parts.append(f"engine: {self.engine}")
        if self.command:
            parts.append(f"$ {self.command}")
        return "  ·  ".join(parts)

    def to_dict(self) -> dict:
        """Plain dict (for JSON and HDF5 attributes)."""
        return asdict(self)
