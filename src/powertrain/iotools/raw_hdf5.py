"""Raw run-up time data in HDF5: the ``powertrain-raw`` layout :func:`write_raw_hdf5` writes,
or any HDF5 file read with a channel map naming its datasets (docs/reference/raw-data.md).

A speed or tacho dataset may have its own time base (its attribute ``time`` names the dataset
of its sample times); it is resampled onto ``/time`` (:func:`powertrain.iotools.raw.assemble`).
"""

from __future__ import annotations

import json

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.raw_signals import FileSignals, written_signals
from powertrain.outputs import atomic_path
from powertrain.provenance import stamp_hdf5
from powertrain.units import to_si

FORMAT = "powertrain-raw"


#: Most values one raw HDF5 file may declare over the datasets read (a declared shape is
#: checked before reading: a chunked dataset of 2**40 unwritten values is a few bytes).
MAX_VALUES = 2 ** 27


def _unit(ds):
    u = ds.attrs.get("unit", "")
    return u.decode() if isinstance(u, bytes) else str(u)


def read_hdf5_signals(path, channel_map=None, *, map_option="--channels", extra=()) -> FileSignals:
    """Signals of a raw HDF5 file (docs/reference/raw-data.md): ``map_option`` is named in the
    hint when a channel map is needed; ``extra`` names more datasets read if present."""
    import h5py  # deferred: heavy package, loaded only when this format is used
    try:
        h5 = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"cannot open HDF5 file ({exc})", file=path) from None
    with h5:
        try:
            return _read(h5, path, channel_map, map_option, tuple(n for n in extra if n))
        except (KeyError, OSError, RuntimeError, TypeError) as exc:   # broken links, unreadable objects
            raise InputError(f"unreadable HDF5 object ({str(exc)[:80]})", file=path) from None


def _read(h5, path, channel_map, map_option, extra):
    fmt = _text_attr(h5, "format", path)
    if fmt == "powertrain-runup":
        raise InputError("this is a run-up result (order curves), not raw time data; "
                         "give it to 'compare' or 'diagnose'", file=path, key="format")
    if fmt == FORMAT:
        return _read_own(h5, path, extra)
    if channel_map is None:
        raise InputError(f"not a '{FORMAT}' HDF5 file; give a {map_option} map naming its "
                         "datasets", file=path, key="format")
    return _read_mapped(h5, path, channel_map, extra)


def _text_attr(h5, name, path, default=""):
    value = h5.attrs.get(name, default)
    value = value.decode(errors="replace") if isinstance(value, bytes) else value
    if not isinstance(value, str):
        raise InputError("expected a text attribute", file=path, key=f"/@{name}")
    return value


class _Budget:
    """Values left to read from one file (:data:`MAX_VALUES` in all)."""

    def __init__(self):
        self.left = MAX_VALUES


def _dataset(h5, name, path, budget):
    obj = h5.get(name)
    if obj is None or not hasattr(obj, "shape") or not hasattr(obj, "dtype"):
        raise InputError("dataset not found (or a group, or a broken link)", file=path, key=name)
    if len(obj.shape or ()) != 1 or obj.dtype.kind not in "iuf":
        raise InputError("expected a 1-D numeric dataset", file=path, key=name)
    if obj.shape[0] > budget.left:
        raise InputError(f"declares {obj.shape[0]:.3g} values; at most {MAX_VALUES} in a "
                         "file", file=path, key=name)
    budget.left -= obj.shape[0]
    return np.asarray(obj[()], float)


def _comments(h5, path):
    text = _text_attr(h5, "comments", path, "[]")
    try:
        comments = json.loads(text)
    except ValueError:
        raise InputError("not a JSON list of strings", file=path, key="/@comments") from None
    if not isinstance(comments, list) or not all(isinstance(c, str) for c in comments):
        raise InputError("not a JSON list of strings", file=path, key="/@comments")
    return comments


def _flag_attr(h5, name, path) -> bool:
    """A yes/no attribute: a boolean or the integer 0 or 1 (absent: no)."""
    value = h5.attrs.get(name, False)
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, (int, np.integer)) and value in (0, 1)):
        return bool(value)
    raise InputError("expected a boolean attribute (true or false)", file=path, key=f"/@{name}")


def _time(h5, name, path, budget):
    """The sample times of the vibration channels: at least two values."""
    time = _dataset(h5, name, path, budget)
    if time.size < 2:
        raise InputError(f"has {time.size} sample time{'s' if time.size != 1 else ''}; "
                         "at least 2 needed", file=path, key=name)
    return time


def _read_own(h5, path, extra=()):
    budget = _Budget()
    time = _time(h5, "time", path, budget)
    unit = _unit(h5["time"]) or "s"
    time = to_si(time, unit, "time", file=path, key="time")
    signals, times = [], {}
    for name in dict.fromkeys(("rpm", "tacho", "cycle", "trigger", *extra)):
        if name in h5 and not name.startswith("channels"):
            signals.append((name, _dataset(h5, name, path, budget), _unit(h5[name])))
            _own_time(h5, name, path, times, budget)
    group = h5.get("channels")
    if group is None or not hasattr(group, "items") or hasattr(group, "shape"):
        raise InputError("no /channels group", file=path, key="channels")
    for name in group:
        key = f"channels/{name}"
        signals.append((name, _dataset(h5, key, path, budget), _unit(h5[key])))
    comments = _comments(h5, path)
    if _flag_attr(h5, "synthetic", path) and not any("synthetic" in c.lower() for c in comments):
        comments.append("SYNTHETIC")
    return FileSignals(time, signals, str(path), "time", comments, times)


def _own_time(h5, name, path, times, budget):
    """Record the own time base [s] of dataset ``name`` its ``time`` attribute names, if any."""
    ref = h5[name].attrs.get("time")
    if ref is None:
        return
    ref = ref.decode() if isinstance(ref, bytes) else str(ref)
    times[name] = to_si(_dataset(h5, ref, path, budget), _unit(h5[ref]) or "s", "time", file=path, key=ref)


def _read_mapped(h5, path, cmap, extra=()):
    budget = _Budget()
    tname = cmap.time or "time"
    time = _time(h5, tname, path, budget)
    signals, times = [], {}
    named = [cmap.rpm, cmap.tacho, *cmap.channels]
    for name in named + [n for n in extra if n in h5 and n not in named]:
        if name:
            signals.append((name, _dataset(h5, name, path, budget), _unit(h5[name])))
    for name in (cmap.rpm, cmap.tacho, *extra):
        if name and name in h5:
            _own_time(h5, name, path, times, budget)
    return FileSignals(time, signals, str(path), tname, times=times)


def write_raw_hdf5(path, recording, *, description: str = "", synthetic: bool = False) -> None:
    """Write a :class:`RawRecording` in the ``powertrain-raw`` layout, values in each channel's
    unit."""
    import h5py  # deferred: heavy package, loaded only when this format is used
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as h5:
            a = h5.attrs
            stamp_hdf5(a, FORMAT)
            a["description"] = description
            a["synthetic"] = bool(synthetic or recording.synthetic)
            a["comments"] = json.dumps(list(recording.comments))
            h5.create_dataset("time", data=recording.time).attrs["unit"] = "s"
            g = h5.create_group("channels", track_order=True)
            for name, values, unit, ch in written_signals(recording):
                ds = (h5 if ch is None else g).create_dataset(name, data=values)
                ds.attrs["unit"] = unit
                for k in ("mount", "side", "direction", "quantity") if ch else ():
                    ds.attrs[k] = getattr(ch, k)
