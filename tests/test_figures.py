"""Every figure the command line writes: no overlapping text, no text outside the figure, all
text at least 8 pt at the 16 cm print width, no legend over data, only colour-blind-safe
colours (Okabe-Ito palette, greys; colour maps viridis and RdBu_r), every requested quantity
drawn, the legend listing exactly the series drawn, every data axis labelled with its unit,
no figure larger than an A4 page at 300 dpi, a provenance line; and the library's
``plot(ax=None)`` contract.

Each CLI command runs in-process with quick settings. ``Figure.savefig`` is wrapped so that
the very draw that writes the PNG records every text drawn (titles, axis and tick labels,
legends, colour-bar labels, the provenance line) with its renderer bounding box; the check
and its tolerance (1 px at the saved resolution) are in ``tests/figure_text.py``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest
from click.testing import CliRunner
from figure_text import (
    TOLERANCE_PX,
    check_boxes,
    drawn_texts,
    legend_problems,
    legends_over_data,
    off_palette_colours,
    outside_problems,
    page_problems,
    recording_texts,
    small_texts,
    text_problems,
    unit_problems,
)

from powertrain.cli import main
from powertrain.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
MEASURED = str(ROOT / "examples" / "measured-runup.csv")
VARIANTS = str(ROOT / "examples" / "whatif-variants.toml")
MOUNT = str(ROOT / "mounts" / "hydraulic-engine-mount-z.toml")


@pytest.fixture
def saved(monkeypatch):
    """{png name: (problems, provenance lines, panel legends, legend and unit problems)} of
    every figure saved meanwhile."""
    from matplotlib.figure import Figure
    found = {}
    original = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        with recording_texts() as drawn:
            original(self, fname, *args, **kwargs)
        dpi = kwargs.get("dpi") or self.dpi
        found[Path(str(fname)).name] = (_problems(drawn, self, dpi) + small_texts(
                                            drawn, self.get_figwidth())
                                        + legends_over_data(self) + off_palette_colours(self)
                                        + _colour_maps(self) + page_problems(self, dpi),
                                        [t.get_text() for t, _ in drawn
                                         if t.get_text().startswith("powertrain ")],
                                        sum(a.get_legend() is not None for a in self.axes),
                                        legend_problems(self) + unit_problems(self))

    monkeypatch.setattr(Figure, "savefig", savefig)
    return found


def _problems(drawn, fig, dpi):
    """As :func:`figure_text.text_problems`, from the texts recorded while saving."""
    w, h = fig.get_figwidth() * dpi, fig.get_figheight() * dpi
    return check_boxes(drawn, w, h, TOLERANCE_PX)


#: Colour maps allowed in figures: perceptually uniform (viridis) and the diverging RdBu_r
#: (blue-red, readable with every common colour-vision deficiency); plus the one-grey map of
#: censored cells.
CVD_SAFE_MAPS = {"viridis", "RdBu_r", "censored grey"}


def _colour_maps(fig):
    return [f"colour map {m.get_cmap().name} in {ax.get_title()!r}" for ax in fig.axes
            for m in ax.collections + ax.images
            if hasattr(m, "get_array") and m.get_array() is not None
            and type(m).__name__ in ("QuadMesh", "AxesImage")
            and m.get_cmap().name not in CVD_SAFE_MAPS]


def run(tmp_path, monkeypatch, *args):
    monkeypatch.chdir(tmp_path)
    res = CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return res


def _one_line(foot: str) -> str:
    """The provenance line with its line breaks and shell continuations undone."""
    return foot.replace(" \\\n  ", " ").replace("\n", " ")


#: The figures of a report (issue 39), also checked for a legend listing exactly the series
#: drawn and units on every data axis.
REPORT_FIGURES = {"orders.png", "sweep.png", "maps.png", "whatif.png", "runup.png",
                  "compare.png", "fit.png", "fit-amplitudes.png"}


def _assert_clean(saved, names, command, panel_legends=True):
    for name in names:
        # an atomic write saves a temporary ".NAME.<random>.tmp" first
        keys = [k for k in saved if k == name or k.startswith(f".{name}.")]
        assert keys, f"{name} not written by `powertrain {command}`"
        problems, foot, n_axes_legends, labelling = saved[keys[-1]]
        problems = problems + (labelling if name in REPORT_FIGURES else [])
        if not panel_legends:
            assert n_axes_legends == 0, f"{name}: {n_axes_legends} panel legends, want one " \
                                        "legend for the figure"
        assert not problems, f"{name}:\n" + "\n".join(problems[:10])
        assert foot and f"$ powertrain {command}" in _one_line(foot[0]), \
            f"{name}: no provenance line naming the command ({foot})"
        assert foot[0].startswith(f"powertrain {__import__('powertrain').__version__}")


@pytest.mark.slow          # ~7-11 s: keeps the fast lane under 3 min
def test_runup_and_compare_figures(tmp_path, monkeypatch, saved):
    run(tmp_path, monkeypatch, "runup", "--solver", "harmonic", "--from", "1000", "--to",
        "6000", "--step", "1000", "--out", "r.h5", "--plot", "runup.png", "--quiet")
    _assert_clean(saved, ["runup.png"], "runup", panel_legends=False)
    # a raised noise floor leaves panels partly and wholly below it (labelled, not blank)
    run(tmp_path, monkeypatch, "compare", MEASURED, "--sim", "r.h5", "--noise-floor", "0.01",
        "--plot", "compare.png", "--quiet")
    _assert_clean(saved, ["compare.png"], "compare", panel_legends=False)


@pytest.mark.slow
def test_compare_figure_at_the_measured_speeds_fits_a_page(tmp_path, monkeypatch, saved):
    """The README's figure (simulated at the 50-rpm measured speeds): nothing clipped at the
    edges (the last column's titles and "6000" once were), and no taller than an A4 page."""
    import matplotlib.pyplot as plt

    from powertrain.plotting.style import MAX_HEIGHT_IN, PRINT_WIDTH_IN
    shown = []
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig))
    run(tmp_path, monkeypatch, "compare", MEASURED, "--plot", "compare.png", "--quiet")
    _assert_clean(saved, ["compare.png"], "compare", panel_legends=False)
    fig = shown[-1]
    assert fig.get_figwidth() == pytest.approx(PRINT_WIDTH_IN)
    assert fig.get_figheight() <= MAX_HEIGHT_IN + 1e-9 < 24.7 / 2.54
    assert len([a for a in fig.axes if a.get_visible()]) == 9 * 4
    gaps = [a.get_title().split("\n")[-1] for a in fig.axes if "bias" in a.get_title()]
    assert len(gaps) == 9 * 4                      # every panel: RMS and bias, in dB
    assert all(g.startswith("rms ") and g.endswith(" dB") and "-0.0 " not in g
               for g in gaps), gaps


