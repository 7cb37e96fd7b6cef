"""Plots of order-tracked run-ups: order curves, Campbell (rpm-order) and rpm-frequency
maps, slow vs fast sweep."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.analysis.orders import order_label
from powertrain.plotting.runup import style_panel
from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colorbar,
    colour,
    figure_legend,
    finish,
    is_axes,
    legend,
    log_axis,
    no_data,
    quantity_label,
    quantity_style,
    subplots,
    wrap,
)

#: Display unit and factor per quantity.
DISPLAY = {"acceleration": ("m/s²", 1.0), "velocity": ("mm/s", 1e3),
           "displacement": ("mm", 1e3), "force": ("N", 1.0)}
#: Dynamic range of an order-curve panel [dB] below its largest level (noise does not
#: stretch the axis).
DYNAMIC_RANGE_DB = 60.0
#: Campbell and waterfall maps reach this far above the highest tracked order.
MAP_MARGIN = 1.25


def tracked_quantities(tracked) -> list:
    """What ``track --plot`` draws: the synthesis and every order of ``tracked``."""
    return ["synthesis"] + [order_label(o) for o in tracked.orders]


def plot_tracked(tracked, path=None, quantities=None, *, ax=None, provenance=None):
    """Order RMS of ``tracked`` against rpm, a panel per channel: ``quantities`` (default
    :func:`tracked_quantities`); curves wholly :data:`DYNAMIC_RANGE_DB` below the panel's
    largest are named in the title instead. PNG to ``path``; ``ax`` None, Figure, SubFigure
    or (one channel) an Axes; ``provenance`` at the foot."""
    quantities = list(quantities or tracked_quantities(tracked))
    n = len(tracked.channels)
    cols = min(3, n)
    rows = -(-n // cols)
    fig, axes, own = subplots(ax, rows, cols, figsize=(PRINT_WIDTH_IN, 2.0 * rows + 2.4))
    hidden = {}
    for c, ch in enumerate(tracked.channels):
        a = axes[c // cols][c % cols]
        label = ch.label
        drawn, left_out = _draw_curves(a, tracked, label, quantities, DISPLAY[ch.quantity][1])
        for q in left_out:
            hidden.setdefault(q, []).append(label)
        if not style_panel(a, f"{label} ({ch.quantity})", drawn, DYNAMIC_RANGE_DB):
            no_data(a, "zero at every speed")
        a.set_ylabel(f"RMS [{DISPLAY[ch.quantity][0]}]", fontsize=LABEL_SIZE)
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    for c in range(n, rows * cols):
        axes[c // cols][c % cols].set_visible(False)
    legend(fig, axes, ax)
    title = f"order tracking ({tracked.method}) of {Path(str(tracked.source)).name}"
    return finish(fig, own, path, provenance,
                  title=title + _hidden_note(hidden, n) if not is_axes(ax) else None)


def _hidden_note(hidden, n_channels) -> str:
    """The title's note on the orders not drawn, grouped by panel."""
    groups = {}
    for q, where in hidden.items():
        groups.setdefault("any panel" if len(where) == n_channels else ", ".join(where), []).append(q)
    note = ""
    for where, qs in groups.items():
        names = ", ".join(q.replace("order_", "") for q in qs)
        note += (f"; not drawn in {where}: order{'s' * (len(qs) > 1)} {names}, more than "
                 f"{DYNAMIC_RANGE_DB:g} dB below the panel's largest level")
    return note


def _draw_curves(a, tracked, label, quantities, factor):
    """Draw a channel's curves reaching within :data:`DYNAMIC_RANGE_DB` of its largest;
    ``(drawn levels clipped to that range, quantities not drawn)``."""
    curves = {}
    for q in quantities:
        v = tracked.curve(label, q) * factor
        ok = np.isfinite(v) & (v > 0)
        curves[q] = (tracked.rpm[ok], v[ok])
    peak = max((float(v.max()) for _, v in curves.values() if v.size), default=0.0)
    floor = peak * 10 ** (-DYNAMIC_RANGE_DB / 20)
    drawn, left_out = [], []
    for q, (r, v) in curves.items():
        if not v.size or v.max() < floor:
            left_out.append(q)
            continue
        a.plot(r, v, label=quantity_label(q), lw=1.8 if q == "synthesis" else 1.1, **quantity_style(q))
        drawn.append(np.maximum(v, floor))
    return (np.concatenate(drawn) if drawn else np.array([])), left_out


