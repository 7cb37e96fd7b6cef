"""A raw run-up recording: time histories of mount-point channels plus speed or tacho.

Values are SI (m/s^2, m/s, m, N), time in s, speed in rpm, tacho in V; a channel names its
mount, side (``active`` engine, ``passive`` body), direction (engine axes) and quantity.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.channel import DIRECTIONS, SIDES, ChannelFields
from powertrain.errors import InputError

#: Largest sample magnitude accepted (far below where squares and spectra overflow).
MAX_SAMPLE = 1e15

#: Measured quantity -> its SI unit.
QUANTITIES = {
    "acceleration": "m/s^2",
    "velocity": "m/s",
    "displacement": "m",
    "force": "N",
}
#: Dimension of :mod:`powertrain.units` -> quantity (``length`` is a displacement).
QUANTITY_OF_DIMENSION = {"acceleration": "acceleration", "velocity": "velocity",
                         "length": "displacement", "force": "force"}
#: Relative tolerance on the (uniform) sampling interval.
UNIFORM_TOLERANCE = 1e-3


@dataclass
class RawChannel(ChannelFields):
    """One transducer channel.

    Attributes
    ----------
    name : str
        Channel name in the file.
    mount, side, direction, quantity : str
        Where and what (``quantity`` a key of :data:`QUANTITIES`).
    values : ndarray
        Samples in SI [m/s^2, m/s, m or N].
    unit : str
        Unit the file declared (converted from).
    """

    name: str
    mount: str
    side: str
    direction: str
    quantity: str
    values: np.ndarray
    unit: str = ""


@dataclass
class RawRecording:
    """Uniformly sampled time data of a run-up.

    Attributes
    ----------
    time : ndarray (n,)
        Sample times [s], strictly increasing, uniform.
    channels : list of RawChannel
    rpm : ndarray (n,) or None
        Speed channel [rpm].
    tacho : ndarray (n,) or None
        Tacho pulse train [V].
    source : str
        File read.
    comments : list of str
        Notes from the file (e.g. a SYNTHETIC label).
    cycle_reference : ndarray (n,) or None
        Once-per-engine-cycle pulse train [V] fixing the 720° phase of the orders.
    trigger : ndarray (n,) or None
        Trigger channel [V] (the start of an event).
    """

    time: np.ndarray
    channels: list
    rpm: np.ndarray | None = None
    tacho: np.ndarray | None = None
    source: str = ""
    comments: list = field(default_factory=list)
    cycle_reference: np.ndarray | None = None
    trigger: np.ndarray | None = None

    @property
    def sample_rate(self) -> float:
        """Sampling rate [Hz]."""
        return (self.time.size - 1) / (self.time[-1] - self.time[0])

    @property
    def synthetic(self) -> bool:
        return any("synthetic" in c.lower() for c in self.comments)

    def channel_matrix(self, channels=None) -> np.ndarray:
        """Samples of ``channels`` (default all) as one (n_ch, n) array [SI], without copying
        when they are the rows of one array."""
        vals = [c.values for c in (self.channels if channels is None else channels)]
        base = vals[0].base
        if (isinstance(base, np.ndarray) and base.ndim == 2 and base.shape[0] == len(vals)
                and base.flags.c_contiguous
                and all(v.base is base and v.__array_interface__["data"][0]
                        == base[i].__array_interface__["data"][0] for i, v in enumerate(vals))):
            return base
        return np.vstack(vals)

    @staticmethod
    def rows(values_list) -> list:
        """The arrays of ``values_list`` copied into one (n_ch, n) block; its rows."""
        block = np.empty((len(values_list), np.size(values_list[0])))
        for i, v in enumerate(values_list):
            block[i] = v
        return list(block)

    def validate(self, time_key="time") -> RawRecording:
        """Check shapes, finiteness and uniform increasing time; return self (raises
        :class:`InputError` naming the file and channel)."""
        t = np.asarray(self.time, float)
        self.time = t
        if t.ndim != 1 or t.size < 16:
            raise InputError("need at least 16 samples", file=self.source, key=time_key)
        if not np.all(np.isfinite(t)):
            raise InputError("time has NaN or infinite values", file=self.source, key=time_key)
        dt = np.diff(t)
        if np.any(dt <= 0):
            i = int(np.flatnonzero(dt <= 0)[0])
            raise InputError(f"time not increasing at sample {i + 1} ({t[i + 1]:g} s)",
                             file=self.source, key=time_key)
        mean = (t[-1] - t[0]) / (t.size - 1)
        if np.max(np.abs(dt - mean)) > UNIFORM_TOLERANCE * mean:
            raise InputError("time is not uniformly sampled (resample before tracking)",
                             file=self.source, key=time_key)
        if not self.channels:
            raise InputError("no vibration channel found", file=self.source)
        seen = set()
        for ch in self.channels:
            self._check_channel(ch, t.size)
            if ch.label + ch.quantity in seen:
                raise InputError(f"channel {ch.label} ({ch.quantity}) appears twice",
                                 file=self.source, key=ch.name)
            seen.add(ch.label + ch.quantity)
        for name in ("rpm", "tacho", "cycle_reference", "trigger"):
            arr = getattr(self, name)
            if arr is not None:
                arr = np.asarray(arr, float)
                setattr(self, name, arr)
                if arr.shape != t.shape or not np.all(np.isfinite(arr)):
                    raise InputError("needs one finite value per time sample",
                                     file=self.source, key=name)
        return self

    def _check_channel(self, ch, n):
        where = {"file": self.source, "key": ch.name}
        if ch.quantity not in QUANTITIES:
            raise InputError(f"unknown quantity {ch.quantity!r} (expected "
                             f"{', '.join(QUANTITIES)})", **where)
        if ch.side not in SIDES:
            raise InputError(f"unknown side {ch.side!r} (expected active or passive)", **where)
        if ch.direction not in DIRECTIONS:
            raise InputError(f"unknown direction {ch.direction!r} (expected x, y or z)",
                             **where)
        if not ch.mount:
            raise InputError("channel maps to no mount", **where)
        ch.values = np.asarray(ch.values, float)
        if ch.values.shape != (n,):
            raise InputError(f"{ch.values.size} samples, time has {n}", **where)
        if not np.all(np.isfinite(ch.values)):
            raise InputError("NaN or infinite sample", **where)
        if np.max(np.abs(ch.values), initial=0.0) > MAX_SAMPLE:
            raise InputError(f"sample magnitude above {MAX_SAMPLE:g}: not a vibration "
                             "signal (export or unit error)", **where)