def _without_orders(measured, cut):
    """A 'simulation': the measurement itself, with left Z order 4 at 1e-12 m/s above
    ``cut`` rpm and right X order 6 zero everywhere (the model misses them)."""
    import copy

    import numpy as np
    sim = copy.deepcopy(measured)
    r, v = sim.curves[("left", "z", "order_4")]
    sim.curves[("left", "z", "order_4")] = (r, np.where(r > cut, 1e-12, v))
    r, v = sim.curves[("right", "x", "order_6")]
    sim.curves[("right", "x", "order_6")] = (r, np.zeros_like(v))
    return sim


@pytest.mark.slow
def test_compare_figure_marks_measured_not_modelled_points():
    import matplotlib.pyplot as plt
    import numpy as np

    from powertrain.iotools.measured import read_measured
    from powertrain.plotting.style import MAX_HEIGHT_IN, OKABE_ITO
    from powertrain.workflows.comparison import compare_runup
    meas = read_measured(MEASURED)
    comp = compare_runup(_without_orders(meas, 4000.0), meas)
    per_key = {(e["mount"], e["direction"], e["quantity"]): len(e["rpm"])
               for e in comp.not_modelled}
    assert set(per_key) == {("left", "z", "order_4"), ("right", "x", "order_6")}
    fig = comp.plot()
    fig.draw_without_rendering()             # the layout, as drawn
    marked = [ln for a in fig.axes for ln in a.get_lines()
              if ln.get_label() == "measured, not modelled"]
    assert sorted(len(ln.get_xdata()) for ln in marked) == sorted(per_key.values())
    assert {ln.get_color() for ln in marked} == {OKABE_ITO["reddish purple"]}
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "measured, not modelled" in legend
    assert f"noise-floor limit ({comp.exclusion_limit * 1e3:g} mm/s)" in legend
    title = fig.legends[0].get_title().get_text().replace("\n", " ")
    assert f"{comp.n_not_modelled} points measured, not modelled" in title
    # the panel with nothing scored shows its measured curve and marks, not "not compared"
    assert not any("not compared" in t.get_text() for a in fig.axes for t in a.texts)
    assert all(np.isfinite(ln.get_ydata()).all() for ln in marked)
    assert fig.get_figheight() <= MAX_HEIGHT_IN + 1e-9
    assert not outside_problems(fig), outside_problems(fig)
    plt.close(fig)


