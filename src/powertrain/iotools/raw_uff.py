"""Raw run-up time data in the universal file format, dataset 58 (read and written by pyuff).

Each dataset 58 holds one channel: its name is ID line 1 (``id1``), its unit the ordinate
units label, its time base the even abscissa (``abscissa_min``, ``abscissa_inc``) or the
abscissa values. All channels must share one time base. Names follow the
``MOUNT.DIRECTION`` convention or a channel map; ``rpm`` and ``tacho`` name the speed and
tacho channels unless the map (or ``--rpm/--tacho``) says otherwise.
"""

from __future__ import annotations

import gc
import warnings

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.raw import FileSignals

#: UFF specific data types (record 8/9 field 1) of the ordinate, by our quantity.
SPECIFIC_DATA_TYPE = {"displacement": 8, "force": 13, "velocity": 11, "acceleration": 12,
                      "rpm": 0, "tacho": 0}


def read_uff_signals(path, channel_map=None) -> FileSignals:
    """Signals of the datasets 58 of a UFF file."""
    import pyuff
    problem = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # pyuff leaves its file handles to the GC
        try:
            sets = pyuff.UFF(str(path)).read_sets()
        except Exception as exc:   # pyuff raises bare Exceptions on malformed files
            problem = str(exc).splitlines()[0][:80] if str(exc) else type(exc).__name__
        gc.collect()
    if problem is not None:
        raise InputError(f"not a readable universal file ({problem})", file=path)
    if isinstance(sets, dict):
        sets = [sets]
    sets = [s for s in sets if s.get("type") == 58]
    if not sets:
        raise InputError("no dataset 58 (function at nodal DOF) in the universal file",
                         file=path)
    time = None
    signals = []
    for k, s in enumerate(sets):
        name = str(s.get("id1", "")).strip() or f"dataset {k + 1}"
        x = np.asarray(s["x"], float)
        data = np.asarray(s["data"])
        if np.iscomplexobj(data):
            raise InputError("complex data: expected a real time history", file=path, key=name)
        if time is None:
            time = x
        elif x.shape != time.shape or not np.allclose(x, time, rtol=0, atol=1e-9 * time[-1]):
            raise InputError("time base differs from the first channel's", file=path, key=name)
        unit = str(s.get("ordinate_axis_units_lab", "")).strip()
        signals.append((name, data.astype(float), unit))
    return FileSignals(time, signals, str(path), "abscissa")


def write_raw_uff(path, recording) -> None:
    """Write a :class:`RawRecording` as datasets 58 (binary, double precision)."""
    import os

    import pyuff

    from powertrain.iotools.atomic import atomic_path
    from powertrain.units import from_si
    rows = []
    if recording.rpm is not None:
        rows.append(("rpm", recording.rpm, "rpm", "rpm"))
    if recording.tacho is not None:
        rows.append(("tacho", recording.tacho, "V", "tacho"))
    for ch in recording.channels:
        dim = "length" if ch.quantity == "displacement" else ch.quantity
        rows.append((ch.label, from_si(ch.values, ch.unit, dim), ch.unit, ch.quantity))
    sets = []
    for node, (name, values, unit, kind) in enumerate(rows, start=1):
        sets.append(pyuff.prepare_58(
            binary=1, id1=name, id2=recording.source or "powertrain", func_type=1,
            rsp_node=node, rsp_dir=0, ref_node=0, ref_dir=0, data=np.asarray(values, float),
            x=recording.time, abscissa_spec_data_type=17, abscissa_axis_units_lab="s",
            ordinate_spec_data_type=SPECIFIC_DATA_TYPE[kind], ordinate_axis_units_lab=unit,
            orddenom_spec_data_type=0, z_axis_spec_data_type=0))
    with atomic_path(path) as tmp:
        os.unlink(tmp)               # pyuff appends to an existing file
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")     # pyuff leaves its file handles to the GC
            pyuff.UFF(str(tmp)).write_sets(sets, mode="add", force_double=True)
            gc.collect()
