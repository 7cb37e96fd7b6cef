"""Raw run-up time data in any format (HDF5, MDF4, UFF, wide CSV, told by the first bytes)
into a :class:`~powertrain.models.recording.RawRecording`: the format's reader lists the
signals, mapped here to channels by name or channel map (:mod:`powertrain.iotools.channel_map`)
and converted to SI.
"""

from __future__ import annotations

import os

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.channel_map import (
    ChannelMap,
    parse_channel_name,
    quantity_of_unit,
    read_channel_map,
    split_unit,
)
from powertrain.iotools.raw_csv import read_csv_signals, write_raw_csv
from powertrain.iotools.raw_hdf5 import read_hdf5_signals, write_raw_hdf5
from powertrain.iotools.raw_mdf import read_mdf_signals, write_raw_mdf
from powertrain.iotools.raw_signals import FileSignals
from powertrain.iotools.raw_uff import read_uff_signals, write_raw_uff
from powertrain.iotools.textfile import check_regular_file
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.units import to_si

#: Start of the comment listing the channels a channel map leaves out.
IGNORED_NOTE = "channels not in the channel map, ignored: "
_HDF5 = b"\x89HDF\r\n\x1a\n"
_MDF = b"MDF     "


def write_raw(path, recording, *, synthetic=True) -> None:
    """Write a :class:`RawRecording` as its suffix says: ``.csv``, ``.uff``/``.unv`` (dataset
    58), ``.mf4``/``.mdf`` (MDF4), else raw HDF5 (marked ``synthetic`` if so)."""
    suffix = os.path.splitext(str(path))[1].lower()
    note = recording.comments[0] if recording.comments else ""
    if suffix == ".csv":
        write_raw_csv(path, recording, comment=note)
    elif suffix in (".uff", ".unv"):
        write_raw_uff(path, recording)
    elif suffix in (".mf4", ".mdf"):
        write_raw_mdf(path, recording)
    else:
        write_raw_hdf5(path, recording, description=note, synthetic=synthetic)


def detect_format(path) -> str:
    """``hdf5``, ``mdf``, ``uff`` or ``csv`` from the first bytes of a regular file."""
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(512)
    except FileNotFoundError:
        raise InputError("file not found", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc})", file=path) from None
    if head.startswith(_HDF5):
        return "hdf5"
    if head.startswith(_MDF):
        return "mdf"
    first = head.lstrip(b" \r\n\t").split(b"\n", 1)[0].strip()
    if first == b"-1":
        return "uff"
    return "csv"


def read_raw(path, channel_map: ChannelMap | None = None, *, rpm: str | None = None,
             tacho: str | None = None, cycle_reference: str | None = None,
             trigger: str | None = None, map_option: str = "--channels") -> RawRecording:
    """Read a raw run-up recording in any supported format.

    Parameters
    ----------
    path : str or Path
        Wide CSV, raw HDF5, UFF (dataset 58) or MDF4 file.
    channel_map : ChannelMap, str or Path, optional
        File channel name -> mount, side, direction, quantity, or its TOML file (default: the
        name convention).
    rpm, tacho : str, optional
        Name of the speed [rpm] or tacho channel (default: the map's, else a channel named
        ``rpm`` / ``tacho``).
    cycle_reference : str, optional
        Name of a once-per-cycle pulse channel [V] (cam or injection signal; default a
        channel named ``cycle``).
    trigger : str, optional
        Name of a trigger channel [V] (default a channel named ``trigger``).
    map_option : str
        The command-line option that gives a channel map, named in the hints of errors.

    Returns
    -------
    RawRecording
        Validated, SI.
    """
    check_regular_file(path)
    path = str(path)
    if isinstance(channel_map, (str, os.PathLike)):
        channel_map = read_channel_map(channel_map)
    elif channel_map is not None and not isinstance(channel_map, ChannelMap):
        raise InputError(f"expected a channel map or its file, got "
                         f"{type(channel_map).__name__}", key="--channels")
    fmt = detect_format(path)
    reader = {"hdf5": read_hdf5_signals, "mdf": read_mdf_signals,
              "uff": read_uff_signals}.get(fmt, read_csv_signals)
    found = (read_hdf5_signals(path, channel_map, map_option=map_option,
                               extra=(trigger, cycle_reference)) if fmt == "hdf5"
             else reader(path, channel_map))
    return assemble(found, channel_map, rpm=rpm, tacho=tacho, cycle_reference=cycle_reference,
                    trigger=trigger, map_option=map_option)


def _find(signals, wanted):
    """Index of the signal named ``wanted``, with or without its unit bracket, exactly, else
    ignoring case."""
    for same in (str.__eq__, lambda a, b: a.casefold() == b.casefold()):
        for i, (name, _, _) in enumerate(signals):
            if same(name, wanted) or same(split_unit(name)[0], wanted):
                return i
    return None


def _pick_speed(found: FileSignals, cmap, rpm, tacho, cycle_reference=None, trigger=None):
    signals = list(found.signals)
    rpm_name = rpm or (cmap.rpm if cmap else None)
    tacho_name = tacho or (cmap.tacho if cmap else None)
    out = {}
    for kind, wanted, default in (("rpm", rpm_name, "rpm"), ("tacho", tacho_name, "tacho"),
                                  ("trigger", trigger, "trigger"),
                                  ("cycle_reference", cycle_reference, "cycle")):
        i = _find(signals, wanted or default) if wanted or default else None
        if i is None:
            if wanted:
                raise InputError(f"no channel named {wanted!r} for the "
                                 f"{kind.replace('_', ' ')}", file=found.source, key=wanted)
            continue
        name, values, unit = signals.pop(i)
        values = np.asarray(values, float).ravel()
        if kind == "rpm":
            unit = unit or "rpm"
            values = to_si(values, unit, "angular_speed", file=found.source, key=name) * 60.0 / (2.0 * np.pi)
        elif unit:
            values = to_si(values, unit, "voltage", file=found.source, key=name)
        out[kind] = (name, values)
    return out, signals


