"""``powertrain synth`` on an engine with a fourth mount (torque rod): the truth effects that
act per mount or per channel are drawn for every mount (they assumed three before)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.iotools.measured import read_measured

ROOT = Path(__file__).resolve().parents[1]
TORQUE_ROD = ROOT / "engines" / "default-torque-rod.toml"


@pytest.mark.parametrize("effect", ["sensor_triads", "mount_temperature"])
def test_synth_draws_per_mount_truths_for_a_four_mount_engine(effect, tmp_path):
    out = tmp_path / "m.csv"
    r = CliRunner().invoke(main, ["synth", "--engine", str(TORQUE_ROD), "--effect", effect,
                                  "--seed", "1", "--out", str(out), "--truth",
                                  str(tmp_path / "t.json"), "--quiet"])
    assert r.exit_code == 0, r.output
    measured = read_measured(out)
    assert {c[0] for c in measured.channels} == {"left", "right", "gearbox", "torque_rod"}
