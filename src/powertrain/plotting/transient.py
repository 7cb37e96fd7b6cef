"""The figures of a transient manoeuvre: crank speed and torque over time above the chosen
channels (each channel's peak marked, its value and time above the panel), the what-if
ranking over a manoeuvre (bars in rank order, or each variant's change against the
baseline), and a simulated manoeuvre overlaid on its recording (a grid that fits a page,
each panel headed by its peak error and RMS of the difference)."""

from __future__ import annotations

import math

import numpy as np

from powertrain.errors import InputError
from powertrain.plotting.style import (
    LABEL_SIZE,
    MAX_HEIGHT_IN,
    OKABE_ITO,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    finish,
    is_axes,
    legend,
    signed,
    subplots,
)

#: Quantities a channel panel shows: attribute, scale to the unit shown, unit.
QUANTITIES = {"acceleration": ("acceleration", 1.0, "m/s²"),
              "displacement": ("displacement", 1e3, "mm"),
              "force": ("force", 1.0, "N")}
#: The crank speed is black (no channel or torque line shares it); the torques (twin axis
#: of the top panel) and the channels take distinct colours of the palette, a channel
#: beyond the third its colour again with another line style.
SPEED_COLOUR = OKABE_ITO["black"]
TORQUE_STYLES = {"engine": (OKABE_ITO["orange"], "-"),
                 "starter": (OKABE_ITO["sky blue"], "--"),
                 "driveline": (OKABE_ITO["vermillion"], ":")}
CHANNEL_COLOURS = (OKABE_ITO["blue"], OKABE_ITO["bluish green"], OKABE_ITO["reddish purple"])
#: Margins of the data inside a channel panel (fractions of the data range): a peak at the
#: first or last step, or at the top or bottom, keeps its marker clear of the frame.
X_MARGIN, Y_MARGIN = 0.05, 0.12
#: Height of a panel of a transient figure [in], and the most panel rows of an overlay on
#: one page (more channels are left out and named in the title).
ROW_IN, MAX_OVERLAY_ROWS = 1.45, 5


