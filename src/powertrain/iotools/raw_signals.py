"""A raw recording as the format modules see it: :class:`FileSignals` (what a reader found,
in file units) and :func:`written_signals` (what a writer stores); shared by the readers and
:mod:`powertrain.iotools.raw` without an import cycle.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.units import from_si


@dataclass
class FileSignals:
    """What a format reader found: a time base and named signals (values in file units)."""

    time: np.ndarray | None
    signals: list                      # [(name, values, unit)]
    source: str
    time_name: str = "time"
    comments: list = field(default_factory=list)
    times: dict = field(default_factory=dict)   # name -> own time base [s] where not `time`


def written_signals(recording, *, cycle: bool = True) -> list:
    """``(name, values, unit, channel)`` a writer stores: ``rpm`` [rpm], ``tacho``, ``cycle``
    (if ``cycle``) and ``trigger`` [V] where present (``channel`` None), then every
    :class:`RawChannel` in its file unit."""
    out = [(name, values, unit, None) for name, values, unit in (
        ("rpm", recording.rpm, "rpm"), ("tacho", recording.tacho, "V"),
        ("cycle", recording.cycle_reference if cycle else None, "V"),
        ("trigger", recording.trigger, "V")) if values is not None]
    for ch in recording.channels:
        dim = "length" if ch.quantity == "displacement" else ch.quantity
        out.append((ch.label, from_si(ch.values, ch.unit, dim), ch.unit, ch))
    return out
