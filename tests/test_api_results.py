"""One protocol on every result of the Python API: ``to_text()``, ``plot(ax=None)`` and
``save(path)`` by suffix, and results built once (frozen).

``plot(ax=...)`` draws into a Figure (or SubFigure) everything it draws into a figure of its
own (panels, lines, the legend), and into one Axes only where the figure has one panel
(then with its legend); an Axes for several panels is an ``InputError`` saying to pass a
Figure."""

from __future__ import annotations

import dataclasses

import matplotlib
import numpy as np
import pytest
from conftest import EXAMPLES, MOUNTS

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import powertrain as pt  # noqa: E402
from powertrain.results.base import Result  # noqa: E402

MOUNT = str(MOUNTS / "hydraulic-engine-mount-z.toml")
MEASURED = str(EXAMPLES / "measured-runup.csv")
RPM = [1000.0, 2000.0, 3000.0]


def _stiffness_data():
    f = np.arange(1.0, 60.0)
    return f, pt.read_mount(MOUNT).cross_point_stiffness(f)


#: name -> function of the engine making one result of every public result class.
MAKERS = {
    "RunupResult": lambda e: pt.runup(e, rpm=RPM, solver="harmonic"),
    "SweepRunup": lambda e: pt.runup(e, rpm=[2000, 2600], sweep=300),
    "TrackedOrders": lambda e: pt.track(str(EXAMPLES / "raw-runup.csv")),
    "StaticResult": lambda e: pt.static(e, rpm=RPM),
    "ModesResult": lambda e: pt.modes(e),
    "ExcitationResult": lambda e: pt.excitation(e, rpm=3000),
    "StiffnessResult": lambda e: pt.stiffness(MOUNT, freq="1:100:1"),
    "AmplitudeStiffnessResult": lambda e: pt.stiffness(MOUNT, freq="1:60:1",
                                                       amplitude=[1e-4, 1e-3]),
    "FitResult": lambda e: pt.fit_mount(*_stiffness_data(), starts=2, hops=0),
    "AmplitudeFitResult": lambda e: pt.fit_mount(str(EXAMPLES / "hydraulic-mount-"
                                                     "amplitudes.csv"), starts=2),
    "ComparisonResult": lambda e: pt.compare(MEASURED, engine=e, solver="harmonic"),
    "WhatIfResult": lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=RPM,
                                        workers=1),
    "TargetFit": lambda e: pt.whatif(e, targets="left.z:+20%:100-300Hz", rpm=RPM,
                                     workers=1).target_fit(),
    "DiagnosisResult": lambda e: pt.diagnose(MEASURED, e, effects=["mount_stiffness"],
                                             pairs=False, progress=False),
    "SynthCase": lambda e: pt.synth([], 0),
    "TransientResult": lambda e: pt.transient(str(EXAMPLES / "start.toml"), e,
                                              angle_step_deg=5.0),
    "TransientRanking": lambda e: pt.whatif(e, scale="left.z.stiffness=1.2",
                                            manoeuvre=str(EXAMPLES / "stop.toml")),
}

#: One panel chosen, for the grid figures given one Axes (keyword arguments of ``plot``).
ONE_PANEL = {
    "RunupResult": {"channel": ("left", "z"), "quantity": "order_2"},
    "WhatIfResult": {"channel": ("left", "z"), "quantity": "synthesis"},
    "ComparisonResult": {"channel": ("right", "x"), "quantity": "order_6", "phase": False},
    "DiagnosisResult": {"quantity": "order_2"},
    "StiffnessResult": {"form": "real-imag"},
    "AmplitudeStiffnessResult": {"form": "real-imag"},
    "FitResult": {"form": "real-imag"},
    "AmplitudeFitResult": {"form": "real-imag"},
    "TargetFit": {"form": "real-imag"},
}


#: Results whose figures have many panels (seconds a draw): their figure and file tests run
#: with the slow tests.
MANY_PANELS = ("ComparisonResult", "RunupResult", "SweepRunup", "ExcitationResult")
NAMES_BY_COST = [pytest.param(n, marks=pytest.mark.slow) if n in MANY_PANELS else n
                 for n in sorted(MAKERS)]


