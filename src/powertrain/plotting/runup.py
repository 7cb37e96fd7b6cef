"""Run-up figures: order curves against speed, one panel per channel (mount × direction) and
quantity (synthesis, orders) — the thesis's layout (Kovarik 2016, Figs 45–71) — for a run-up,
a comparison with a measurement and a what-if study."""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import (
    LABEL_SIZE,
    SIGNAL_UNITS,
    TICK_SIZE,
    TITLE_SIZE,
    figure_legend,
    finish,
    is_axes,
    log_axis,
    no_data,
    quantity_label,
    subplots,
)

RPM_LABEL = "engine speed [rpm]"


def grid(ax, rows, quantities, channel=None, quantity=None, panel_height=1.9):
    """Panels of a channel × quantity figure.

    ``ax`` None, Figure or SubFigure: the full grid; an Axes: the one panel ``channel``
    (default: the first) and ``quantity`` (default: the first).

    Returns
    -------
    fig, panels : dict {(mount, direction, quantity): Axes}, own : bool, axes : 2-D array
    """
    if is_axes(ax):
        ch = tuple(channel) if channel is not None else rows[0]
        q = quantity or quantities[0]
        return ax.figure, {(*ch, q): ax}, False, np.array([[ax]])
    nr, nq = len(rows), len(quantities)
    fig, axes, own = subplots(ax, nr, nq, figsize=(3.9 * nq + 0.5, panel_height * nr + 1.3),
                              sharex=True)
    panels = {(*rows[r], quantities[q]): axes[r, q] for r in range(nr) for q in range(nq)}
    return fig, panels, own, axes


def label_grid(fig, axes, ylabel):
    """Shared axis labels: one x label under the grid and one y label beside it, or the
    labels of a single axes."""
    if axes.size == 1:
        axes.flat[0].set_xlabel(RPM_LABEL, fontsize=LABEL_SIZE)
        axes.flat[0].set_ylabel(ylabel, fontsize=LABEL_SIZE)
        return
    for ax in axes[-1]:
        ax.set_xlabel(RPM_LABEL, fontsize=LABEL_SIZE)
    fig.supylabel(ylabel, fontsize=LABEL_SIZE + 1)


def style_panel(ax, title, values):
    """Title, log y axis with plain-number ticks and limits spanning at least a factor 4."""
    ax.set_title(title, fontsize=TITLE_SIZE)
    ax.grid(True, which="major", alpha=0.35)
    ax.tick_params(which="both", labelsize=TICK_SIZE)
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values) & (values > 0)]
    if values.size == 0:
        return False
    lo, hi = values.min() / 1.4, values.max() * 1.4
    if hi / lo < 4:
        mid = np.sqrt(lo * hi)
        lo, hi = mid / 2, mid * 2
    log_axis(ax, "y", max_ticks=5, minor=False)
    ax.set_ylim(lo, hi)
    return True


def _positive(rpm, values):
    values = np.asarray(values, dtype=float)
    ok = np.isfinite(values) & (values > 0)
    return np.asarray(rpm)[ok], values[ok]


# --------------------------------------------------------------------------- run-up
def plot_runup(results, path=None, quantities=("synthesis", "order_2", "order_4"),
               signal="velocity", *, ax=None, channel=None, quantity=None, provenance=None):
    """RMS curves of one or more run-ups: rows = mount × direction, columns = ``quantities``.

    Parameters
    ----------
    results : list of (label, RunupResult)
    path : str or Path, optional
        PNG written atomically.
    quantities : sequence of str
        ``synthesis`` and/or ``order_<n>``; every one is drawn.
    signal : {"velocity", "displacement", "acceleration", "mount_force"}
    ax : None, Axes, Figure or SubFigure
        Where to draw (see :func:`grid`); an Axes gets the one panel ``channel``/``quantity``.
    provenance : Provenance, optional
        Foot line of a new figure.

    Returns
    -------
    matplotlib Figure (or SubFigure)
    """
    first = results[0][1]
    rows = list(first.channels)
    fig, panels, own, axes = grid(ax, rows, list(quantities), channel, quantity)
    scale, unit = SIGNAL_UNITS[signal]
    for (mount, direction, q), a in panels.items():
        values = []
        for label, res in results:
            if (mount, direction) not in res.channels:
                continue
            r, v = _positive(res.rpm, res.curve(mount, direction, q, signal) * scale)
            a.plot(r, v, "o-", ms=2.5, lw=1.2, label=label)
            values.append(v)
        title = f"{mount} {direction.upper()} — {quantity_label(q)}"
        if not style_panel(a, title, np.concatenate(values) if values else []):
            no_data(a, "zero at every speed (not excited)")
    label_grid(fig, axes, f"RMS {signal.replace('_', ' ')} [{unit}]")
    if len(results) > 1 and own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance,
                  title=f"run-up: RMS {signal.replace('_', ' ')} at the mounts" if own else None)