def _with_phases(measured, keys, shift_deg):
    """``measured`` with an order phase (a ramp over speed, plus ``shift_deg``) on ``keys``."""
    import copy

    out = copy.deepcopy(measured)
    for key in keys:
        rpm = out.curves[key][0]
        out.phases[key] = (rpm / 10.0 + shift_deg + 180.0) % 360.0 - 180.0
    return out


def _phase_axes(fig):
    from powertrain.plotting.compare import PHASE_LIMIT_DEG
    return [a for a in fig.axes if a.get_visible() and a.get_lines()
            and a.get_ylim() == (-PHASE_LIMIT_DEG, PHASE_LIMIT_DEG)]


@pytest.mark.slow
@pytest.mark.parametrize("phased", ["none", "one side", "left Z", "every order"])
def test_compare_figure_phase_panels_exactly_where_both_sides_give_phase(phased):
    """A phase panel under each level panel with phase on both sides (and nowhere else);
    without, the figure is the level grid alone. Every layout: clean text >= 8 pt, no
    legend over data, palette colours, no taller than the A4 text height."""
    import matplotlib.pyplot as plt

    from powertrain.iotools.measured import read_measured
    from powertrain.plotting.style import MAX_HEIGHT_IN, PRINT_WIDTH_IN
    from powertrain.workflows.comparison import compare_runup
    meas = read_measured(MEASURED)
    orders = [k for k in meas.curves if k[2] != "synthesis"]
    keys = {"none": [], "one side": orders, "left Z": [k for k in orders if k[:2] ==
                                                        ("left", "z")],
            "every order": orders}[phased]
    sim = _with_phases(meas, keys, 20.0)
    meas = _with_phases(meas, [] if phased == "one side" else keys, 0.0)
    fig = compare_runup(sim, meas).plot()
    drawn = drawn_texts(fig)          # lays the figure out and records its texts, once
    shown = _phase_axes(fig)
    expected = 0 if phased == "one side" else len(keys)
    assert len(shown) == expected
    bottom_slot = phased == "every order"   # a bottom phase row's synthesis slot: speed axis
    assert len([a for a in fig.axes if a.get_visible()]) == 9 * 4 + expected + bottom_slot
    for a in shown:
        assert {ln.get_label() for ln in a.get_lines()} == {"measured", "simulated"}
    assert fig.get_figwidth() == pytest.approx(PRINT_WIDTH_IN)
    assert fig.get_figheight() <= MAX_HEIGHT_IN + 1e-9
    problems = (text_problems(fig, drawn=drawn) + small_texts(drawn, fig.get_figwidth())
                + legends_over_data(fig) + off_palette_colours(fig))
    assert not problems, "\n".join(problems[:10])
    plt.close(fig)


@pytest.mark.slow          # ~7-11 s: keeps the fast lane under 3 min
def test_runup_body_figures(tmp_path, monkeypatch, saved):
    engine = str(ROOT / "engines" / "default-modal-body.toml")
    res = run(tmp_path, monkeypatch, "runup", "--engine", engine, "--solver", "harmonic",
              "--from", "1000", "--to", "3000", "--step", "1000", "--plot", "body.png",
              "--path-plot", "paths.png")
    # more rows than fit an A4 page: a second page, named with the files written
    _assert_clean(saved, ["body.png", "body_p2.png", "paths.png"], "runup",
                  panel_legends=False)
    assert "wrote body.png, body_p2.png, paths.png" in res.output


def test_runup_sweep_figure(tmp_path, monkeypatch, saved):
    run(tmp_path, monkeypatch, "runup", "--from", "2000", "--to", "3000", "--sweep", "500",
        "--sample-rate", "4096", "--plot", "sweep.png", "--quiet")
    _assert_clean(saved, ["sweep.png"], "runup", panel_legends=False)


