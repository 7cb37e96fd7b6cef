"""A raw recording as the format modules see it: :class:`FileSignals` (what a reader found,
before :func:`powertrain.iotools.raw.read_raw` maps channels and converts units) and
:func:`written_signals` (what a writer stores).

Its own module so that the format readers (``raw_csv``, ``raw_hdf5``, ``raw_mdf``,
``raw_uff``) and the entry point (``raw``) import it without importing each other in a circle.
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
    """``(name, values, unit, channel)`` a writer stores: ``rpm`` [rpm], ``tacho``, (with
    ``cycle``) ``cycle`` and ``trigger`` [V] where ``recording`` has them (``channel``
    None), then every
    :class:`RawChannel` in its file unit."""
    out = [(name, values, unit, None) for name, values, unit in (
        ("rpm", recording.rpm, "rpm"), ("tacho", recording.tacho, "V"),
        ("cycle", recording.cycle_reference if cycle else None, "V"),
        ("trigger", recording.trigger, "V")) if values is not None]
    for ch in recording.channels:
        dim = "length" if ch.quantity == "displacement" else ch.quantity
        out.append((ch.label, from_si(ch.values, ch.unit, dim), ch.unit, ch))
    return out
