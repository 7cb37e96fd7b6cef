"""Readers of raw time data (issue 12, item 1) and their bad-input messages."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import signals
from powertrain.errors import InputError
from powertrain.iotools.channel_map import parse_channel_name, read_channel_map
from powertrain.iotools.raw import detect_format, read_raw
from powertrain.iotools.raw_csv import write_raw_csv
from powertrain.iotools.raw_hdf5 import write_raw_hdf5
from powertrain.iotools.raw_mdf import write_raw_mdf
from powertrain.iotools.raw_uff import write_raw_uff
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.units import STANDARD_GRAVITY, to_si

WRITERS = {"csv": write_raw_csv, "h5": write_raw_hdf5, "uff": write_raw_uff,
           "mf4": write_raw_mdf}


def recording():
    t = np.arange(2000) / 1000.0
    chans = [RawChannel("a", "left", "active", "z", "acceleration", np.sin(7 * t), "g"),
             RawChannel("b", "right", "passive", "x", "velocity", 1e-3 * np.cos(t), "mm/s"),
             RawChannel("c", "gearbox", "active", "y", "displacement", 1e-4 * t, "mm"),
             RawChannel("d", "left", "active", "x", "force", 10 * t, "N")]
    return RawRecording(t, chans, 1000 + 10 * t, signals.tacho(40 * t, 1), "mem",
                        ["SYNTHETIC: test"])


@pytest.mark.parametrize("ext", list(WRITERS))
def test_round_trip_every_format(tmp_path, ext):
    rec = recording()
    path = tmp_path / f"rec.{ext}"
    WRITERS[ext](path, rec)
    assert detect_format(path) == {"csv": "csv", "h5": "hdf5", "uff": "uff", "mf4": "mdf"}[ext]
    back = read_raw(path)
    assert back.sample_rate == pytest.approx(1000.0)
    assert [(c.label, c.quantity, c.unit) for c in back.channels] == \
        [(c.label, c.quantity, c.unit) for c in rec.channels]
    for a, b in zip(back.channels, rec.channels):
        assert np.allclose(a.values, b.values, rtol=1e-7, atol=1e-12)
    assert np.allclose(back.rpm, rec.rpm) and np.allclose(back.tacho, rec.tacho)
    assert back.channel_matrix() is back.channel_matrix()     # rows of one block, no copy


def test_units_table_knows_vibration_units():
    assert to_si(1.0, "g", "acceleration") == STANDARD_GRAVITY
    assert to_si(1.0, "g", "mass") == 1e-3                      # still a gram for masses
    assert to_si(2.0, "mm/s", "velocity") == pytest.approx(2e-3)
    with pytest.raises(InputError, match="measures"):
        to_si(1.0, "bar", "acceleration")


def test_name_convention():
    spec = parse_channel_name("left.passive.z [g]")
    assert (spec.mount, spec.side, spec.direction, spec.unit) == ("left", "passive", "z", "g")
    assert parse_channel_name("left.Z").side == "active"
    assert parse_channel_name("Accel 1 [g]") is None


def test_channel_map_on_free_text_mdf(tmp_path):
    from asammdf import MDF, Signal
    t = np.arange(4000) / 2000.0
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.sin(50 * t), t, name="ACC_ENG_LEFT_Z", unit="g"),
                Signal(np.cos(50 * t), t, name="ACC_BODY_LEFT_Z", unit="m/s^2"),
                Signal(2000 + 0 * t, t, name="EngineSpeed", unit="1/min"),
                Signal(20 + 0 * t, t, name="OilTemp", unit="degC")])
    mdf.save(tmp_path / "run.mf4", overwrite=True)
    (tmp_path / "map.toml").write_text(
        'rpm = "EngineSpeed"\n[channels]\n'
        '"ACC_ENG_LEFT_Z" = { mount = "left", direction = "z", quantity = "acceleration" }\n'
        '"ACC_BODY_LEFT_Z" = { mount = "left", side = "passive", direction = "z" }\n')
    rec = read_raw(tmp_path / "run.mf4", read_channel_map(tmp_path / "map.toml"))
    assert [c.label for c in rec.channels] == ["left.z", "left.passive.z"]
    assert np.allclose(rec.channels[0].values, STANDARD_GRAVITY * np.sin(50 * t))
    assert np.allclose(rec.rpm, 2000.0)
    assert any("OilTemp" in c for c in rec.comments)


def _csv(tmp_path, header, rows, name="raw.csv"):
    p = tmp_path / name
    p.write_text(header + "\n" + "\n".join(rows) + "\n")
    return p


def _rows(n=64, cols=1, t=None):
    return [",".join([f"{k / 1000:g}", "1000"] + ["0.1"] * cols) for k in range(n)]


BAD = {
    "no mount": ("time [s],rpm [1/min],accel1 [g]", _rows(), "accel1", "maps to no mount"),
    "wrong unit": ("time [s],rpm [1/min],left.z [bar]", _rows(), "left.z", "unit"),
    "no unit": ("time [s],rpm [1/min],left.z", _rows(), "left.z", "no unit"),
    "time not increasing": ("time [s],rpm [1/min],left.z [g]",
                            _rows()[:10] + _rows()[5:20], "time", "not increasing"),
    "not a number": ("time [s],rpm [1/min],left.z [g]", _rows()[:10] + ["0.5,1000,abc"],
                     "column 3", "not a number"),
    "order curves, not raw": ("mount,direction,quantity,rpm,velocity_rms_mm_per_s",
                              ["left,z,order_2,1000,1.0"], "time", "wide raw CSV"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_csv_names_file_and_channel(tmp_path, case):
    header, rows, key, words = BAD[case]
    p = _csv(tmp_path, header, rows)
    with pytest.raises(InputError) as err:
        read_raw(p)
    msg = err.value.one_line()
    assert str(p) in msg and key in msg and words in msg and "\n" not in msg


def test_bad_channel_map(tmp_path):
    (tmp_path / "m.toml").write_text('[channels]\n"X" = { mount = "left", direction = "q" }\n')
    with pytest.raises(InputError, match="channels.X.direction"):
        read_channel_map(tmp_path / "m.toml")
    (tmp_path / "m.toml").write_text('[channels]\n"X" = { mount = "left", direction = "z" }\n')
    p = _csv(tmp_path, "time [s],rpm [1/min],left.z [g]", _rows())
    with pytest.raises(InputError, match="channels.X"):
        read_raw(p, read_channel_map(tmp_path / "m.toml"))


def test_other_formats_are_rejected(tmp_path):
    from powertrain.results.runup import RunupResult  # noqa: F401  (layout owner)
    p = tmp_path / "fake.mf4"
    p.write_bytes(b"MDF     4.10    " + b"\0" * 100)
    with pytest.raises(InputError, match="MDF"):
        read_raw(p)
    p = tmp_path / "fake.uff"
    p.write_text("    -1\n    58\ngarbage\n")
    with pytest.raises(InputError, match=str(p)):
        read_raw(p)


def _uff_starts(data: bytes) -> list:
    import re
    return [m.start() for m in re.finditer(rb"(?:^|\n)[ ]*-1[ ]*\n[ ]*58", data)]


@pytest.mark.parametrize("cut", ["mid-dataset", "between datasets"])
def test_truncated_uff_is_refused(tmp_path, cut):
    """Issue 18: a UFF cut at 90 % was read with its last channel silently dropped. A cut
    inside a dataset misses the closing delimiter; a cut exactly between two datasets is
    found by the numbering (ID line 4) of the datasets we write."""
    path = tmp_path / "rec.uff"
    write_raw_uff(path, recording())
    data = path.read_bytes()
    starts = _uff_starts(data)
    path.write_bytes(data[:int(0.9 * len(data))] if cut == "mid-dataset"
                     else data[:starts[-1] + 1])
    with pytest.raises(InputError, match="truncated") as e:
        read_raw(path)
    assert e.value.file == str(path)


@pytest.mark.parametrize("edit,key", [
    (lambda h5: h5.attrs.__setitem__("comments", "not json"), "/@comments"),
    (lambda h5: (h5.__delitem__("time"), h5.__setitem__("time", __import__("h5py").SoftLink(
        "/nowhere"))), "time"),
    (lambda h5: (h5.__delitem__("channels"), h5.__setitem__("channels", np.ones(3))),
     "channels"),
    (lambda h5: (h5.__delitem__("time"), h5.create_dataset("time", shape=(2 ** 40,),
                                                           chunks=(1024,), dtype="f8")),
     "time"),
], ids=["comments not JSON", "dangling link", "channels a dataset", "2**40 declared"])
def test_bad_raw_hdf5_names_file_and_key(tmp_path, edit, key):
    import h5py
    path = tmp_path / "rec.h5"
    write_raw_hdf5(path, recording())
    with h5py.File(path, "r+") as h5:
        edit(h5)
    with pytest.raises(InputError) as e:
        read_raw(path)
    assert (e.value.file, e.value.key) == (str(path), key)


def test_fifo_is_refused_without_blocking(tmp_path):
    import os
    os.mkfifo(tmp_path / "run.csv")
    with pytest.raises(InputError, match="not a regular file"):
        read_raw(tmp_path / "run.csv")