@pytest.mark.slow
def test_whatif_figures(tmp_path, monkeypatch, saved):
    run(tmp_path, monkeypatch, "whatif", "--variants", VARIANTS, "--measured", MEASURED,
        "--from", "1000", "--to", "3000", "--step", "1000", "--workers", "1", "--quiet",
        "--plot", "whatif.png")
    run(tmp_path, monkeypatch, "whatif", "--target", "left.z:+20%:100-300Hz", "--from",
        "1000", "--to", "2000", "--step", "1000", "--workers", "1", "--quiet",
        "--target-plot", "target.png")
    _assert_clean(saved, ["whatif.png"], "whatif", panel_legends=False)
    _assert_clean(saved, ["target.png"], "whatif")


@pytest.mark.slow
def test_diagnose_report_figures(tmp_path, monkeypatch, saved):
    run(tmp_path, monkeypatch, "diagnose", MEASURED, "--effects", "mount_stiffness",
        "--no-pairs", "--noise-floor", "0.005", "--report", "diag")
    _assert_clean(saved, ["gap_map.png", "overlay.png"], "diagnose", panel_legends=False)
    # two panels with different series (channels, orders): a legend above each, off the data
    _assert_clean(saved, ["gap_vs_frequency.png"], "diagnose")


@pytest.mark.slow
@pytest.mark.parametrize("form,axis", [("magnitude-phase", "log"), ("real-imag", "linear"),
                                       ("real-imag", "log"), ("magnitude-phase", "linear")])
def test_stiffness_and_fit_figures(tmp_path, monkeypatch, saved, form, axis):
    res = run(tmp_path, monkeypatch, "stiffness", MOUNT, "--freq", "1:300:1", "--format",
              "csv", "--plot", "k.png", "--form", form, "--freq-axis", axis)
    (tmp_path / "k.csv").write_text("# SYNTHETIC: the model's own curve\n" + res.stdout)
    import matplotlib.pyplot as plt

    from powertrain.plotting.stiffness import FIT_POINTS
    shown = []
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig))
    run(tmp_path, monkeypatch, "fit-mount", "k.csv", "--model", "sls", "--starts", "2",
        "--out", "fit.toml", "--plot", "fit.png", "--form", form, "--freq-axis", axis)
    _assert_clean(saved, ["k.png"], "stiffness")
    _assert_clean(saved, ["fit.png"], "fit-mount")
    fig = shown[-1]
    title = fig.axes[0].get_title().replace("\n", " ")
    assert title.startswith("SYNTHETIC data") and "fitted to k.csv" in title   # the mount
    fitted = [ln for ln in fig.axes[0].get_lines() if "fit" in ln.get_label()]
    assert fitted and all(len(ln.get_xdata()) == FIT_POINTS for ln in fitted)  # a curve
    assert any(ln.get_label().startswith("SYNTHETIC data") for ln in fig.axes[0].get_lines())


def test_fit_amplitudes_figure(tmp_path, monkeypatch, saved):
    """Multi-amplitude fit of the shipped SYNTHETIC table: marked SYNTHETIC, the fit a
    continuous curve per amplitude."""
    import matplotlib.pyplot as plt

    from powertrain.plotting.stiffness import FIT_POINTS
    shown = []
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig))
    run(tmp_path, monkeypatch, "fit-mount", ROOT / "examples" / "hydraulic-mount-amplitudes.csv",
        "--model", "sls", "--starts", "1", "--out", "f.toml", "--plot", "fit-amplitudes.png",
        "--quiet")
    _assert_clean(saved, ["fit-amplitudes.png"], "fit-mount")
    a = shown[-1].axes[0]
    assert a.get_title().startswith("SYNTHETIC data")
    labels = [ln.get_label() for ln in a.get_lines()]
    assert labels and not any("measured" in lab for lab in labels)
    assert sum(lab.endswith("SYNTHETIC data") for lab in labels) == 4
    assert all(len(ln.get_xdata()) == FIT_POINTS for ln in a.get_lines()
               if ln.get_label().endswith("fitted"))


def test_excitation_figure(tmp_path, monkeypatch, saved):
    run(tmp_path, monkeypatch, "excitation", "--rpm", "3000", "--step", "2", "--plot",
        "exc.png")
    _assert_clean(saved, ["exc.png"], "excitation")


@pytest.mark.parametrize("args", [[], ["--static"]])
def test_modes_figure(tmp_path, monkeypatch, saved, args):
    run(tmp_path, monkeypatch, "modes", *args, "--plot", "modes.png")
    _assert_clean(saved, ["modes.png"], "modes")


