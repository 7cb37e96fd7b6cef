"""Plots of order-tracked run-ups: order curves, Campbell (rpm-order) and rpm-frequency
maps, slow vs fast sweep. matplotlib comes through :mod:`powertrain.plotting`."""

from __future__ import annotations

import numpy as np

from powertrain.plotting import _pyplot, save_figure

#: Display unit and factor per quantity.
DISPLAY = {"acceleration": ("m/s²", 1.0), "velocity": ("mm/s", 1e3),
           "displacement": ("mm", 1e3), "force": ("N", 1.0)}


def plot_tracked(tracked, path=None, quantities=None):
    """Order RMS against rpm, one panel per channel (synthesis and the orders asked)."""
    plt = _pyplot()
    from powertrain.analysis.orders import order_label
    quantities = list(quantities or ["synthesis"] + [order_label(o) for o in tracked.orders
                                                     if o in (1.0, 2.0, 4.0)]
                      or [order_label(tracked.orders[0])])
    n = len(tracked.channels)
    cols = min(3, n)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 2.8 * rows), squeeze=False,
                             sharex=True)
    for c, ch in enumerate(tracked.channels):
        ax = axes[c // cols][c % cols]
        unit, f = DISPLAY[ch.quantity]
        label = ch.mount + ("" if ch.side == "active" else f".{ch.side}") + f".{ch.direction}"
        for q in quantities:
            ax.semilogy(tracked.rpm, np.maximum(tracked.curve(label, q) * f, 1e-12), label=q)
        ax.set_title(f"{label} ({ch.quantity})", fontsize=9)
        ax.set_ylabel(f"RMS [{unit}]")
        ax.grid(True, which="both", alpha=0.3)
    for c in range(n, rows * cols):
        axes[c // cols][c % cols].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("speed [rpm]")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f"order tracking ({tracked.method}) of {tracked.source}", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path) if path else fig


def plot_maps(rpm, orders, order_rms, times, freqs, rpm_t, psd, title="", path=None,
              unit="m/s²"):
    """Campbell (rpm-order) and rpm-frequency colour maps side by side, levels in dB."""
    plt = _pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.5))
    ref = max(np.max(order_rms), 1e-30)
    m1 = a1.pcolormesh(orders, rpm, 20 * np.log10(np.maximum(order_rms, ref * 1e-5) / ref),
                       shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a1.set_xlabel("order")
    a1.set_ylabel("speed [rpm]")
    a1.set_title("rpm-order map (Campbell)", fontsize=10)
    fig.colorbar(m1, ax=a1, label=f"order RMS [dB re {ref:.3g} {unit}]")
    refp = max(np.max(psd), 1e-30)
    m2 = a2.pcolormesh(freqs, rpm_t, 10 * np.log10(np.maximum(psd, refp * 1e-8) / refp),
                       shading="nearest", cmap="viridis", vmin=-80, vmax=0)
    a2.set_xlabel("frequency [Hz]")
    a2.set_ylabel("speed [rpm]")
    a2.set_title("rpm-frequency map (waterfall)", fontsize=10)
    fig.colorbar(m2, ax=a2, label="PSD [dB re max]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path) if path else fig


def plot_sweep_rates(curves, path=None, title=""):
    """Order curves of several sweep rates over the stepped run-up.

    ``curves``: list of (label, rpm, level [m/s]) drawn in that order.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for label, rpm, level in curves:
        ax.semilogy(rpm, np.asarray(level) * 1e3, label=label,
                    lw=2.2 if label.startswith("stepped") else 1.2,
                    ls="--" if label.startswith("stepped") else "-")
    ax.set_xlabel("speed [rpm]")
    ax.set_ylabel("RMS velocity [mm/s]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path) if path else fig