@pytest.fixture(scope="module")
def results(default_engine):
    return {name: make(default_engine) for name, make in MAKERS.items()}


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def drawn(fig) -> dict:
    """What a figure holds: its visible panels with their lines, filled areas and bars, and
    how many legends (the figure's and the panels')."""
    axes = [a for a in fig.axes if a.get_visible()]
    return {"panels": [(len(a.get_lines()), len(a.collections), len(a.patches))
                       for a in axes],
            "legends": len(fig.legends) + sum(a.get_legend() is not None for a in axes)}


@pytest.mark.slow
def test_every_result_class_follows_the_protocol(results):
    for name, r in results.items():
        assert type(r).__name__ == name
        assert isinstance(r, Result), name
        for method in ("to_text", "plot", "save", "writers"):
            assert callable(getattr(r, method, None)), f"{name}.{method}"
        assert isinstance(r.to_text(), str) and r.to_text().strip(), name
        assert ".png" in r.writers(), name


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_a_result_is_built_once(name, results):
    r = results[name]
    assert dataclasses.is_dataclass(r) and type(r).__dataclass_params__.frozen, name
    field = dataclasses.fields(r)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(r, field, None)


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES_BY_COST)
def test_plot_into_a_figure_draws_what_it_draws_alone(name, results):
    r = results[name]
    alone = drawn(r.plot())
    fig = plt.figure(layout="constrained")
    assert r.plot(ax=fig) is fig
    assert drawn(fig) == alone, name
    sub = plt.figure(layout="constrained").subfigures(1, 2)[1]
    assert r.plot(ax=sub) is sub
    assert drawn(sub) == alone, name


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_plot_into_one_axes_draws_the_one_panel_or_asks_for_a_figure(name, results):
    r = results[name]
    fig, ax = plt.subplots()
    try:
        r.plot(ax=ax)
    except pt.InputError as err:
        assert "pass a Figure" in str(err), err
    else:
        alone = drawn(r.plot())
        assert drawn(fig)["panels"] == alone["panels"], name
        assert drawn(fig)["legends"] >= min(alone["legends"], 1), name
    if name in ONE_PANEL:
        fig, ax = plt.subplots()
        assert r.plot(ax=ax, **ONE_PANEL[name]) is fig
        alone = drawn(r.plot(**ONE_PANEL[name]))
        assert drawn(fig)["panels"] == alone["panels"], name
        assert drawn(fig)["legends"] >= min(alone["legends"], 1), name


def test_the_comparison_panel_in_an_axes_has_its_legend(results):
    """The issue's case: one Axes used to get the first channel, silently, without a legend."""
    gap = results["ComparisonResult"]
    fig, ax = plt.subplots()
    with pytest.raises(pt.InputError, match="pass a Figure"):
        gap.plot(ax=ax)
    gap.plot(ax=ax, channel=("right", "x"), quantity="order_6", phase=False)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "measured" in labels and "simulated" in labels
    assert ax.get_title().startswith("right X · order 6")


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES_BY_COST)
def test_save_writes_every_suffix_it_names(name, results, tmp_path):
    r = results[name]
    for suffix in r.writers():
        path = tmp_path / f"out{suffix}"
        assert r.save(path) == path
        assert path.stat().st_size > 0, (name, suffix)
    with pytest.raises(pt.InputError, match="writes"):
        r.save(tmp_path / "out.xyz")


def test_saved_files_are_those_of_the_writers(results, tmp_path):
    run = results["RunupResult"]
    run.save(tmp_path / "a.csv")
    run.to_csv(tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    gap = results["ComparisonResult"]
    gap.save(tmp_path / "c.json")
    assert (tmp_path / "c.json").read_text(encoding="utf-8") == gap.to_json()


def test_worst_first_gives_the_largest_gap_first(results):
    gap = results["ComparisonResult"]
    worst = gap.worst_first()
    rms = [c.stats["rms_db"] for c in worst]
    assert rms == sorted(rms, reverse=True) and len(worst) == len(gap.channels)
    assert (worst[0].mount, worst[0].direction, worst[0].quantity) == ("right", "x",
                                                                        "order_6")
    assert worst[0].stats["rms_db"] == pytest.approx(0.80, abs=0.01)