def test_track_figures(tmp_path, monkeypatch, saved):
    from benchmarks import signals
    from powertrain.iotools.raw_csv import write_raw_csv
    write_raw_csv(tmp_path / "sweep.csv",
                  signals.analytic_sweep(duration=4.0, rpm0=1500.0, rpm1=4500.0),
                  comment="SYNTHETIC: analytic sweep")
    run(tmp_path, monkeypatch, "track", "sweep.csv", "--quantity", "acceleration",
        "--orders", "0.5:8:0.5", "--quiet", "--plot", "orders.png", "--map", "maps.png")
    _assert_clean(saved, ["orders.png"], "track", panel_legends=False)
    _assert_clean(saved, ["maps.png"], "track")


# --------------------------------------------------------------------------- checker
def test_the_checker_finds_overlap_and_overflow():
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.set_title("a title")
    ax.text(0.5, 1.02, "on the title", transform=ax.transAxes, ha="center")
    fig.text(0.9, 0.5, "runs off the right edge")
    problems, outside = text_problems(fig), outside_problems(fig)
    plt.close(fig)
    assert any("overlap" in p and "on the title" in p for p in problems)
    assert any("outside" in p and "right edge" in p for p in problems)
    assert any("right edge" in p for p in outside)
    assert not any("overlap" in p or "on the title" in p for p in outside)


# --------------------------------------------------------------------------- style helpers
def test_one_style_per_order():
    """Every half order to 8 has its own colour and line style, from the palette, the same
    through order_style and quantity_style."""
    from powertrain.plotting.style import PALETTE, order_style, quantity_style
    orders = [k / 2 for k in range(1, 17)]
    styles = [(order_style(o)["color"], order_style(o)["ls"]) for o in orders]
    assert len(set(styles)) == len(orders)
    assert {c for c, _ in styles} <= set(PALETTE)
    assert all(quantity_style(f"order_{o:g}") == order_style(o) for o in orders)
    assert quantity_style("synthesis")["color"] == "k"
    assert order_style(2) == {"color": PALETTE[0], "ls": "-"}


def test_foot_keeps_the_command_whole():
    """The provenance foot breaks the command only between arguments, with shell
    continuations: joined again, it is the command as typed."""
    from powertrain.plotting.style import PRINT_WIDTH_IN, foot_text
    from powertrain.provenance import Provenance
    command = ("powertrain runup --engine engines/default-modal-body.toml --from 1000 --to "
               "6000 --step 500 --csv runup.csv --plot runup.png --path-plot paths.png --quiet")
    text = foot_text(Provenance.now(command, "1.8 L TGDI inline-4 (EA888-like), "
                                    "longitudinal (default.toml)"), PRINT_WIDTH_IN * 0.98)
    lines = text.split("\n")
    first = next(i for i, ln in enumerate(lines) if ln.startswith("$ "))
    shell = lines[first:]
    assert all(ln.endswith(" \\") for ln in shell[:-1]) and len(shell) > 1
    assert " ".join(ln.removesuffix(" \\").strip() for ln in shell) == "$ " + command
    assert not any(ln.endswith(("--from", "--to", "--plot")) for ln in lines)  # option+value


def test_pages_of_a_tall_grid():
    from powertrain.plotting.pages import MIN_ROW_IN, page_path, page_rows
    from powertrain.plotting.style import MAX_HEIGHT_IN
    pages, row = page_rows(list(range(9)), 1.6)
    assert len(pages) == 1 and row * 9 + 1.6 <= MAX_HEIGHT_IN + 1e-9
    pages, row = page_rows(list(range(30)), 1.6)
    assert [r for p in pages for r in p] == list(range(30)) and len(pages) == 3
    assert row >= MIN_ROW_IN and max(map(len, pages)) * row + 1.6 <= MAX_HEIGHT_IN + 1e-9
    assert [page_path("out/runup.png", k) for k in range(3)] == [
        "out/runup.png", "out/runup_p2.png", "out/runup_p3.png"]


def test_signed_never_prints_minus_zero():
    from powertrain.plotting.style import signed
    assert [signed(v) for v in (-0.04, 0.0, -0.0, 0.04, 0.06, -0.26)] == [
        "0.0", "0.0", "0.0", "0.0", "+0.1", "-0.3"]
    assert signed(-0.004, 2) == "0.00"


@pytest.mark.parametrize("lo,hi", [(1, 400), (0.003, 0.2), (0.6, 0.9), (1e-5, 1e3), (30, 600),
                                   (0.95, 1.02), (2.1, 2.9)])
