"""The Python API of the run-up, modes and excitation commands: each library function returns
its result, whose ``to_text()`` is what the command prints and whose ``plot(ax=...)`` draws
into the axes (or figure) it is given."""

from __future__ import annotations

import subprocess
import sys

import h5py
import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH  # noqa: E402
from powertrain.iotools.runup_hdf5 import read_runup_hdf5  # noqa: E402
from powertrain.results.excitation import ExcitationResult  # noqa: E402
from powertrain.results.modes import ModesResult  # noqa: E402
from powertrain.results.runup import RunupResult  # noqa: E402
from powertrain.workflows.excitation import excitation  # noqa: E402
from powertrain.workflows.modes import modes  # noqa: E402
from powertrain.workflows.runup import runup  # noqa: E402


def _printed(*args) -> str:
    """stdout of ``powertrain ARGS`` (exit 0 asserted)."""
    r = subprocess.run([sys.executable, "-m", "powertrain.cli", *args], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.mark.slow
def test_runup_text_is_what_the_command_prints_and_plot_draws_into_given_axes():
    result = runup(None, [1000.0, 2000.0], solver="harmonic", balancers=False,
                   effects=["sensor_error:g1=1"])
    assert isinstance(result, RunupResult)
    printed = _printed("runup", "--from", "1000", "--to", "2000", "--step", "1000",
                       "--solver", "harmonic", "--no-balancers", "--effect", "sensor_error:g1=1")
    text, last = printed.rstrip("\n").rsplit("\n", 1)
    assert result.to_text() == text
    assert last.startswith("solver time:")
    assert "5.9 (y)" in text and "effects: sensor_error(g1=1" in text
    fig, ax = plt.subplots()
    assert result.plot(ax, channel=("left", "z"), quantity="synthesis") is fig
    assert len(ax.get_lines()) == 1
    plt.close(fig)


def test_runup_hdf5_holds_the_engine_and_mount_snapshots(tmp_path):
    result = runup(DEFAULT_ENGINE_PATH, [1500.0], solver="harmonic")
    result.to_hdf5(tmp_path / "r.h5")
    with h5py.File(tmp_path / "r.h5") as h5:
        assert h5.attrs["engine_snapshot"] == DEFAULT_ENGINE_PATH.read_text(encoding="utf-8")
        assert "left.z" in h5.attrs["mount_snapshots"]
        assert h5.attrs["description"].startswith("run-up 1500-1500 rpm")
    back = read_runup_hdf5(tmp_path / "r.h5")
    np.testing.assert_array_equal(back.velocity, result.velocity)
    assert back.to_text() == result.to_text()


def test_modes_text_is_what_the_command_prints_and_plot_draws_into_given_axes():
    result = modes(static=True)
    assert isinstance(result, ModesResult)
    assert result.to_text() + "\n" == _printed("modes", "--static")
    fig, ax = plt.subplots()
    assert result.plot(ax) is fig and len(ax.patches) == 6 * 6
    plt.close(fig)


def test_excitation_text_is_what_the_command_prints_and_plot_draws_into_a_subfigure():
    result = excitation(None, 2000.0, load=0.5, balancers=False)
    assert isinstance(result, ExcitationResult)
    assert result.to_text() + "\n" == _printed("excitation", "--rpm", "2000", "--load", "0.5",
                                               "--no-balancers")
    fig = plt.figure()
    left, _ = fig.subfigures(1, 2)
    assert result.plot(left) is left and len(left.axes) == 6
    plt.close(fig)
