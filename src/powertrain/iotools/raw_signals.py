"""What a raw-data format reader returns (:class:`FileSignals`): a time base and named signals
in file units, before :func:`powertrain.iotools.raw.read_raw` maps channels and converts units.

Its own module so that the format readers (``raw_csv``, ``raw_hdf5``, ``raw_mdf``,
``raw_uff``) and the entry point (``raw``) import it without importing each other in a circle.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class FileSignals:
    """What a format reader found: a time base and named signals (values in file units)."""

    time: np.ndarray | None
    signals: list                      # [(name, values, unit)]
    source: str
    time_name: str = "time"
    comments: list = field(default_factory=list)
    times: dict = field(default_factory=dict)   # name -> own time base [s] where not `time`