def _same_time(a, b) -> bool:
    return a.shape == b.shape and (b.size == 0 or np.allclose(a, b, rtol=0, atol=1e-9 * max(abs(b[-1]), 1.0)))


def _vibration_time(found: FileSignals, signals):
    """The one time base of the vibration channels (only a speed channel may have its own)."""
    if not signals:
        return found.time
    first = signals[0][0]
    time = found.times.get(first, found.time)
    for name, _, _ in signals[1:]:
        if not _same_time(np.asarray(found.times.get(name, found.time)), np.asarray(time)):
            raise InputError(f"time base differs from channel {first!r}'s (only the speed or "
                             "tacho channel may have its own; it is resampled)", file=found.source, key=name)
    return time


def _onto_time(found: FileSignals, speed, time):
    """``(speed values, time, keep)``: speed/tacho channels with their own time base
    interpolated onto ``time``; vibration samples outside their record dropped (``keep``)."""
    time = np.asarray(time, float)
    keep = slice(None)
    out = {}
    for kind, (name, values) in speed.items():
        own = found.times.get(name)
        if own is None or _same_time(np.asarray(own, float), time):
            out[kind] = values
            continue
        own = np.asarray(own, float).ravel()
        if (own.shape != values.shape or own.size < 2 or not np.all(np.isfinite(own))
                or np.any(np.diff(own) <= 0)):
            raise InputError("the channel's own time base must increase and have one value "
                             "per sample", file=found.source, key=name)
        inside = (time >= own[0]) & (time <= own[-1])
        if not inside.any():
            raise InputError("the channel's time base does not overlap the vibration "
                             "channels'", file=found.source, key=name)
        lo, hi = np.flatnonzero(inside)[[0, -1]]
        if lo > 0 or hi < time.size - 1:
            keep = slice(max(lo, keep.start or 0), min(hi + 1, keep.stop or time.size))
            found.comments.append(f"vibration samples outside the {name} record "
                                  f"({own[0]:g}..{own[-1]:g} s) dropped")
        rate = (own.size - 1) / (own[-1] - own[0])
        found.comments.append(f"{name} resampled (linear) from its own time base "
                              f"({rate:.4g} Hz) onto the vibration channels'")
        out[kind] = np.interp(time, own, values)
    return {k: v[keep] for k, v in out.items()}, time[keep], keep


def assemble(found: FileSignals, cmap: ChannelMap | None = None, *, rpm=None,
             tacho=None, cycle_reference=None, trigger=None, map_option="--channels") -> RawRecording:
    """Map the signals of a file to mount channels in SI (see :func:`read_raw`)."""
    src = found.source
    speed, signals = _pick_speed(found, cmap, rpm, tacho, cycle_reference, trigger)
    speed, time, keep = _onto_time(found, speed, _vibration_time(found, signals))
    channels, ignored, used = [], [], set()
    for name, values, file_unit in signals:
        if cmap is not None and cmap.channels:
            spec = cmap.channels.get(name) or cmap.channels.get(split_unit(name)[0])
            if spec is None:
                spec = parse_channel_name(name)
                if spec is None:
                    ignored.append(name)
                    continue
            used |= {name, split_unit(name)[0]}
        else:
            spec = parse_channel_name(name)
            if spec is None:
                raise InputError("channel name maps to no mount (name it MOUNT.DIRECTION "
                                 f"[UNIT], e.g. 'left.z [m/s^2]', or give a {map_option} "
                                 "map)", file=src, key=name)
        unit = spec.unit or file_unit or split_unit(name)[1]
        if not unit:
            raise InputError("channel declares no unit (add it in brackets or as 'unit' in "
                             "the channel map)", file=src, key=name)
        quantity = quantity_of_unit(unit, file=src, key=name)
        if spec.quantity is not None and spec.quantity != quantity:
            raise InputError(f"unit {unit!r} measures {quantity}, but the channel map says "
                             f"{spec.quantity}", file=src, key=name)
        dimension = "length" if quantity == "displacement" else quantity
        si = to_si(np.asarray(values, float)[keep], unit, dimension, file=src, key=name)
        channels.append(RawChannel(name, spec.mount, spec.side, spec.direction, quantity, si, unit))
    if cmap is not None:
        for name in cmap.channels:
            if name not in used:
                raise InputError("channel of the channel map not found in the file",
                                 file=cmap.source or src, key=f"channels.{name}")
    if channels and len({c.values.size for c in channels}) == 1:
        for ch, row in zip(channels, RawRecording.rows([c.values for c in channels])):
            ch.values = row
    comments = list(found.comments)
    if ignored:
        comments.append(IGNORED_NOTE + ", ".join(ignored))
    rec = RawRecording(time, channels, speed.get("rpm"), speed.get("tacho"), src, comments,
                       speed.get("cycle_reference"), speed.get("trigger"))
    return rec.validate(found.time_name)
