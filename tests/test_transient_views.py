"""The views of a transient manoeuvre (issue 38), on small synthetic results (no
simulation): the figure's peak labels off the traces and the frame, distinct colours for the
speed and the channels, the overlay on a recording as a grid that fits a page with each
channel's errors, the what-if ranking's bars in rank order with their values and its change
view, a body point's force reported as not applicable, and ``whatif --manoeuvre`` refusing
the run-up's options before any work (command line and API)."""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from figure_text import legend_problems, page_problems, text_problems, unit_problems

import powertrain as pt
from powertrain.cli.group import main
from powertrain.results.transient import TransientComparison, TransientRanking, TransientResult

#: Largest overlay figure [in]: a portrait page's text area with room for a caption.
PAGE_IN = (7.0, 9.5)
NETWORKS = [f"{m}.{d}" for m in ("left", "right") for d in "xyz"]
CHANNELS = NETWORKS + [f"seat_rail.{d}" for d in "xyz"]


def synthetic(scale=1.0, n=300) -> TransientResult:
    """A 0.3 s result whose channels peak at the first step (left.x), the last step
    (left.y), at a fast oscillation's crest (left.z) and elsewhere; a seat point."""
    t = np.linspace(0.0, 0.3, n)
    k = len(CHANNELS)
    wave = np.sin(2 * np.pi * 180.0 * t)[:, None] * np.linspace(0.5, 1.5, k)
    acc = scale * (wave + np.exp(-t / 0.05)[:, None] * np.r_[3.0, np.zeros(k - 1)])
    acc[:, 1] += scale * 4.0 * (t / t[-1]) ** 8
    disp = 1e-3 * acc
    force = 100.0 * acc
    force[:, 6:] = 0.0                                  # a body point transmits none
    return TransientResult(
        "synthetic", "s.toml", "engine", t, 800.0 + 2000.0 * t,
        {"engine": 50.0 * t, "starter": np.where(t < 0.1, 20.0, 0.0), "driveline": 0 * t},
        np.zeros((n, 6)), CHANNELS, disp, 1e-2 * acc, acc, force, NETWORKS,
        scale * 1e-3 * wave[:, :6],
        {"point": "seat_rail", "rms": dict.fromkeys("xyz", 0.1),
         "vdv": dict.fromkeys("xyz", 0.2), "weighting": dict.fromkeys("xyz", "W_k")})


def _clean(fig):
    problems = text_problems(fig) + legend_problems(fig) + unit_problems(fig) \
        + page_problems(fig, 300)
    assert not problems, problems


def test_the_transient_figure_marks_peaks_off_the_traces(tmp_path):
    import matplotlib.pyplot as plt
    r = synthetic()
    fig = r.plot(channels=["left.x", "left.y", "left.z"])
    _clean(fig)
    top, *panels = [a for a in fig.axes if a.get_ylabel() != "torque [N·m]"]
    speed = top.get_lines()[0].get_color()
    for a, c in zip(panels, ("left.x", "left.y", "left.z")):
        assert a.get_ylabel().startswith(c)
        assert not a.texts                                   # nothing written on the data
        assert a.get_title(loc="right").startswith("peak ")  # above the frame
        line, marker = a.get_lines()
        assert line.get_color() != speed
        lo, hi = a.get_xlim()
        span = hi - lo
        x = marker.get_xdata()[0]
        assert lo + 0.02 * span < x < hi - 0.02 * span        # clear of the y axes
        ylo, yhi = a.get_ylim()
        assert ylo < marker.get_ydata()[0] < yhi
    colours = [ln.get_color() for a in panels for ln in a.get_lines()[:1]]
    assert len(set(colours)) == 3 and speed not in colours
    plt.close(fig)


@pytest.mark.parametrize("n_channels,grid", [(2, (2, 1)), (21, (5, 3))])
def test_the_overlay_fits_a_page_and_heads_each_panel_with_its_errors(n_channels, grid):
    import matplotlib.pyplot as plt
    r = synthetic()
    rng = np.random.default_rng(1)
    names = [f"m{k // 3}.{'xyz'[k % 3]}" for k in range(n_channels)]
    meas = np.tile(r.acceleration, 3)[:, :n_channels]
    comp = TransientComparison("synthetic", "rec.h5", 0.0, r.time, names, meas,
                               1.1 * meas + 0.05 * rng.standard_normal(meas.shape))
    fig = comp.plot()
    w, h = fig.get_size_inches()
    assert w <= PAGE_IN[0] and h <= PAGE_IN[1]
    _clean(fig)
    shown = [a for a in fig.axes if a.get_visible()]
    assert len(shown) == min(n_channels, 15) and fig.axes[0].get_gridspec().get_geometry() \
        == grid
    e = comp.errors()
    worst = sorted(np.argsort(-e["rms_difference_percent"], kind="stable")[:15])
    for j, a in zip(worst, shown):
        title = a.get_title()
        assert title.startswith(f"{names[j]}: peak +{e['peak_error_percent'][j]:.1f} %")
        assert f"RMS diff. {e['rms_difference'][j]:.3g} m/s²" in title
    heading = fig.legends[0].get_title().get_text().replace("\n", " ")
    left_out = [names[j] for j in range(n_channels) if j not in worst]
    assert ("6 channels of smaller RMS difference not drawn" in heading) == (n_channels > 15)
    assert all(f" {c}" in heading for c in left_out)
    plt.close(fig)


def _ranking():
    return TransientRanking("synthetic", ["baseline", "softer", "stiffer"],
                            [synthetic(1.0), synthetic(0.9), synthetic(1.2)])


