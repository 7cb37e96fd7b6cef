"""The Python API behind ``powertrain diagnose``, ``synth``, ``stiffness`` and ``fit-mount``:
each library function returns its result; the result's ``to_text()`` is what the command
prints; ``plot(ax=...)`` draws into the Axes (or Figure) it is given."""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest
from click.testing import CliRunner
from conftest import ENGINES, MOUNTS

from powertrain.cli import main
from powertrain.diagnosis import DiagnosisResult, diagnose
from powertrain.errors import InputError
from powertrain.results.fit import FitResult
from powertrain.results.stiffness import StiffnessResult
from powertrain.workflows.fitting import fit_mount
from powertrain.workflows.stiffness import stiffness
from powertrain.workflows.synth import SynthCase, synth

matplotlib.use("Agg")
MOUNT = MOUNTS / "hydraulic-engine-mount-z.toml"
TIMING = re.compile(r"\d+\.\d+ s\b")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt
    plt.close("all")


def _cli(*args) -> str:
    res = CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return res.stdout


def _axes():
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    return fig, ax


def _drew_into(ax) -> bool:
    return bool(ax.lines or ax.collections or ax.images)


def test_stiffness_text_is_the_command_output():
    res = stiffness(MOUNT, freq=np.arange(1.0, 51.0))
    assert isinstance(res, StiffnessResult)
    assert res.label == "Hydraulic engine mount, Z direction"   # the file's name
    assert _cli("stiffness", MOUNT, "--freq", "1:50:1") == res.to_text()
    assert _cli("stiffness", MOUNT, "--freq", "1:50:1", "--format", "csv") == res.to_csv()


def test_stiffness_of_an_engine_mount_direction():
    res = stiffness("torque_rod.x", engine=ENGINES / "default-torque-rod.toml",
                    freq=[5.0, 10.0, 20.0])
    assert res.label == "inline spring-damper x"        # the inline model's name
    assert _cli("stiffness", "--engine", ENGINES / "default-torque-rod.toml", "--mount",
                "torque_rod.x", "--freq", "5,10,20") == res.to_text()
    with pytest.raises(InputError, match="expected MOUNT.DIR"):
        stiffness("torque_rod.q", engine=ENGINES / "default-torque-rod.toml")
    with pytest.raises(InputError, match="go together"):
        stiffness(MOUNT, engine_mass=100.0)


def test_stiffness_plot_draws_into_the_given_axes(tmp_path):
    res = stiffness(MOUNT, freq=np.arange(1.0, 51.0))
    fig, ax = _axes()
    assert res.plot(ax, form="real-imag") is fig
    assert _drew_into(ax)
    res.plot(path=tmp_path / "k.png")
    assert (tmp_path / "k.png").read_bytes()[:4] == b"\x89PNG"


def test_fit_mount_on_a_file_is_the_command(tmp_path):
    csv = tmp_path / "k.csv"
    stiffness(MOUNT).to_csv(csv)
    res = fit_mount(csv, model="sls", starts=2)
    assert isinstance(res, FitResult)
    out = _cli("fit-mount", csv, "--model", "sls", "--starts", "2", "--out",
               tmp_path / "fit.toml")
    assert TIMING.sub("", out) == TIMING.sub("", res.to_text() + "\n"
                                            + f"wrote {tmp_path / 'fit.toml'}\n")
    assert "parameters:\n   c1 = " in res.to_text()
    written = (tmp_path / "fit.toml").read_text()
    assert all(f"# {line}" in written for line in res.file_comment().splitlines())
    assert "to k.csv: 400 frequencies, 1-400 Hz" in res.file_comment()
    import matplotlib.pyplot as plt
    fig, pair = plt.subplots(2)                    # |K*| and loss angle: a pair of Axes
    assert res.plot(tuple(pair)) is fig and all(_drew_into(a) for a in pair)
    plt.close(fig)
    with pytest.raises(InputError, match="--starts"):
        fit_mount(csv, model="sls", starts=0)


def test_synth_case_is_the_command(tmp_path):
    case = synth(["balancer_error"], 3)
    assert isinstance(case, SynthCase)
    out = tmp_path / "m.csv"
    text = _cli("synth", "--effect", "balancer_error", "--seed", "3", "--out", out,
                "--truth", tmp_path / "t.json")
    assert text == f"wrote {out}, {tmp_path / 't.json'}: {case.to_text()}\n"
    assert out.read_text() == case.to_csv()
    assert (tmp_path / "t.json").read_text() == case.to_truth_json()
    fig, ax = _axes()
    assert case.plot(ax) is fig and _drew_into(ax)
    with pytest.raises(InputError, match="unknown truth effect"):
        synth(["no_such_effect"], 1)


@pytest.mark.slow
def test_diagnose_text_is_the_command_output(tmp_path):
    csv = tmp_path / "m.csv"
    synth(["balancer_error"], 3).to_csv(csv)
    kw = {"effects": ["balancer_error"], "pairs": False}
    res = diagnose(csv, None, progress=False, **kw)          # a path and the default engine
    assert isinstance(res, DiagnosisResult)
    assert res.chosen is not None and res.chosen.label == "balancer_error"
    out = _cli("diagnose", csv, "--effects", "balancer_error", "--no-pairs")
    assert TIMING.sub("", out) == TIMING.sub("", res.to_text() + "\n")
    fig, ax = _axes()
    with pytest.raises(InputError, match="pass a Figure"):     # the gap map has 4 panels
        res.plot(ax)
    assert res.plot(ax, quantity="order_2") is fig and _drew_into(ax)
    assert res.plot(fig) is fig and len(fig.axes) > 1
    with pytest.raises(InputError, match="unknown effect"):
        diagnose(csv, effects=["no_such_effect"])
