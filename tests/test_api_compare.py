"""The public API of compare, whatif and track: each returns its result, whose ``to_text()`` is
what the command prints and whose ``plot(ax=...)`` draws into the axes or figure given."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.results.comparison import ComparisonResult
from powertrain.results.tracked import TrackedOrders
from powertrain.results.whatif import WhatIfResult
from powertrain.workflows.comparison import compare
from powertrain.workflows.tracking import track
from powertrain.workflows.whatif import whatif

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
MEASURED = ROOT / "examples" / "measured-runup.csv"
RAW = ROOT / "examples" / "raw-runup.csv"
#: Wall-clock times in the reports ("0.42 s"): the only part allowed to differ.
SECONDS = re.compile(r"\d+\.\d+ s\b")


def _cli(args) -> str:
    res = CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return res.output


def _same_text(api_text: str, cli_output: str) -> None:
    assert SECONDS.sub("T s", api_text + "\n") == SECONDS.sub("T s", cli_output)


def _axes():
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    return fig, ax


def test_compare_returns_its_result_text_and_draws_into_axes():
    result = compare(MEASURED, solver="harmonic", step=500.0)
    assert isinstance(result, ComparisonResult) and result.channels
    assert result.run["solver"] == "harmonic" and result.run["engine"] is not None
    _same_text(result.to_text(), _cli(["compare", MEASURED, "--solver", "harmonic",
                                       "--step", "500"]))
    assert result.to_text().splitlines()[-1].startswith(result.summary())
    fig, ax = _axes()
    assert result.plot(ax=ax, channel=("left", "z"), quantity="synthesis") is fig
    assert ax.lines


def test_compare_of_a_given_simulation_runs_nothing(tmp_path):
    sim = tmp_path / "sim.csv"
    _cli(["runup", "--solver", "harmonic", "--step", "500", "--csv", sim, "--quiet"])
    result = compare(MEASURED, simulated=sim)
    assert result.run["engine"] is None and result.run["simulation_file"] == str(sim)
    _same_text(result.to_text(), _cli(["compare", MEASURED, "--sim", sim]))
    with pytest.raises(ValueError):
        compare(MEASURED, simulated=sim, engine="engines/default.toml")


def test_whatif_returns_its_result_text_and_draws_into_axes():
    result = whatif(scale=["left.z.stiffness=1.2"], rpm=[1000.0, 2000.0, 3000.0], workers=1)
    assert isinstance(result, WhatIfResult)
    assert [v.name for v in result.variants] == ["command line"]
    assert result.variants[0].specs == ["left.z.stiffness=1.2"]
    _same_text(result.to_text(), _cli(["whatif", "--scale", "left.z.stiffness=1.2", "--from",
                                       "1000", "--to", "3000", "--step", "1000",
                                       "--workers", "1"]))
    d = result.delta_db("command line", "left", "z")
    assert np.all(np.isfinite(d)) and np.max(np.abs(d)) > 0.03     # the variant changed left.z
    fig, ax = _axes()
    assert result.plot(ax=ax, channel=("left", "z"), quantity="synthesis") is fig
    assert ax.lines


def test_whatif_applies_each_variant_once(monkeypatch):
    from powertrain.workflows import variants
    calls = []
    original = variants.Scale.apply

    def counted(self, engine):
        calls.append(self.spec)
        return original(self, engine)
    monkeypatch.setattr(variants.Scale, "apply", counted)
    whatif(scale=["left.z.stiffness=1.2"], rpm=[2000.0], workers=1)
    assert calls == ["left.z.stiffness=1.2"]


def test_track_returns_its_result_text_and_draws_into_a_figure(tmp_path):
    import matplotlib.pyplot as plt
    result = track(RAW, orders="2,4", rpm_step=100.0, overall=True)
    assert isinstance(result, TrackedOrders) and result.overall is not None
    csv = tmp_path / "t.csv"
    out = _cli(["track", RAW, "--orders", "2,4", "--rpm-step", "100", "--overall",
                "--csv", csv])
    _same_text(result.to_text([str(csv)]), out)
    fig = plt.figure()
    assert result.plot(ax=fig) is fig
    assert all(a.lines for a in fig.axes if a.get_visible() and a.has_data())
    assert len([a for a in fig.axes if a.has_data()]) == len(result.channels)
