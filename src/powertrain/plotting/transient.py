"""Figures of a transient manoeuvre: speed and torque over the chosen channels, the what-if
ranking over a manoeuvre, and a simulated manoeuvre overlaid on its recording."""

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
#: Crank speed black; torques (twin axis) and channels in distinct palette colours.
SPEED_COLOUR = OKABE_ITO["black"]
TORQUE_STYLES = {"engine": (OKABE_ITO["orange"], "-"),
                 "starter": (OKABE_ITO["sky blue"], "--"),
                 "driveline": (OKABE_ITO["vermillion"], ":")}
CHANNEL_COLOURS = (OKABE_ITO["blue"], OKABE_ITO["bluish green"], OKABE_ITO["reddish purple"])
#: Data margins inside a channel panel (fractions of its range): a peak marker clear of the frame.
X_MARGIN, Y_MARGIN = 0.05, 0.12
#: Height of a panel [in], and the most panel rows of an overlay (the rest named in the title).
ROW_IN, MAX_OVERLAY_ROWS = 1.45, 5


def channel_style(k: int) -> dict:
    """Colour and line style of the ``k``-th channel panel (:data:`CHANNEL_COLOURS`)."""
    n = len(CHANNEL_COLOURS)
    return {"color": CHANNEL_COLOURS[k % n], "ls": ("-", "--", ":", "-.")[(k // n) % 4]}


def plot_transient(result, channels, path=None, ax=None, provenance=None, quantity="acceleration"):
    """Speed [rpm] and torques [N·m] of ``result`` above a panel per channel of ``channels``
    (``mount.direction``) with its ``quantity`` (:data:`QUANTITIES`), its peak marked; PNG
    to ``path``, into ``ax`` (None, Figure, SubFigure), ``provenance`` at the foot."""
    if quantity not in QUANTITIES:
        raise InputError(f"unknown quantity {quantity!r} (one of: {', '.join(QUANTITIES)})", key="--quantity")
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
    return finish(fig, own, path, provenance, title=f"{result.name} — {result.engine}" if own else None)


def _speed_and_torque(top, result):
    """Top panel: speed, and on a returned twin axis every torque not zero throughout."""
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
    """One channel's trace, its peak marked and written above the frame."""
    i = int(np.argmax(np.abs(y)))
    marker = "v" if y[i] < 0 else "^"
    a.plot(t, y, lw=0.7, label=label, **style)
    a.plot(t[i], y[i], marker, color="k", ms=5, label="peak")
    a.margins(x=X_MARGIN, y=Y_MARGIN)
    a.set_title(f"peak {'▼' if y[i] < 0 else '▲'} {y[i]:.3g} {unit} at {t[i]:.3f} s",
                loc="right", fontsize=TICK_SIZE, pad=2)
    a.set_ylabel(f"{label}\n[{unit}]", fontsize=LABEL_SIZE)


def plot_ranking(ranking, path=None, ax=None, provenance=None, view="levels"):
    """The what-if ``ranking`` over a manoeuvre as bars, best at the top: ``view="levels"``
    peak seat acceleration [m/s²] and mount deflection [mm], ``"delta"`` their change [%];
    ``path``, ``ax``, ``provenance`` as :func:`plot_transient`'s."""
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
    """``(title, names, values, notes, unit)`` per panel of :func:`plot_ranking` of
    ``ranking``, runs in rank order (``delta``: changes [%], no baseline)."""
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
    """Horizontal bars, first at the top, values and ``notes`` right of the frame (``delta``:
    a decrease blue, an increase vermillion)."""
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
    a.set_xlabel(("change against the baseline" if delta else "peak") + f" [{unit}]", fontsize=LABEL_SIZE)
    a.tick_params(labelsize=TICK_SIZE)
    a.grid(True, axis="x", lw=0.3)


def _decimals(value) -> int:
    """Decimals of a change [%]: one from 1 %, else two significant digits (at most three)."""
    size = abs(float(value))
    return 1 if size == 0 or size >= 1 else min(3, 1 - math.floor(math.log10(size)))


def overlay_grid(n: int) -> tuple:
    """``(rows, columns, shown)`` of an overlay of ``n`` channels: one column up to three,
    else three, at most :data:`MAX_OVERLAY_ROWS` rows."""
    cols = 1 if n <= 3 else 3
    rows = min(math.ceil(n / cols), MAX_OVERLAY_ROWS)
    return rows, cols, min(n, rows * cols)


def plot_overlay(comparison, path=None, ax=None, provenance=None):
    """Measured and simulated acceleration [m/s²] of ``comparison`` over time, a panel per
    channel (:func:`overlay_channels`) headed by its peak error [%] and RMS difference
    [m/s²]; ``path``, ``ax``, ``provenance`` as :func:`plot_transient`'s."""
    n = len(comparison.channels)
    rows, cols, shown = overlay_grid(n)
    height = min(1.7 + 1.6 * rows, MAX_HEIGHT_IN)
    fig, axes, own = subplots(ax, rows, cols, figsize=(PRINT_WIDTH_IN, height), sharex=True)
    e, t = comparison.errors(), comparison.time
    drawn = overlay_channels(comparison.channels, e["rms_difference_percent"], shown)
    for k, a in enumerate(axes.ravel()):
        if k >= shown:
            _hide(axes, k, cols)
            continue
        j = drawn[k]
        a.plot(t, comparison.measured[:, j], color=OKABE_ITO["blue"], lw=0.7, label="measured")
        a.plot(t, comparison.simulated[:, j], color=OKABE_ITO["orange"], lw=0.7, ls="--", label="simulated")
        peak, share = e["peak_error_percent"][j], e["rms_difference_percent"][j]
        a.set_title(f"{comparison.channels[j]}: peak "
                    f"{'n/a' if np.isnan(peak) else signed(peak) + ' %'}\n"
                    f"RMS diff. {e['rms_difference'][j]:.3g} m/s²"
                    + ("" if np.isnan(share) else f" ({share:.0f} %)"), fontsize=TICK_SIZE, pad=3)
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
    """Indices of the ``shown`` of ``channels`` drawn, in order: the seat's first, then the
    largest ``rms_difference_percent``."""
    share = np.nan_to_num(np.asarray(rms_difference_percent, float), nan=-np.inf)
    seat = np.array([c.startswith("seat") for c in channels])
    order = np.lexsort((-share, ~seat))
    return sorted(int(j) for j in order[:shown])


def _hide(axes, j, cols):
    """Hide unused panel ``j`` of ``axes``; the panel above keeps its time axis."""
    r, c = divmod(j, cols)
    axes[r, c].set_visible(False)
    if r > 0:
        above = axes[r - 1, c]
        above.xaxis.set_tick_params(labelbottom=True)
        above.set_xlabel("time [s] (simulation)", fontsize=LABEL_SIZE)
