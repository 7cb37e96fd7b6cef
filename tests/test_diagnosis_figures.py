"""The diagnosis figures at twenty-one channels (a modal body, both sides and the body points
measured): the checks of tests/test_figures.py (no overlapping or clipped text, text at
least 8 pt, no legend over data, palette colours) plus every panel's axes labelled, no two
legend entries alike in colour and line style, titles of at most two lines, the gap map's
colour scale from the data, censored points hollow and the simulated curve whole."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest
from figure_text import drawn_texts, legends_over_data, off_palette_colours, small_texts, text_problems

from powertrain.diagnosis import diagnose
from powertrain.effects import predict
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.plotting.diagnosis import (
    _run_name,
    gap_scale,
    plot_diagnosis_overlay,
    plot_gap_frequency,
    plot_gap_map,
)
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows.measurement import FLOOR, measure

matplotlib.use("Agg")
MODAL = Path(DEFAULT_ENGINE_PATH).parent / "default-modal-body.toml"


@pytest.fixture(scope="module")
def result():
    """The both-sides example of diagnose.md (body mode 2 at 28.5 Hz, 45 kg) on a 250-rpm
    grid, every channel of the modal body measured (21), scatter 0.5 dB."""
    engine = read_engine(MODAL)
    rpm = np.arange(1000.0, 6001.0, 250.0)
    hm = HarmonicModel(engine, rpm)
    v = predict(hm, {"chassis_modes": {"f2": 28.5, "m2": 45.0}}).velocity
    meas = measure(v, 0.5, np.random.default_rng(5), "both sides", hm.channels, rpm)
    assert len(hm.channels) >= 20
    return diagnose(meas, engine, noise_floor=FLOOR, effects=["chassis_modes"], pairs=False,
                    band_check=False, progress=False)


@pytest.fixture(scope="module")
def figures(result):
    """Each figure drawn once: {function name: Figure}."""
    import matplotlib.pyplot as plt
    out = {f.__name__: f(result) for f in (plot_gap_map, plot_gap_frequency,
                                          plot_diagnosis_overlay)}
    yield out
    for fig in out.values():
        plt.close(fig)


def _entries(fig):
    """(label, colour, line style, marker, marker face) of every legend entry."""
    from matplotlib.colors import to_hex
    out = []
    for leg in fig.legends + [a.get_legend() for a in fig.axes if a.get_legend()]:
        for h, t in zip(leg.legend_handles, leg.get_texts()):
            if hasattr(h, "get_linestyle") and hasattr(h, "get_marker"):
                mfc = h.get_markerfacecolor()
                out.append((t.get_text(), to_hex(h.get_color()), str(h.get_linestyle()),
                            h.get_marker(), mfc if isinstance(mfc, str) else to_hex(mfc)))
    return out


def _title_lines(fig) -> int:
    t = fig.legends[0].get_title().get_text() if fig.legends else fig._suptitle.get_text()
    return t.count("\n") + 1


@pytest.mark.slow
@pytest.mark.parametrize("name", ["plot_gap_map", "plot_gap_frequency",
                                  "plot_diagnosis_overlay"])
def test_twenty_channel_figures_are_clean(figures, name):
    fig = figures[name]
    drawn = drawn_texts(fig)
    problems = (text_problems(fig, drawn=drawn) + small_texts(drawn, fig.get_figwidth())
                + legends_over_data(fig) + off_palette_colours(fig))
    assert not problems, "\n".join(problems[:10])
    panels = [a for a in fig.axes if a.get_visible() and (a.get_lines() or a.collections)
              and a.get_label() != "<colorbar>"]
    assert panels
    for a in panels:
        assert a.get_xlabel() and a.get_ylabel(), f"{a.get_title()!r}: axes not labelled"
    styles = [e[1:] for e in _entries(fig)]
    assert len(styles) == len(set(styles)), _entries(fig)
    assert _title_lines(fig) <= 2


def test_gap_map_scale_from_the_data_and_small_multiples(figures):
    assert gap_scale([0.5, -2.0]) == 6.0 and gap_scale([39.0, -1.0]) == 40.0
    titles = {a.get_title() for a in figures["plot_gap_frequency"].axes}
    assert {"left Z", "gearbox Z", "seat_rail Z"} <= titles        # one panel per base, axis


def test_overlay_draws_censored_points_hollow_and_the_simulation_whole(result, figures):
    fig = figures["plot_diagnosis_overlay"]
    lines = [ln for a in fig.axes for ln in a.get_lines()]
    hollow = [ln for ln in lines if "censored" in ln.get_label()]
    assert hollow and all(ln.get_markerfacecolor() == "none" for ln in hollow)
    sim = [ln for ln in lines if ln.get_label() == "baseline simulation"]
    assert sim and all(np.isfinite(ln.get_ydata()).all() for ln in sim)
    assert len(sim[0].get_xdata()) == result.data.rpm.size


def test_a_plans_figures_name_their_run():
    plan = SimpleNamespace(runs=[{"file": "/x/part.csv"}, {"file": "wot.csv"}])
    assert _run_name(plan) == " of run 1 (part.csv) of 2"
    assert _run_name(SimpleNamespace(runs=[])) == ""
