"""compare/diagnose inputs in acceleration, displacement and force (issue 12, item 5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from powertrain.iotools.measured import read_measured


def write(path, column, rows):
    path.write_text(f"mount,direction,quantity,rpm,{column}\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("column, factor", [("acceleration_rms_m_per_s2", None),
                                            ("displacement_rms_mm", 1e-3)])
def test_converted_per_order_and_synthesis_recomputed(tmp_path, column, factor):
    rows = ["left,z,order_2,3000,2.0", "left,z,order_4,3000,1.0", "left,z,synthesis,3000,9.9"]
    m = read_measured(write(tmp_path / "m.csv", column, rows))
    w2, w4 = 2 * math.pi * 2 * 50.0, 2 * math.pi * 4 * 50.0
    if factor is None:                                   # v = a / w
        v2, v4 = 2.0 / w2, 1.0 / w4
    else:                                                # v = w x
        v2, v4 = 2.0 * factor * w2, 1.0 * factor * w4
    assert m.signal == "velocity"
    assert m.curve("left", "z", "order_2")[1][0] == pytest.approx(v2)
    assert m.curve("left", "z", "order_4")[1][0] == pytest.approx(v4)
    assert m.curve("left", "z", "synthesis")[1][0] == pytest.approx(math.hypot(v2, v4))
    assert any("converted to velocity" in n for n in m.notes)


def test_force_curves_compare_with_mount_forces(tmp_path):
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.workflows.comparison import compare_runup
    from powertrain.workflows.runup import run_runup
    rpm = np.array([2000.0, 2500.0, 3000.0])
    res = run_runup(read_engine(DEFAULT_ENGINE_PATH), rpm, solver="harmonic")
    rows = [f"{mnt},{d},{q},{r:g},{res.curve(mnt, d, q, 'mount_force')[i]:.10g}"
            for mnt, d in res.channels for q in ("order_2", "order_4", "synthesis")
            for i, r in enumerate(rpm)]
    m = read_measured(write(tmp_path / "f.csv", "force_rms_n", rows))
    assert m.signal == "mount_force"
    comp = compare_runup(res, m, noise_floor=1e-9)
    assert comp.channels and abs(comp.overall_rms_db) < 1e-6


def test_old_velocity_files_unchanged(tmp_path):
    m = read_measured(write(tmp_path / "v.csv", "velocity_rms_mm_per_s",
                            ["left,z,order_2,3000,2.0", "left,z,synthesis,3000,9.9"]))
    assert m.signal == "velocity"
    assert m.curve("left", "z", "synthesis")[1][0] == pytest.approx(9.9e-3)