def test_log_ticks_are_plain_numbers(lo, hi):
    from powertrain.plotting.style import _log_ticks, _plain
    ticks = _log_ticks(lo, hi, 8)
    labels = [_plain(t) for t in ticks]
    assert 2 <= len(ticks) <= 8, labels
    assert all(lo <= t <= hi for t in ticks)
    assert not any("×" in lab or "^" in lab for lab in labels)
    if hi / lo < 1e4:
        assert not any("e" in lab for lab in labels), labels
    if (lo, hi) == (1, 400):
        assert labels == ["1", "2", "5", "10", "20", "50", "100", "200"]


@pytest.mark.parametrize("data,extend", [([-10, 2], "min"), ([-2, 8], "max"),
                                         ([-9, 9], "both"), ([-5, 5], "neither")])
def test_colorbar_extends_where_clipped(data, extend):
    import matplotlib.pyplot as plt
    import numpy as np

    from powertrain.plotting.style import colorbar
    fig, ax = plt.subplots(layout="constrained")
    im = ax.pcolormesh(np.array([data]), vmin=-6, vmax=6)
    assert colorbar(fig, im, ax, data, -6, 6, "gap [dB]").extend == extend
    plt.close(fig)


def test_provenance_line():
    from powertrain import __version__
    from powertrain.provenance import Provenance
    p = Provenance.now("powertrain runup --plot r.png", "EA888 (default.toml), balancers off")
    line = p.line()
    assert line.startswith(f"powertrain {__version__}")
    assert "UTC" in line and "balancers off" in line and "$ powertrain runup" in line
    assert p.to_dict()["command"] == "powertrain runup --plot r.png"
    from powertrain.provenance import provenance
    q = Provenance.from_record(provenance())   # the HDF5/JSON record, short form
    assert q.version == __version__ and q.date.endswith("Z") and q.command.startswith("powertrain")