def plot_maps(rpm, orders, order_rms, times, freqs, rpm_t, psd, title="", path=None,
              unit="m/s²", *, factor=1.0, max_order=None, tracked_rpm=None, block_revs=None,
              window_s=None, ax=None, provenance=None):
    """Campbell map (``order_rms`` [SI] at ``rpm`` × ``orders``) above the rpm-frequency map
    (``psd`` at ``rpm_t`` × ``freqs``; ``times`` unused), in dB re the maximum on an 80 dB
    scale, shown in ``unit`` = SI × ``factor``; axes end :data:`MAP_MARGIN` above
    ``max_order``. Both speed axes span ``tracked_rpm``; speeds a map does not reach (its
    ``block_revs`` blocks or ``window_s`` windows centred in the record) shaded. ``title``,
    ``path``, ``ax`` (None, Figure, SubFigure), ``provenance`` as usual."""
    fig, axes, own = subplots(ax, 2, 1, figsize=(PRINT_WIDTH_IN, 7.4), sharey=True)
    a1, a2 = axes[:, 0]
    top = MAP_MARGIN * float(max_order or np.max(orders))
    ref = max(np.max(order_rms), 1e-30)
    db1 = 20 * np.log10(np.maximum(order_rms, ref * 1e-5) / ref)
    m1 = a1.pcolormesh(orders, rpm, db1, shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a1.set_xlabel("order", fontsize=LABEL_SIZE)
    a1.set_xlim(0, min(top, float(np.max(orders))))
    colorbar(fig, m1, a1, db1, -80, 0, f"order RMS [dB re {ref * factor:.3g} {unit}]")
    refp = max(np.max(psd), 1e-30)
    db2 = 10 * np.log10(np.maximum(psd, refp * 1e-8) / refp)
    m2 = a2.pcolormesh(freqs, rpm_t, db2, shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a2.set_xlabel("frequency [Hz]", fontsize=LABEL_SIZE)
    colorbar(fig, m2, a2, db2, -80, 0, "PSD [dB re max]")
    f_top = top * float(np.max(rpm)) / 60.0
    a2.set_xlim(float(np.min(freqs)), min(f_top, float(np.max(freqs))))
    lo, hi = tracked_rpm or (min(np.min(rpm), np.min(rpm_t)), max(np.max(rpm), np.max(rpm_t)))
    for a, name, speeds, span in (
            (a1, "rpm-order map (Campbell)", rpm, block_revs and f"{block_revs:g}-revolution "
             "blocks"),
            (a2, "rpm-frequency map (waterfall)", rpm_t, window_s and f"{window_s:.2g} s "
             "windows")):
        _speed_axis(a, name, float(np.min(speeds)), float(np.max(speeds)), (lo, hi), span)
    return finish(fig, own, path, provenance, title=title if not is_axes(ax) else None)


def _speed_axis(a, name, first, last, limits, span):
    """Speed axis ``limits`` [rpm] of a map reaching ``first``..``last``, the rest shaded."""
    lo, hi = float(min(limits)), float(max(limits))
    step = (last - first) / 50 if last > first else 0.0
    title = name
    if first - step > lo or last + step < hi:
        title += (f": data {first:.0f}–{last:.0f} rpm of {lo:.0f}–{hi:.0f}"
                  + (f" ({span} centred in the record)" if span else ""))
        for a0, a1_ in ((lo, first), (last, hi)):
            if a1_ > a0:
                a.axhspan(a0, a1_, color="0.88", lw=0, zorder=0)
    a.set_title(wrap(title, PRINT_WIDTH_IN * 0.75, TITLE_SIZE), fontsize=TITLE_SIZE)
    a.set_ylabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a.set_ylim(lo, hi)
    a.tick_params(labelsize=TICK_SIZE)
    a.yaxis.set_tick_params(labelleft=True)


def plot_sweep_rates(curves, path=None, title="", *, ax=None, provenance=None):
    """Order curves of several sweep rates over the stepped run-up: ``curves`` of (label,
    rpm, level [m/s]); ``path``, ``title``, ``ax``, ``provenance`` as usual."""
    fig, axes, own = subplots(ax, figsize=(PRINT_WIDTH_IN, 4.2))
    a = axes[0, 0]
    for k, (label, rpm, level) in enumerate(curves):
        stepped = label.startswith("stepped")
        a.plot(rpm, np.asarray(level) * 1e3, label=label, lw=2.2 if stepped else 1.2,
               color="k" if stepped else colour(k), ls="--" if stepped else "-")
    log_axis(a, "y")
    a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a.set_ylabel("RMS velocity [mm/s]", fontsize=LABEL_SIZE)
    a.grid(True, which="major", alpha=0.35)
    if own:
        figure_legend(fig, axes)
    else:
        a.legend(fontsize=LEGEND_SIZE)
    return finish(fig, own, path, provenance, title=title if own else None)
