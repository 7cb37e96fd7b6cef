"""Raw run-up time data in the universal file format (pyuff): one dataset 58 per channel, name
= ID line 1, unit = ordinate units label, one time base (docs/reference/raw-data.md). A
truncated file is refused; datasets written here are numbered (ID line 4 ``powertrain dataset
K of N``) so that a file cut at a dataset boundary is found too.
"""

from __future__ import annotations

import gc
import os
import re
import warnings

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.raw_signals import FileSignals, written_signals
from powertrain.outputs import atomic_path

#: UFF specific data types (record 8/9 field 1) of the ordinate, by our quantity.
SPECIFIC_DATA_TYPE = {"displacement": 8, "force": 13, "velocity": 11, "acceleration": 12,
                      "rpm": 0, "tacho": 0, "trigger": 0}


def read_uff_signals(path, channel_map=None) -> FileSignals:
    """Signals of the datasets 58 of a UFF file."""
    import pyuff  # deferred: heavy package, loaded only when this format is used
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
    sets = [sets] if isinstance(sets, dict) else sets
    check_complete(path, len(sets))
    sets = [s for s in sets if s.get("type") == 58]
    if not sets:
        raise InputError("no dataset 58 (function at nodal DOF) in the universal file", file=path)
    _check_count(path, sets)
    time, signals = None, []
    for k, s in enumerate(sets):
        name = str(s.get("id1", "")).strip() or f"dataset {k + 1}"
        x = np.asarray(s["x"], float)
        data = np.asarray(s["data"])
        if x.size < 2 or data.shape != x.shape:
            raise InputError(f"{data.size} values at {x.size} abscissa points; a signal "
                             "needs at least 2", file=path, key=name)
        if np.iscomplexobj(data):
            raise InputError("complex data: expected a real time history", file=path, key=name)
        if time is None:
            time = x
        elif x.shape != time.shape or not np.allclose(x, time, rtol=0, atol=1e-9 * time[-1]):
            raise InputError("time base differs from the first channel's", file=path, key=name)
        unit = str(s.get("ordinate_axis_units_lab", "")).strip()
        signals.append((name, data.astype(float), unit))
    return FileSignals(time, signals, str(path), "abscissa")


_COUNT = re.compile(r"powertrain dataset (\d+) of (\d+)")
#: Start of a dataset: the ``-1`` delimiter line, then the dataset number (``58``, ``58b``).
_DATASET_START = re.compile(rb"(?:^|\n)[ ]*-1[ ]*\r?\n[ ]*(\d+)b?[ \r\n]")


def check_complete(path, n_read: int) -> None:
    """Refuse a truncated file: it must end with the ``-1`` delimiter, and every dataset that
    starts in it must have been read (pyuff silently drops an incomplete last one)."""
    with open(path, "rb") as fh:
        data = fh.read()
    if not data.rstrip().endswith(b"-1") or not data.rstrip()[:-2].endswith((b"\n", b" ")):
        raise InputError("file does not end with the '-1' delimiter line: truncated?", file=path)
    started = len(_DATASET_START.findall(data))
    if started > n_read:
        raise InputError(f"{started} datasets start in the file but only {n_read} could be "
                         "read: truncated or damaged", file=path)


def _check_count(path, sets) -> None:
    """Refuse numbered datasets (ID line 4, ``powertrain dataset K of N``) missing some of 1..N."""
    marks = [_COUNT.fullmatch(str(s.get("id4", "")).strip()) for s in sets]
    totals = {int(m.group(2)) for m in marks if m}
    if not totals:
        return
    seen = sorted(int(m.group(1)) for m in marks if m)
    if len(totals) > 1 or seen != list(range(1, max(totals) + 1)):
        raise InputError(f"{len(sets)} datasets, but the file's datasets are numbered "
                         f"{seen[:3]}... of {max(totals)}: truncated or damaged", file=path)


def write_raw_uff(path, recording) -> None:
    """Write a :class:`RawRecording` as datasets 58 (binary, double precision)."""
    import pyuff  # deferred: heavy package, loaded only when this format is used
    rows = written_signals(recording, cycle=False)
    sets = []
    for node, (name, values, unit, ch) in enumerate(rows, start=1):
        sets.append(pyuff.prepare_58(
            binary=1, id1=name, id2=recording.source or "powertrain",
            id4=f"powertrain dataset {node} of {len(rows)}", func_type=1,
            rsp_node=node, rsp_dir=0, ref_node=0, ref_dir=0, data=np.asarray(values, float),
            x=recording.time, abscissa_spec_data_type=17, abscissa_axis_units_lab="s",
            ordinate_spec_data_type=SPECIFIC_DATA_TYPE[ch.quantity if ch else name],
            ordinate_axis_units_lab=unit, orddenom_spec_data_type=0, z_axis_spec_data_type=0))
    with atomic_path(path) as tmp:
        os.unlink(tmp)               # pyuff appends to an existing file
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")     # pyuff leaves its file handles to the GC
            pyuff.UFF(str(tmp)).write_sets(sets, mode="add", force_double=True)
            gc.collect()
