"""The figure of a transient manoeuvre: crank speed and torque over time above the chosen
channels' accelerations, each channel's peak marked."""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.plotting.style import (
    LABEL_SIZE,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    finish,
    legend,
    subplots,
)

#: Quantities a channel panel shows: attribute, scale to the unit shown, unit.
QUANTITIES = {"acceleration": ("acceleration", 1.0, "m/s²"),
              "displacement": ("displacement", 1e3, "mm"),
              "force": ("force", 1.0, "N")}


def plot_transient(result, channels, path=None, ax=None, provenance=None,
                   quantity="acceleration"):
    """Speed [rpm] and the torques [N·m] in the top panel, below it one panel per channel of
    ``channels`` (labels ``mount.direction``) with its ``quantity`` (:data:`QUANTITIES`) and
    the largest magnitude marked; returns the figure (``ax``: None, a Figure or SubFigure;
    one Axes asks for a Figure)."""
    if quantity not in QUANTITIES:
        raise InputError(f"unknown quantity {quantity!r} (one of: {', '.join(QUANTITIES)})",
                         key="--quantity")
    attr, scale, unit = QUANTITIES[quantity]
    missing = [c for c in channels if c not in result.channels]
    if missing:
        raise InputError(f"unknown channel {missing[0]!r} (one of: "
                         f"{', '.join(result.channels)})", key="channels")
    n = 1 + len(channels)
    fig, axes, own = subplots(ax, n, 1, figsize=(PRINT_WIDTH_IN, 1.6 + 1.5 * n), sharex=True)
    top = axes[0, 0]
    t = result.time
    top.plot(t, result.rpm, color=colour(0), label="speed [rpm]")
    top.set_ylabel("speed [rpm]", fontsize=LABEL_SIZE)
    twin = top.twinx()
    for k, (name, values) in enumerate(result.torques.items()):
        if np.any(values):
            twin.plot(t, values, color=colour(k + 1), lw=0.8, ls=("-", "--", ":")[k % 3],
                      label=f"{name} torque")
    twin.set_ylabel("torque [N·m]", fontsize=LABEL_SIZE)
    twin.tick_params(labelsize=TICK_SIZE)
    for row, c in enumerate(channels, start=1):
        a = axes[row, 0]
        y = getattr(result, attr)[:, result.channel(c)] * scale
        i = int(np.argmax(np.abs(y)))
        a.plot(t, y, color=colour(row + 3), lw=0.7, label=c)
        a.plot(t[i], y[i], "v" if y[i] < 0 else "^", color="k", ms=5)
        a.annotate(f"{y[i]:.3g} {unit} at {t[i]:.3f} s", (t[i], y[i]), fontsize=TICK_SIZE,
                   xytext=(4, 0), textcoords="offset points", va="center")
        a.set_ylabel(f"{c}\n[{unit}]", fontsize=LABEL_SIZE)
    for a in axes[:, 0]:
        a.tick_params(labelsize=TICK_SIZE)
        a.grid(True, lw=0.3)
    axes[-1, 0].set_xlabel("time [s]", fontsize=LABEL_SIZE)
    handles, labels = twin.get_legend_handles_labels()
    legend(fig, axes, ax, extra=list(zip(handles, labels)))
    if not own:
        top.set_title(result.name, fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance,
                  title=f"{result.name} — {result.engine}" if own else None)


def plot_ranking(ranking, path=None, ax=None, provenance=None):
    """Bars per run: the peak seat acceleration [m/s²] (with a seat) and the peak mount
    deflection [mm]; returns the figure."""
    seat = ranking.peak_seat()
    defl = ranking.peak_deflection()[0] * 1e3
    panels = [(defl, "peak mount deflection [mm]")]
    if seat is not None:
        panels.insert(0, (seat, "peak seat acceleration [m/s²]"))
    fig, axes, own = subplots(ax, len(panels), 1, figsize=(PRINT_WIDTH_IN, 1.2 + 1.8 * len(panels)))
    x = np.arange(len(ranking.names))
    for a, (values, label) in zip(axes[:, 0], panels):
        a.bar(x, values, color=[colour(k) for k in x])
        a.set_ylabel(label, fontsize=LABEL_SIZE)
        a.set_xticks(x)
        a.set_xticklabels(ranking.names, fontsize=TICK_SIZE, rotation=15)
        a.tick_params(labelsize=TICK_SIZE)
    return finish(fig, own, path, provenance, title=f"what-if over {ranking.manoeuvre}")


def plot_overlay(comparison, path=None, ax=None, provenance=None):
    """Measured and simulated acceleration [m/s²] over time, one panel per channel;
    returns the figure."""
    n = len(comparison.channels)
    fig, axes, own = subplots(ax, n, 1, figsize=(PRINT_WIDTH_IN, 1.2 + 1.4 * n), sharex=True)
    t = comparison.time
    for j, (a, c) in enumerate(zip(axes[:, 0], comparison.channels)):
        a.plot(t, comparison.measured[:, j], color=colour(0), lw=0.7,
               label="measured" if j == 0 else None)
        a.plot(t, comparison.simulated[:, j], color=colour(1), lw=0.7, ls="--",
               label="simulated" if j == 0 else None)
        a.set_ylabel(f"{c}\n[m/s²]", fontsize=LABEL_SIZE)
        a.tick_params(labelsize=TICK_SIZE)
        a.grid(True, lw=0.3)
    axes[-1, 0].set_xlabel("time [s] (simulation)", fontsize=LABEL_SIZE)
    legend(fig, axes, ax)
    return finish(fig, own, path, provenance,
                  title=f"{comparison.name} — simulated vs {comparison.raw}")