# --------------------------------------------------------------------------- library API
@pytest.fixture
def no_backend_switch(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a plot function switched the matplotlib backend")
    monkeypatch.setattr(matplotlib, "use", refuse)


def test_plot_into_user_axes_and_subfigures(no_backend_switch):
    import matplotlib.pyplot as plt
    import numpy as np

    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.iotools.mount_file import read_mount
    from powertrain.workflows.runup import run_runup
    from powertrain.workflows.stiffness import stiffness_table

    table = stiffness_table(read_mount(MOUNT), np.arange(1.0, 100.0))
    fig, (a1, a2) = plt.subplots(1, 2)
    assert table.plot(a1, form="real-imag") is fig
    assert len(a1.get_lines()) == 2
    result = run_runup(read_engine(DEFAULT_ENGINE_PATH), np.array([1000.0, 2000.0]),
                       solver="harmonic", progress=False)
    assert result.plot(a2, channel=("left", "z"), quantity="order_2") is fig
    assert a2.get_title().startswith("left Z")
    with pytest.raises(InputError, match="pass a Figure or SubFigure"):
        table.plot(a1)    # |K*| and loss angle need two panels
    plt.close(fig)
    fig = plt.figure(layout="constrained")
    left, right = fig.subfigures(1, 2)
    assert result.plot(left) is left and len(left.axes) == 27
    assert table.plot(right) is right and len(right.axes) == 2
    plt.close(fig)


# --------------------------------------------------------------------------- what is drawn
def _drawn_labels(fig):
    return {ln.get_label() for ax in fig.axes for ln in ax.get_lines()}


@pytest.mark.parametrize("spec,expected", [
    ("1.5,2,4", ["order 1.5", "order 2", "order 4"]),
    ("0.5:8:0.5", [f"order {o / 2:g}" for o in range(1, 17)]),
])
def test_track_plot_draws_every_requested_order(spec, expected):
    import matplotlib.pyplot as plt
    import numpy as np

    from benchmarks import signals
    from powertrain.analysis.order_tracking import parse_orders
    from powertrain.workflows.tracking import track_recording
    rec = signals.analytic_sweep(duration=3.0, rpm0=1500.0, rpm1=3500.0)
    tracked = track_recording(rec, parse_orders(spec), rpm_step=100.0, progress=False)
    from powertrain.plotting.style import order_style
    fig = tracked.plot()
    outside = outside_problems(fig)          # draws the figure (layout, texts)
    assert not outside, outside
    assert not legend_problems(fig) and not unit_problems(fig)
    title = fig.legends[0].get_title().get_text().replace("\n", " ")
    drawn = _drawn_labels(fig)
    assert "synthesis" in drawn
    for label in expected:       # drawn, or named in the title as more than 60 dB down
        assert label in drawn or f" {label[6:]}," in title.split("not drawn")[-1] + ",", label
    for ax in fig.axes:          # at most the documented dynamic range, plain tick labels
        lo, hi = ax.get_ylim()
        assert 20 * np.log10(hi / lo) <= 60 + 20 * np.log10(1.4) + 1e-6
        assert not any("e" in t.get_text() for t in ax.get_yticklabels())
        levels = np.concatenate([ln.get_ydata() for ln in ax.get_lines()])
        assert lo >= levels.min() / 1.4 - 1e-12        # the range from the drawn curves
        for ln in ax.get_lines():                      # one colour per order, everywhere
            if ln.get_label() != "synthesis":
                style = order_style(float(ln.get_label()[6:]))
                assert (ln.get_color(), ln.get_linestyle()) == (style["color"], style["ls"])
    plt.close(fig)


def test_map_channel_and_reference_unit(tmp_path, monkeypatch, saved):
    import matplotlib.pyplot as plt

    from benchmarks import signals
    from powertrain.iotools.raw_csv import write_raw_csv
    write_raw_csv(tmp_path / "sweep.csv",
                  signals.analytic_sweep(duration=3.0, rpm0=1500.0, rpm1=3500.0),
                  comment="SYNTHETIC: analytic sweep")
    shown = []
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig))
    run(tmp_path, monkeypatch, "track", "sweep.csv", "--orders", "2,4", "--quiet",
        "--map", "maps.png", "--map-channel", "left.z", "--as", "velocity", "--csv", "t.csv")
    _assert_clean(saved, ["maps.png"], "track")
    fig = shown[-1]
    a1, a2 = fig.axes[:2]
    import csv
    lines = [ln for ln in (tmp_path / "t.csv").read_text().splitlines() if ln[:1] != "#"]
    rpm = [float(row["rpm"]) for row in csv.DictReader(lines)]
    assert a1.get_ylim() == a2.get_ylim() == (min(rpm), max(rpm))  # the tracked range
    assert "centred in the record" in a1.get_title()          # why the map stops short
    assert a1.get_xlim()[1] == pytest.approx(1.25 * 4)       # 25 % above the highest order
    assert "left.z" in fig.legends[0].get_title().get_text() if fig.legends else \
        "left.z" in fig._suptitle.get_text()
    res = CliRunner().invoke(main, ["track", "sweep.csv", "--map", "m.png", "--map-channel",
                                    "nope"])
    assert res.exit_code == 1 and "--map-channel" in res.output
    assert not (tmp_path / "m.png").exists()


@pytest.mark.slow
def test_whatif_levels_and_delta_views():
    """Both views draw every channel-quantity (the retuned mount's included however little
    it changes), a legend of exactly what is drawn, and name no figure that was not made."""
    import matplotlib.pyplot as plt
    import numpy as np

    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.workflows.operations import Variant
    from powertrain.workflows.variants import parse_operations
    from powertrain.workflows.whatif import run_whatif
    engine = read_engine(DEFAULT_ENGINE_PATH)
    variants = [Variant("gearbox x3", parse_operations({"scale": ["gearbox.*.stiffness=3"]}))]
    result = run_whatif(engine, variants, np.array([1000.0, 2000.0, 3000.0]), workers=1,
                        progress=False)
    keys = [(m, d, q) for m, d in result.baseline.channels for q in result.quantities]
    for view in ("levels", "delta"):
        fig = result.plot(view=view)
        assert not outside_problems(fig), outside_problems(fig)
        assert not legend_problems(fig) and not unit_problems(fig)
        assert not page_problems(fig, 300)
        titles = [a.get_title() for a in fig.axes if a.get_visible()]
        assert len(titles) == len(keys)
        for m, d, q in keys:
            assert f"{m} {d.upper()} · {q.replace('_', ' ')}" in titles
        text = fig.legends[0].get_title().get_text()
        assert "figure" not in text and "-0.00" not in " ".join(
            t.get_text() for t in fig.legends[0].get_texts())
        assert any(v.name in lab for v in result.variants for lab in _drawn_labels(fig))
        plt.close(fig)