@pytest.mark.parametrize("view", ["levels", "delta"])
def test_the_ranking_bars_are_in_rank_order_with_their_values(view):
    import matplotlib.pyplot as plt
    rank = _ranking()
    assert [rank.names[k] for k in rank.ranking()] == ["softer", "baseline", "stiffer"]
    fig = rank.plot(view=view)
    assert not text_problems(fig) and not page_problems(fig, 300)
    bars = [a for a in fig.axes if a.patches]
    assert len(bars) == 2                              # seat acceleration, deflection
    order = ["softer", "stiffer"] if view == "delta" else ["softer", "baseline", "stiffer"]
    seat = rank.peak_seat()
    for a in bars:
        assert [t.get_text() for t in a.get_yticklabels()] == order
        assert "[%]" in a.get_xlabel() if view == "delta" else "[m" in a.get_xlabel()
        values = [t.get_text() for t in a.child_axes[0].get_yticklabels()]   # right of it
        assert len(values) == len(order) and all(values)
    texts = " ".join(t.get_text() for a in bars for t in a.child_axes[0].get_yticklabels())
    if view == "delta":
        assert f"{100 * (seat[1] / seat[0] - 1):+.1f} %" in texts
    else:
        assert f"{seat[1]:.4g} m/s²" in texts
    plt.close(fig)


def test_a_body_point_transmits_no_force(tmp_path):
    r = synthetic()
    seat_rows = [ln for ln in r.to_text().splitlines() if ln.strip().startswith("seat_rail.")]
    assert len(seat_rows) == 3 and all(" n/a " in ln for ln in seat_rows)
    doc = json.loads(r.to_json())
    assert doc["channels"]["seat_rail.z"]["peak_force_n"] is None
    assert doc["channels"]["left.z"]["peak_force_n"] > 0
    r.to_csv(tmp_path / "r.csv")
    with open(tmp_path / "r.csv", newline="") as fh:
        rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
    assert {row["seat_rail.z_force_n"] for row in rows} == {""}
    assert float(rows[5]["left.z_force_n"]) == pytest.approx(r.force[5, 2])
    h5py = pytest.importorskip("h5py")
    r.to_hdf5(tmp_path / "r.h5")
    with h5py.File(tmp_path / "r.h5") as h5:
        assert list(h5.attrs["transmits_force"]) == [True] * 6 + [False] * 3
        assert h5["force"].attrs["unit"] == "N" and h5["acceleration"].attrs["unit"] == "m/s^2"
        assert h5["torque/engine"].attrs["unit"] == "N*m"
        np.testing.assert_array_equal(h5["force"][:, 6:], 0.0)


@pytest.mark.parametrize("option", [
    ["--from", "1000"], ["--to", "3000"], ["--step", "250"], ["--solver", "harmonic"],
    ["--signal", "mount_force"], ["--objective", "left.z:order_2:1000-2000"],
    ["--measured", "m.csv"], ["--workers", "1"], ["--scheduler", "serial"],
    ["--target-out", "t.toml"], ["--target-plot", "t.png"]])
def test_whatif_over_a_manoeuvre_refuses_a_runup_option_before_any_work(option, tmp_path):
    res = CliRunner().invoke(main, ["whatif", "--manoeuvre", str(EXAMPLES / "start.toml"),
                                    "--scale", "left.z.dynamic=1.2", *option,
                                    "--json", str(tmp_path / "w.json")])
    assert res.exit_code == 1
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and f"'{option[0]}'" in lines[0] and "--manoeuvre" in lines[0]
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("keyword,value", [("rpm", [1000.0, 2000.0]), ("solver", "newmark"),
                                           ("signal", "velocity"), ("objective", "x"),
                                           ("measured", "m.csv"), ("rpm_step", 100.0),
                                           ("workers", 2), ("executor", "serial")])
def test_the_api_refuses_a_runup_keyword_with_a_manoeuvre(keyword, value):
    with pytest.raises(pt.InputError, match=f"key '{keyword}'.*no meaning"):
        pt.whatif(scale="left.z.dynamic=1.2", manoeuvre=EXAMPLES / "start.toml",
                  **{keyword: value})


def test_what_plot_accepts():
    """As documented (docs/guide/python-api.md): a transient's figure always has the speed
    panel, so one Axes is refused; a one-channel comparison and a ranking without a seat
    draw into one Axes; a SubFigure takes any of them."""
    import matplotlib.pyplot as plt
    r = synthetic()
    fig, (a1, a2) = plt.subplots(1, 2)
    with pytest.raises(pt.InputError, match="pass a Figure or SubFigure"):
        r.plot(a1)
    one = TransientComparison("s", "rec.h5", 0.0, r.time, ["left.z"], r.acceleration[:, 2:3],
                              r.acceleration[:, 2:3])
    assert one.plot(a1) is fig and a1.get_title().startswith("left.z: peak 0.0 %")
    no_seat = [dataclasses.replace(x, seat=None) for x in _ranking().runs]
    assert TransientRanking("s", ["baseline", "a", "b"], no_seat).plot(a2) is fig
    plt.close(fig)
    fig = plt.figure(layout="constrained")
    left, right = fig.subfigures(1, 2)
    assert r.plot(left, channels=["left.z"]) is left and len(left.axes) == 3   # + twin
    assert _ranking().plot(right, view="delta") is right
    plt.close(fig)


def test_the_overlay_draws_the_seat_first_then_the_largest_relative_difference():
    """Review 3: the seat's axes are drawn whatever their error (a modal body's 21 channels
    left the seat rail out), then the channels of the largest RMS of the difference
    relative to the measured RMS (a channel of noise only, with no relative error, last)."""
    from powertrain.plotting.transient import overlay_channels
    names = ["a.x", "seat_rail.z", "b.x", "c.x", "d.x"]
    assert overlay_channels(names, [50.0, 1.0, np.nan, 80.0, 10.0], 3) == [0, 1, 3]
