"""Raw run-up time data in ASAM MDF4 (asammdf): every channel but the masters is a signal.
The vibration channels share one time base; a speed or tacho channel may have its own (e.g.
CAN speed at 100 Hz), resampled by :func:`powertrain.iotools.raw.assemble`.
"""

from __future__ import annotations

import gc
import os
import sys
import warnings

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.raw_signals import FileSignals, written_signals
from powertrain.outputs import atomic_path


def read_mdf_signals(path, channel_map=None) -> FileSignals:
    """Signals of an MDF file."""
    from asammdf import MDF  # deferred: heavy package, loaded only when this format is used
    with open(path, "rb") as fh:
        head = fh.read(72)
    if len(head) < 72 or head[64:68] not in (b"##HD", b"HD\x00\x00") and head[64:66] != b"HD":
        raise InputError("not a readable MDF file (no header block after the identification "
                         "block)", file=path)
    problem = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            mdf = MDF(str(path))
        except Exception as exc:   # asammdf raises many types on malformed files
            problem = str(exc).splitlines()[0][:80] if str(exc) else type(exc).__name__
        _quiet_collect()           # a half-built MDF object complains when finalised
    if problem is not None:
        raise InputError(f"not a readable MDF file ({problem})", file=path)
    time, signals, times = None, [], {}
    try:
        _check_declared_size(mdf, path)
        for g, group in enumerate(mdf.groups):
            for c in range(len(group.channels)):
                if mdf.masters_db.get(g) == c:          # the group's time channel
                    continue
                sig = _channel(mdf, g, c, path)
                t = np.asarray(sig.timestamps, float)
                if t.size < 2 or np.size(sig.samples) != t.size:
                    raise InputError(f"channel has {np.size(sig.samples)} samples at "
                                     f"{t.size} times; a signal needs at least 2", file=path, key=sig.name)
                if time is None:
                    time = t
                elif t.shape != time.shape or not np.allclose(t, time, rtol=0,
                                                              atol=1e-9 * max(time[-1], 1.0)):
                    times[sig.name] = t                 # checked once the speed is known
                samples = np.asarray(sig.samples)
                if not np.issubdtype(samples.dtype, np.number):
                    raise InputError("not a numeric channel", file=path, key=sig.name)
                signals.append((sig.name, samples.astype(float), (sig.unit or "").strip()))
    finally:
        mdf.close()
    if time is None:
        raise InputError("no channel in the MDF file", file=path)
    return FileSignals(time, signals, str(path), "master time", times=times)


#: Most bytes of samples the groups of one MDF file may declare (checked before reading: a
#: damaged record length can declare gigabytes).
MAX_SAMPLE_BYTES = 2 ** 30


def _check_declared_size(mdf, path) -> None:
    total = 0
    for g, group in enumerate(mdf.groups):
        cg = group.channel_group
        record = int(getattr(cg, "samples_byte_nr", 0)) + int(getattr(cg, "invalidation_bytes_nr", 0))
        total += int(getattr(cg, "cycles_nr", 0)) * record
        if total > MAX_SAMPLE_BYTES:
            raise InputError(f"channel group {g + 1} declares {total:.3g} bytes of samples; "
                             f"at most {MAX_SAMPLE_BYTES} in a file (damaged?)", file=path)


def _channel(mdf, g, c, path):
    """Channel ``c`` of group ``g``; a damaged block is an error naming the channel."""
    try:
        return mdf.get(group=g, index=c)
    except Exception as exc:       # asammdf raises many types on damaged blocks
        name = mdf.groups[g].channels[c].name
        raise InputError(f"cannot read the channel's samples ({type(exc).__name__}: "
                         f"{str(exc)[:60]}): damaged file?", file=path, key=name) from None


def _quiet_collect():
    """Collect garbage with finalizer errors of half-built asammdf objects silenced."""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        gc.collect()
    finally:
        sys.unraisablehook = hook


def write_raw_mdf(path, recording) -> None:
    """Write a :class:`RawRecording` as MDF 4.10, one group, one channel per signal."""
    from asammdf import MDF, Signal  # deferred: heavy package, loaded only when this format is used
    t = np.asarray(recording.time, float)
    sigs = [Signal(np.asarray(values, float), t, name=name, unit=unit)
            for name, values, unit, _ in written_signals(recording, cycle=False)]
    mdf = MDF(version="4.10")
    mdf.append(sigs, comment=recording.source or "powertrain")
    with atomic_path(path) as tmp:
        out = mdf.save(str(tmp), overwrite=True)
        if str(out) != str(tmp):
            os.replace(out, tmp)
    mdf.close()
