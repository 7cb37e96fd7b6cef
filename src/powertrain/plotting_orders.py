"""Plots of order-tracked run-ups: order curves, Campbell (rpm-order) and rpm-frequency
maps, slow vs fast sweep. matplotlib comes through :mod:`powertrain.plotting`."""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import (
    LABEL_SIZE,
    TICK_SIZE,
    TITLE_SIZE,
    colorbar,
    figure_legend,
    finish,
    log_axis,
    no_data,
    subplots,
)

#: Display unit and factor per quantity.
DISPLAY = {"acceleration": ("m/s²", 1.0), "velocity": ("mm/s", 1e3),
           "displacement": ("mm", 1e3), "force": ("N", 1.0)}


def plot_tracked(tracked, path=None, quantities=None, *, ax=None, provenance=None):
    """Order RMS against rpm, one panel per channel (synthesis and the orders asked); one
    legend for the figure; returns the figure (``ax``: None, Figure or SubFigure, or an
    Axes when there is one channel)."""
    from powertrain.analysis.orders import order_label
    from powertrain.plotting.runup import style_panel
    quantities = list(quantities or ["synthesis"] + [order_label(o) for o in tracked.orders
                                                     if o in (1.0, 2.0, 4.0)]
                      or [order_label(tracked.orders[0])])
    n = len(tracked.channels)
    cols = min(3, n)
    rows = -(-n // cols)
    fig, axes, own = subplots(ax, rows, cols, figsize=(4.2 * cols + 0.4, 2.6 * rows + 1.3))
    for c, ch in enumerate(tracked.channels):
        a = axes[c // cols][c % cols]
        unit, f = DISPLAY[ch.quantity]
        label = ch.mount + ("" if ch.side == "active" else f".{ch.side}") + f".{ch.direction}"
        values = []
        for k, q in enumerate(quantities):
            v = tracked.curve(label, q) * f
            ok = np.isfinite(v) & (v > 0)
            a.plot(tracked.rpm[ok], v[ok], color=f"C{k % 10}", label=q.replace("_", " "))
            values.append(v[ok])
        if not style_panel(a, f"{label} ({ch.quantity})", np.concatenate(values)):
            no_data(a, "zero at every speed")
        a.set_ylabel(f"RMS [{unit}]", fontsize=LABEL_SIZE)
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    for c in range(n, rows * cols):
        axes[c // cols][c % cols].set_visible(False)
    if own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance,
                  title=f"order tracking ({tracked.method}) of {tracked.source}" if own
                  else None)


def plot_maps(rpm, orders, order_rms, times, freqs, rpm_t, psd, title="", path=None,
              unit="m/s²", *, ax=None, provenance=None):
    """Campbell (rpm-order) and rpm-frequency colour maps side by side, levels in dB re the
    maximum on an 80 dB scale (colour-bar arrows where lower levels are clipped); returns
    the figure (``ax``: None, Figure or SubFigure)."""
    fig, axes, own = subplots(ax, 1, 2, figsize=(12, 5.0))
    a1, a2 = axes[0]
    ref = max(np.max(order_rms), 1e-30)
    db1 = 20 * np.log10(np.maximum(order_rms, ref * 1e-5) / ref)
    m1 = a1.pcolormesh(orders, rpm, db1, shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a1.set_xlabel("order", fontsize=LABEL_SIZE)
    a1.set_ylabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a1.set_title("rpm-order map (Campbell)", fontsize=TITLE_SIZE)
    colorbar(fig, m1, a1, db1, -80, 0, f"order RMS [dB re {ref:.3g} {unit}]")
    refp = max(np.max(psd), 1e-30)
    db2 = 10 * np.log10(np.maximum(psd, refp * 1e-8) / refp)
    m2 = a2.pcolormesh(freqs, rpm_t, db2, shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a2.set_xlabel("frequency [Hz]", fontsize=LABEL_SIZE)
    a2.set_ylabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a2.set_title("rpm-frequency map (waterfall)", fontsize=TITLE_SIZE)
    colorbar(fig, m2, a2, db2, -80, 0, "PSD [dB re max]")
    f_top = 1.25 * float(np.max(orders)) * float(np.max(rpm)) / 60.0   # highest order shown
    if 0 < f_top < float(np.max(freqs)):
        a2.set_xlim(float(np.min(freqs)), f_top)
    for a in (a1, a2):
        a.tick_params(labelsize=TICK_SIZE)
    return finish(fig, own, path, provenance, title=title if own else None)


def plot_sweep_rates(curves, path=None, title="", *, ax=None, provenance=None):
    """Order curves of several sweep rates over the stepped run-up; returns the figure.

    ``curves``: list of (label, rpm, level [m/s]) drawn in that order.
    """
    fig, axes, own = subplots(ax, figsize=(7.5, 4.6))
    a = axes[0, 0]
    for label, rpm, level in curves:
        a.plot(rpm, np.asarray(level) * 1e3, label=label,
               lw=2.2 if label.startswith("stepped") else 1.2,
               ls="--" if label.startswith("stepped") else "-")
    log_axis(a, "y")
    a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a.set_ylabel("RMS velocity [mm/s]", fontsize=LABEL_SIZE)
    a.grid(True, which="major", alpha=0.35)
    a.legend(fontsize=8)
    a.set_title(title, fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance)