# --------------------------------------------------------------------------- what-if
def plot_whatif(whatif, path=None, *, ax=None, channel=None, quantity=None, provenance=None):
    """Baseline, variants and measurement overlaid: RMS velocity [mm/s] (or the signal of
    ``whatif.signal``) against speed.

    One row per mount and direction, one column per quantity of ``whatif.quantities``; the
    baseline black, each variant in colour, the measurement (when given) as grey dots. One
    legend for the figure: each variant with its mean change over all channels, quantities
    and speeds; each panel title lists the variants' mean change in that panel (dB, in
    legend order) when there are at most six variants.

    Parameters
    ----------
    whatif : powertrain.whatif.WhatIfResult
    path : str, optional
        PNG written atomically.
    ax, channel, quantity, provenance
        As for :func:`plot_runup`.
    """
    base = whatif.baseline
    signal = getattr(whatif, "signal", "velocity")
    scale, unit = SIGNAL_UNITS[signal]
    quantities = list(whatif.quantities)
    fig, panels, own, axes = grid(ax, list(base.channels), quantities, channel, quantity,
                                  panel_height=2.0)
    overall = {v.name: _mean_change(whatif, v.name, base.channels, quantities)
               for v in whatif.variants}
    for (mount, direction, q), a in panels.items():
        values = []
        if whatif.measured is not None and signal == "velocity":
            key = (mount, direction, q)
            if key in whatif.measured.curves:
                r, v = _positive(*whatif.measured.curves[key])
                a.plot(r, v * 1e3, ".", color="0.55", ms=2.5, label="measured")
                values.append(v * 1e3)
        r, v = _positive(base.rpm, base.curve(mount, direction, q, signal) * scale)
        a.plot(r, v, "k-", lw=1.6, label="baseline")
        values.append(v)
        means = []
        for k, var in enumerate(whatif.variants):
            r, v = _positive(var.result.rpm,
                             var.result.curve(mount, direction, q, signal) * scale)
            a.plot(r, v, "o-", ms=2, lw=1.0, color=f"C{k % 10}",
                   label=f"{var.name} (mean {overall[var.name]:+.2f} dB)")
            values.append(v)
            means.append(_mean_change(whatif, var.name, [(mount, direction)], [q]))
        title = f"{mount} {direction.upper()} — {quantity_label(q)}"
        if 0 < len(means) <= 6:
            title += "\nmean Δ [dB]: " + "  ".join(f"{m:+.2f}" for m in means)
        if not style_panel(a, title, np.concatenate(values)):
            no_data(a, "zero at every speed (not excited)")
    label_grid(fig, axes, f"RMS {signal.replace('_', ' ')} [{unit}]")
    if own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance,
                  title=("what-if: baseline vs variants; mean Δ = mean change 20 log10(v/v0) "
                         "over the speed steps [dB], in the panel titles per variant in "
                         "legend order") if own else None)


def _mean_change(whatif, name, channels, quantities) -> float:
    """Mean change [dB] of variant ``name`` over the given channels, quantities and speeds."""
    d = [whatif.delta_db(name, m, di, q) for m, di in channels for q in quantities]
    d = np.concatenate([np.atleast_1d(x) for x in d]) if d else np.array([])
    d = d[np.isfinite(d)]
    return float(d.mean()) if d.size else float("nan")