def channel_style(k: int) -> dict:
    """Colour and line style of the ``k``-th channel panel (:data:`CHANNEL_COLOURS`)."""
    n = len(CHANNEL_COLOURS)
    return {"color": CHANNEL_COLOURS[k % n], "ls": ("-", "--", ":", "-.")[(k // n) % 4]}


def plot_transient(result, channels, path=None, ax=None, provenance=None,
                   quantity="acceleration"):
    """Speed [rpm] and the torques [N·m] in the top panel, below it one panel per channel of
    ``channels`` (labels ``mount.direction``) with its ``quantity`` (:data:`QUANTITIES`);
    each channel's largest magnitude is marked (▲/▼) and its value and time stand above the
    panel's frame. Returns the figure; ``ax``: None (a new figure), a Figure or SubFigure
    (one Axes is refused: the figure has several panels)."""
    if quantity not in QUANTITIES:
        raise InputError(f"unknown quantity {quantity!r} (one of: {', '.join(QUANTITIES)})",
                         key="--quantity")
    attr, scale, unit = QUANTITIES[quantity]
    missing = [c for c in channels if c not in result.channels]
    if missing:
        raise InputError(f"unknown channel {missing[0]!r} (one of: "
                         f"{', '.join(result.channels)})", key="channels")
    n = 1 + len(channels)
    height = min(1.7 + ROW_IN * n, MAX_HEIGHT_IN)
    fig, axes, own = subplots(ax, n, 1, figsize=(PRINT_WIDTH_IN, height), sharex=True)
    twin = _speed_and_torque(axes[0, 0], result)
    for row, c in enumerate(channels, start=1):
        y = getattr(result, attr)[:, result.channel(c)] * scale
        _channel_panel(axes[row, 0], result.time, y, c, unit, channel_style(row - 1))
    for a in axes[:, 0]:
        a.tick_params(labelsize=TICK_SIZE)
        a.grid(True, lw=0.3)
    axes[-1, 0].set_xlabel("time [s]", fontsize=LABEL_SIZE)
    handles, labels = twin.get_legend_handles_labels()
    legend(fig, axes, ax, extra=list(zip(handles, labels)))
    if not own:
        axes[0, 0].set_title(result.name, fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance,
                  title=f"{result.name} — {result.engine}" if own else None)


def _speed_and_torque(top, result):
    """The top panel: crank speed (black) and, on a twin axis, every torque that is not
    zero throughout (:data:`TORQUE_STYLES`); returns the twin axes."""
    t = result.time
    top.plot(t, result.rpm, color=SPEED_COLOUR, lw=1.2, label="crank speed [rpm]")
    top.set_ylabel("speed [rpm]", fontsize=LABEL_SIZE)
    top.margins(x=X_MARGIN)
    twin = top.twinx()
    for name, values in result.torques.items():
        if np.any(values):
            color, ls = TORQUE_STYLES.get(name, (OKABE_ITO["reddish purple"], "-."))
            twin.plot(t, values, color=color, lw=0.9, ls=ls, label=f"{name} torque [N·m]")
    twin.set_ylabel("torque [N·m]", fontsize=LABEL_SIZE)
    twin.tick_params(labelsize=TICK_SIZE)
    return twin


def _channel_panel(a, t, y, label, unit, style):
    """One channel's trace, its peak marked on the curve and written above the frame (the
    panel's right-hand title: free space, never on the trace)."""
    i = int(np.argmax(np.abs(y)))
    marker = "v" if y[i] < 0 else "^"
    a.plot(t, y, lw=0.7, label=label, **style)
    a.plot(t[i], y[i], marker, color="k", ms=5, label="peak")
    a.margins(x=X_MARGIN, y=Y_MARGIN)
    a.set_title(f"peak {'▼' if y[i] < 0 else '▲'} {y[i]:.3g} {unit} at {t[i]:.3f} s",
                loc="right", fontsize=TICK_SIZE, pad=2)
    a.set_ylabel(f"{label}\n[{unit}]", fontsize=LABEL_SIZE)


# ------------------------------------------------------------------ what-if ranking
def plot_ranking(ranking, path=None, ax=None, provenance=None, view="levels"):
    """The what-if over a manoeuvre as horizontal bars, best (smallest) first from the top
    in the ranking's order: ``view="levels"`` the peak seat acceleration [m/s²] (with a
    seat) and the peak mount deflection [mm] of every run (the mount direction named),
    ``view="delta"`` each variant's change of them against the baseline [%]; every bar
    carries its value. Returns the figure."""
    if view not in ("levels", "delta"):
        raise InputError(f"unknown view {view!r} (levels or delta)", key="view")
    panels = ranking_panels(ranking, delta=view == "delta")
    n_bars = len(panels[0][1])
    fig, axes, own = subplots(ax, len(panels), 1, figsize=(
        PRINT_WIDTH_IN, min(1.5 + len(panels) * (0.75 + 0.3 * n_bars), MAX_HEIGHT_IN)))
    for a, (title, names, values, notes, unit) in zip(axes[:, 0], panels):
        _bars(a, names, values, notes, unit, delta=view == "delta")
        a.set_title(title, fontsize=TITLE_SIZE, loc="left")
    what = "change against the baseline" if view == "delta" else "peaks"
    return finish(fig, own, path, provenance,
                  title=f"what-if over {ranking.manoeuvre}: {what}, ranked by "
                        f"{ranking.ranked_by().replace('_', ' ')} (best at the top)")


def ranking_panels(ranking, delta=False) -> list:
    """``(title, names, values, notes, unit)`` per panel of :func:`plot_ranking`, the runs
    in rank order (without the baseline for ``delta``: their change in %)."""
    order = ranking.ranking()
    if delta:
        order = [k for k in order if k != 0]
    seat = ranking.peak_seat()
    defl, where = ranking.peak_deflection()
    quantities = [("peak seat acceleration", seat, [""] * len(defl), "m/s²"),
                  ("peak mount deflection", defl * 1e3, [f" ({w})" for w in where], "mm")]
    panels = []
    for title, values, notes, unit in quantities:
        if values is None:
            continue
        if delta:
            values, unit = 100.0 * (values / values[0] - 1.0), "%"
            title = f"{title}: change against the baseline"
        panels.append((title, [ranking.names[k] for k in order],
                       np.array([values[k] for k in order]), [notes[k] for k in order], unit))
    return panels


def _bars(a, names, values, notes, unit, delta):
    """Horizontal bars of ``values`` (first at the top), each bar's value (and ``notes``) in
    a column right of the frame, on its bar's line; the baseline grey, the variants blue
    (``delta``: a decrease blue, an increase vermillion, about a zero line)."""
    y = np.arange(len(names))
    if delta:
        colours = [OKABE_ITO["blue"] if v <= 0 else OKABE_ITO["vermillion"] for v in values]
        texts = [f"{signed(v, _decimals(v))} %" for v in values]
        a.axvline(0.0, color="k", lw=0.8)
        lo, hi = min(0.0, float(np.min(values))), max(0.0, float(np.max(values)))
        pad = 0.08 * ((hi - lo) or 1.0)
        a.set_xlim(lo - pad, hi + pad)            # the zero line clear of the frame
    else:
        colours = ["0.55" if n == "baseline" else OKABE_ITO["blue"] for n in names]
        texts = [f"{v:.4g} {unit}{note}" for v, note in zip(values, notes)]
    a.barh(y, values, color=colours, height=0.6)
    a.set_yticks(y, names, fontsize=TICK_SIZE)
    a.set_ylim(len(names) - 0.5, -0.5)           # the first at the top
    values_axis = a.secondary_yaxis("right")
    values_axis.set_yticks(y, texts, fontsize=TICK_SIZE)
    values_axis.tick_params(length=0, pad=4)
    a.set_xlabel(("change against the baseline" if delta else "peak") + f" [{unit}]",
                 fontsize=LABEL_SIZE)
    a.tick_params(labelsize=TICK_SIZE)
    a.grid(True, axis="x", lw=0.3)


def _decimals(value) -> int:
    """Decimals of a change [%]: one from 1 % on, below it two significant digits (at most
    three decimals)."""
    size = abs(float(value))
    return 1 if size == 0 or size >= 1 else min(3, 1 - math.floor(math.log10(size)))


# ------------------------------------------------------------------ overlay on a recording
def overlay_grid(n: int) -> tuple:
    """``(rows, columns, shown)`` of an overlay of ``n`` channels: one column up to three
    channels, else three (a mount's X, Y, Z side by side), at most
    :data:`MAX_OVERLAY_ROWS` rows (``shown`` channels; the rest are left out)."""
    cols = 1 if n <= 3 else 3
    rows = min(math.ceil(n / cols), MAX_OVERLAY_ROWS)
    return rows, cols, min(n, rows * cols)


def plot_overlay(comparison, path=None, ax=None, provenance=None):
    """Measured and simulated acceleration [m/s²] over time, one panel per channel in a grid
    that fits a page (:func:`overlay_grid`; where not all fit, the seat's and those of the
    largest relative RMS of the difference are drawn, in file order
    (:func:`overlay_channels`), and the others named in the title), each
    panel headed by the channel, the simulated peak's error [%] and the RMS of the
    difference [m/s²] (and of the measured RMS [%]). Returns the figure."""
    n = len(comparison.channels)
    rows, cols, shown = overlay_grid(n)
    height = min(1.7 + 1.6 * rows, MAX_HEIGHT_IN)
    fig, axes, own = subplots(ax, rows, cols, figsize=(PRINT_WIDTH_IN, height), sharex=True)
    e = comparison.errors()
    t = comparison.time
    drawn = overlay_channels(comparison.channels, e["rms_difference_percent"], shown)
    for k, a in enumerate(axes.ravel()):
        if k >= shown:
            _hide(axes, k, cols)
            continue
        j = drawn[k]
        a.plot(t, comparison.measured[:, j], color=OKABE_ITO["blue"], lw=0.7,
               label="measured")
        a.plot(t, comparison.simulated[:, j], color=OKABE_ITO["orange"], lw=0.7, ls="--",
               label="simulated")
        peak, share = e["peak_error_percent"][j], e["rms_difference_percent"][j]
        a.set_title(f"{comparison.channels[j]}: peak "
                    f"{'n/a' if np.isnan(peak) else signed(peak) + ' %'}\n"
                    f"RMS diff. {e['rms_difference'][j]:.3g} m/s²"
                    + ("" if np.isnan(share) else f" ({share:.0f} %)"), fontsize=TICK_SIZE,
                    pad=3)
        a.margins(x=X_MARGIN, y=Y_MARGIN)
        a.tick_params(labelsize=TICK_SIZE)
        a.grid(True, lw=0.3)
    for a in axes[-1, :]:
        a.set_xlabel("time [s] (simulation)", fontsize=LABEL_SIZE)
    if is_axes(ax):
        axes[0, 0].set_ylabel("acceleration [m/s²]", fontsize=LABEL_SIZE)
    else:
        fig.supylabel("acceleration [m/s²]", fontsize=LABEL_SIZE)
    legend(fig, axes, ax)
    title = (f"{comparison.name} — simulated vs {comparison.raw}; over each panel the "
             "simulated peak's error and the RMS of the difference (of the measured RMS)")
    if shown < n:
        title += (f"; {n - shown} channels of smaller RMS difference not drawn (in the table "
                  "and JSON): " + ", ".join(c for j, c in enumerate(comparison.channels)
                                            if j not in drawn))
    return finish(fig, own, path, provenance, title=title)


def overlay_channels(channels, rms_difference_percent, shown) -> list:
    """Indices of the ``shown`` channels drawn, in their order: the seat's axes (a body
    point named ``seat...``) first, then those of the largest RMS of the difference
    relative to the measured RMS [%] (a channel without one last)."""
    share = np.nan_to_num(np.asarray(rms_difference_percent, float), nan=-np.inf)
    seat = np.array([c.startswith("seat") for c in channels])
    order = np.lexsort((-share, ~seat))
    return sorted(int(j) for j in order[:shown])


def _hide(axes, j, cols):
    """Hide the unused panel ``j`` of the grid; the panel above it keeps its time axis."""
    r, c = divmod(j, cols)
    axes[r, c].set_visible(False)
    if r > 0:
        above = axes[r - 1, c]
        above.xaxis.set_tick_params(labelbottom=True)
        above.set_xlabel("time [s] (simulation)", fontsize=LABEL_SIZE)
