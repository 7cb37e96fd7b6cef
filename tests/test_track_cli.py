"""``powertrain track`` end to end: outputs, formats, bad input (issue 12, items 1-4)."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from tolerances import TRACKED_ORDER_DB

from benchmarks import signals
from powertrain.cli import main
from powertrain.iotools.raw_csv import write_raw_csv
from powertrain.iotools.raw_hdf5 import write_raw_hdf5
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.results.tracked import TrackedOrders


def run(*args):
    return CliRunner().invoke(main, ["track", *map(str, args)])


@pytest.fixture(scope="module")
def analytic(tmp_path_factory):
    folder = tmp_path_factory.mktemp("raw")
    path = folder / "sweep.csv"
    write_raw_csv(path, signals.analytic_sweep(duration=6.0, rpm0=1500.0, rpm1=4500.0),
                  comment="SYNTHETIC: analytic sweep")
    return path


def test_track_writes_csv_hdf5_and_plots(tmp_path, analytic):
    out = {k: tmp_path / f"o.{k}" for k in ("csv", "h5", "png", "map.png")}
    r = run(analytic, "--quantity", "acceleration", "--orders", "0.5:8:0.5", "--csv",
            out["csv"], "--out", out["h5"], "--plot", out["png"], "--map", out["map.png"])
    assert r.exit_code == 0, r.output
    assert "tracked RMS" in r.output and "[SYNTHETIC]" in r.output
    lines = out["csv"].read_text().splitlines()
    assert lines[0].startswith("# tracked by powertrain track (cot)")
    header = [ln for ln in lines if not ln.startswith("#")][0]
    assert header == "mount,direction,quantity,rpm,acceleration_rms_m_per_s2"
    tr = TrackedOrders.from_hdf5(out["h5"])
    assert tr.orders.size == 16 and tr.amplitude.shape[1] == 1
    assert out["png"].stat().st_size > 10_000 and out["map.png"].stat().st_size > 10_000


def test_as_velocity_and_side_column(tmp_path):
    t, rpm, th = signals.linear_sweep(4096.0, 6.0, 1500.0, 4500.0)
    rec = RawRecording(t, [
        RawChannel("a", "left", "active", "z", "acceleration", np.cos(2 * th), "m/s^2"),
        RawChannel("b", "left", "passive", "z", "acceleration", np.cos(4 * th), "g")], rpm)
    write_raw_hdf5(tmp_path / "r.h5", rec)
    r = run(tmp_path / "r.h5", "--orders", "2,4", "--as", "velocity", "--csv", tmp_path / "v.csv",
            "--quiet")
    assert r.exit_code == 0, r.output
    text = (tmp_path / "v.csv").read_text().splitlines()
    assert "mount,side,direction,quantity,rpm,velocity_rms_mm_per_s" in text
    assert any(ln.startswith("left,passive,z,order_4,") for ln in text)


def test_mixed_quantities_need_a_choice(tmp_path, analytic):
    r = run(analytic, "--csv", tmp_path / "x.csv", "--quiet")
    assert r.exit_code == 1 and "--quantity" in r.output
    assert not (tmp_path / "x.csv").exists()


def _bad_files(folder):
    t, rpm, th = signals.linear_sweep(2048.0, 4.0, 1500.0, 3000.0)
    cases = {}
    p = folder / "tacho-flat.csv"
    write_raw_csv(p, RawRecording(t, [RawChannel("a", "left", "active", "z", "acceleration",
                                                 np.cos(th), "m/s^2")], None, np.ones(t.size)))
    cases["tacho with no edges"] = (p, ["--tacho", "tacho", "--pulses-per-rev", "1"],
                                    "tacho", "no edges")
    p = folder / "short.csv"
    write_raw_csv(p, RawRecording(t[:400], [RawChannel("a", "left", "active", "z", "velocity",
                                                       np.cos(th[:400]), "mm/s")], rpm[:400]))
    cases["speed never in range"] = (p, [], "rpm", "never passes")
    p = folder / "nomount.csv"
    p.write_text("time [s],rpm [1/min],sensor7 [g]\n" + "\n".join(
        f"{k / 1000},{1500},{0.1}" for k in range(100)) + "\n")
    cases["channel maps to no mount"] = (p, [], "sensor7", "no mount")
    p = folder / "kind.csv"
    p.write_text("time [s],rpm [1/min],left.z [kPa]\n" + "\n".join(
        f"{k / 1000},{1500},{0.1}" for k in range(100)) + "\n")
    cases["unit of the wrong kind"] = (p, [], "left.z", "kPa")
    p = folder / "backwards.csv"
    p.write_text("time [s],rpm [1/min],left.z [g]\n" + "\n".join(
        f"{(k % 50) / 1000},{1500},{0.1}" for k in range(100)) + "\n")
    cases["time not increasing"] = (p, [], "time", "not increasing")
    p = folder / "runup.h5"
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.workflows.runup import run_runup
    run_runup(read_engine(DEFAULT_ENGINE_PATH), [2000.0, 2500.0], solver="harmonic").to_hdf5(p)
    cases["file of another format"] = (p, [], "format", "run-up result")
    return cases


def test_bad_input_one_line_exit_1_no_output(tmp_path):
    for name, (path, extra, key, words) in _bad_files(tmp_path).items():
        out = tmp_path / f"{path.stem}-out.csv"
        r = run(path, *extra, "--csv", out, "--quiet")
        lines = [ln for ln in r.output.splitlines() if ln.strip()]
        assert r.exit_code == 1, (name, r.output)
        assert len(lines) == 1, (name, r.output)
        assert str(path.name) in lines[0] and key in lines[0] and words in lines[0], \
            (name, lines[0])
        assert not out.exists(), name


def _order2_level(csv_path, rpm_step=100.0):
    rows = [ln.split(",") for ln in csv_path.read_text().splitlines()
            if ",order_2," in ln and not ln.startswith("#")]
    return np.array([float(r[-1]) for r in rows])


def test_lab_units_m_s2_and_u_min(tmp_path):
    t, rpm, th = signals.linear_sweep(2048.0, 4.0, 1500.0, 3000.0)
    path = tmp_path / "lab.csv"
    body = np.column_stack([t, rpm, 1000.0 * np.cos(2 * th)])        # mm/s² amplitude 1 m/s²
    np.savetxt(path, body, delimiter=",", fmt="%.9g", comments="",
               header="time [s],rpm [U/min],left.z [mm/s²]", encoding="utf-8")
    r = run(path, "--orders", "2", "--csv", tmp_path / "o.csv", "--quiet")
    assert r.exit_code == 0, r.output
    level = _order2_level(tmp_path / "o.csv")
    assert level.size > 5
    assert np.max(np.abs(20 * np.log10(level * np.sqrt(2)))) <= TRACKED_ORDER_DB


def _can_speed_mdf(path, *, vibration_bases_differ=False):
    """Vibration at 4096 Hz in one MDF4 group, engine speed at 100 Hz (CAN) in its own,
    starting 3 ms later and ending 0.5 s earlier than the vibration record."""
    from asammdf import MDF, Signal
    t, rpm, th = signals.linear_sweep(4096.0, 6.0, 1500.0, 4500.0)
    t_can = np.arange(0.003, 5.5, 0.01)
    rpm_can = np.interp(t_can, t, rpm)
    vib = [Signal(np.cos(2 * th), t, name="left.z", unit="m/s²")]
    if vibration_bases_differ:
        vib.append(Signal(np.cos(2 * th[::2]), t[::2], name="right.z", unit="m/s^2"))
    mdf = MDF(version="4.10")
    mdf.append(vib[:1])
    mdf.append([Signal(rpm_can, t_can, name="EngSpeed", unit="1/min")])
    if vibration_bases_differ:
        mdf.append(vib[1:])
    mdf.save(str(path), overwrite=True)
    mdf.close()


def test_speed_channel_on_its_own_time_base_mdf4(tmp_path):
    _can_speed_mdf(tmp_path / "can.mf4")
    r = run(tmp_path / "can.mf4", "--rpm", "EngSpeed", "--orders", "2", "--csv",
            tmp_path / "o.csv")
    assert r.exit_code == 0, r.output
    level = _order2_level(tmp_path / "o.csv")
    assert level.size > 20
    assert np.max(np.abs(20 * np.log10(level * np.sqrt(2)))) <= TRACKED_ORDER_DB
    text = (tmp_path / "o.csv").read_text()
    assert "EngSpeed resampled (linear) from its own time base (100 Hz)" in text
    assert "outside the EngSpeed record" in text                   # said, not silent
    _can_speed_mdf(tmp_path / "bad.mf4", vibration_bases_differ=True)
    r = run(tmp_path / "bad.mf4", "--rpm", "EngSpeed", "--csv", tmp_path / "b.csv", "--quiet")
    assert r.exit_code == 1 and "right.z" in r.output and "time base" in r.output
    assert len(r.output.strip().splitlines()) == 1 and not (tmp_path / "b.csv").exists()


def test_speed_channel_on_its_own_time_base_hdf5(tmp_path):
    import h5py
    t, rpm, th = signals.linear_sweep(4096.0, 6.0, 1500.0, 4500.0)
    rec = RawRecording(t, [RawChannel("a", "left", "active", "z", "acceleration",
                                      np.cos(2 * th), "m/s^2")], None)
    write_raw_hdf5(tmp_path / "r.h5", rec)
    t_can = np.arange(0.0, 6.0, 0.01)
    with h5py.File(tmp_path / "r.h5", "a") as h5:
        h5.create_dataset("rpm_time", data=t_can * 1e3).attrs["unit"] = "ms"
        ds = h5.create_dataset("rpm", data=np.interp(t_can, t, rpm))
        ds.attrs["unit"] = "rpm"
        ds.attrs["time"] = "rpm_time"
    r = run(tmp_path / "r.h5", "--orders", "2", "--csv", tmp_path / "o.csv", "--quiet")
    assert r.exit_code == 0, r.output
    level = _order2_level(tmp_path / "o.csv")
    assert level.size > 20
    assert np.max(np.abs(20 * np.log10(level * np.sqrt(2)))) <= TRACKED_ORDER_DB


def test_overall_and_order_spectrum_options(tmp_path, analytic):
    out = {k: tmp_path / k for k in ("t.csv", "s.csv", "t.h5")}
    r = run(analytic, "--quantity", "velocity", "--orders", "1,2,4", "--overall",
            "--spectrum-at", "3000", "--spectrum-at", "3500", "--spectrum-out", out["s.csv"],
            "--csv", out["t.csv"], "--out", out["t.h5"])
    assert r.exit_code == 0, r.output
    assert " overall " in r.output
    rows = [ln.split(",") for ln in out["t.csv"].read_text().splitlines()
            if not ln.startswith("#")]
    assert rows[0] == ["mount", "direction", "quantity", "rpm", "velocity_rms_mm_per_s"]
    kinds = {row[2] for row in rows[1:]}
    assert kinds == {"order_1", "order_2", "order_4", "synthesis", "overall"}
    assert TrackedOrders.from_hdf5(out["t.h5"]).overall.shape[1] == 1
    spec = [ln.split(",") for ln in out["s.csv"].read_text().splitlines()
            if not ln.startswith("#")]
    assert spec[0] == ["mount", "direction", "rpm", "order", "velocity_rms_mm_per_s"]
    assert {row[2] for row in spec[1:]} == {"3000", "3500"}
    at2 = [float(row[4]) for row in spec[1:] if row[2] == "3000" and row[3] == "2"]
    expected = signals.ANALYTIC_VELOCITY[3] * 1e3 / np.sqrt(2)             # order 2 [mm/s]
    assert abs(20 * np.log10(at2[0] / expected)) <= TRACKED_ORDER_DB
    c = CliRunner().invoke(main, ["compare", str(out["t.csv"]), "--step", "500", "--quiet"])
    assert c.exit_code == 0, c.output                                    # overall rows skipped


@pytest.mark.parametrize("extra, key", [
    (["--spectrum-at", "3000"], "--spectrum-out"),
    (["--spectrum-at", "9000", "--spectrum-out", "s.csv"], "--spectrum-at"),
    (["--overall-band", "900:5"], "--overall-band"),
    (["--overall-band", "a:b"], "--overall-band"),
])
def test_overall_and_spectrum_bad_options(tmp_path, analytic, extra, key):
    extra = [str(tmp_path / e) if e.endswith(".csv") else e for e in extra]
    r = run(analytic, "--csv", tmp_path / "t.csv", "--quantity", "velocity", "--quiet", *extra)
    assert r.exit_code == 1 and key in r.output, r.output
    assert len(r.output.strip().splitlines()) == 1
    assert not (tmp_path / "t.csv").exists() and not (tmp_path / "s.csv").exists()
