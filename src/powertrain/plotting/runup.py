"""Run-up figures: order curves against speed, a panel per channel and quantity (Kovarik
2016, Figs 45–71), for a run-up and a what-if study; the grid shared with the comparison."""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.plotting.pages import draw_pages, page_rows
from powertrain.plotting.style import (
    LABEL_SIZE,
    PRINT_WIDTH_IN,
    SIGNAL_UNITS,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    finish,
    is_axes,
    legend,
    log_axis,
    no_data,
    panels_error,
    quantity_label,
    signed,
    subplots,
    wrap,
)

RPM_LABEL = "engine speed [rpm]"
#: Said once in a figure's title instead of in every panel.
SYNTHESIS_NOTE = " (synthesis = RMS sum of the orders ≤ 8)"
#: Height of a grid figure outside its panel rows [in]: title, legend, x labels, foot line.
GRID_FRAME_IN = 1.6


def grid(ax, rows, quantities, channel=None, quantity=None, panel_height=None, frame_in=GRID_FRAME_IN):
    """Panels of a channel × quantity figure: ``rows`` × ``quantities``, or only the row
    ``channel`` and column ``quantity`` where given; an Axes ``ax`` takes one panel.

    ``panel_height`` [in]: of a row, default as tall as fit one page with ``frame_in`` [in]
    for title, legend, x labels and foot line.

    Returns
    -------
    fig, panels : dict {(mount, direction, quantity): Axes}, own : bool, axes : 2-D array
    """
    rows, quantities = select_panels(rows, quantities, channel, quantity)
    if is_axes(ax):
        if len(rows) * len(quantities) != 1:
            raise InputError(panels_error(len(rows) * len(quantities), ", or choose one "
                                          "panel with channel=(MOUNT, DIR) and quantity="), key="ax")
        return ax.figure, {(*rows[0], quantities[0]): ax}, False, np.array([[ax]])
    nr, nq = len(rows), len(quantities)
    if panel_height is None:
        panel_height = page_rows(rows, frame_in)[1]
    fig, axes, own = subplots(ax, nr, nq, figsize=(PRINT_WIDTH_IN, panel_height * nr + frame_in), sharex=True)
    panels = {(*rows[r], quantities[q]): axes[r, q] for r in range(nr) for q in range(nq)}
    return fig, panels, own, axes


def select_panels(rows, quantities, channel=None, quantity=None):
    """``rows`` and ``quantities`` narrowed to ``channel`` and ``quantity`` where given."""
    rows = [tuple(r) for r in rows]
    if channel is not None:
        if tuple(channel) not in rows:
            raise InputError(f"no channel {tuple(channel)!r} (channels: "
                             f"{', '.join(f'{m}.{d}' for m, d in rows)})", key="channel")
        rows = [tuple(channel)]
    if quantity is not None:
        if quantity not in quantities:
            raise InputError(f"no quantity {quantity!r} (quantities: "
                             f"{', '.join(quantities)})", key="quantity")
        quantities = [quantity]
    return rows, list(quantities)


def panel_title(mount, direction, quantity) -> str:
    """Short panel title of a grid: ``left Z · order 2``."""
    return f"{mount} {direction.upper()} · {quantity_label(quantity)}"


#: Most columns that each get their own x label (more: one under the middle column).
MAX_LABELLED_COLUMNS = 4


def label_grid(fig, axes, ylabel):
    """An x label under each column of ``axes`` (the middle one beyond
    :data:`MAX_LABELLED_COLUMNS`) and one ``ylabel`` beside them."""
    if axes.size == 1:
        axes.flat[0].set_xlabel(RPM_LABEL, fontsize=LABEL_SIZE)
        axes.flat[0].set_ylabel(ylabel, fontsize=LABEL_SIZE)
        return
    columns = axes[-1] if axes.shape[1] <= MAX_LABELLED_COLUMNS else [axes[-1, axes.shape[1] // 2]]
    for ax in columns:
        ax.set_xlabel(RPM_LABEL, fontsize=LABEL_SIZE)
    fig.supylabel(ylabel, fontsize=LABEL_SIZE + 0.5)


def style_panel(ax, title, values, dynamic_range_db=None, max_ticks=4):
    """``title`` and a log y axis for ``values`` (at most ``max_ticks`` ticks, a factor 4 at
    least, at most ``dynamic_range_db`` below the largest); False with nothing to show."""
    ax.set_title(title, fontsize=TITLE_SIZE)
    ax.grid(True, which="major", alpha=0.35)
    ax.tick_params(which="both", labelsize=TICK_SIZE)
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values) & (values > 0)]
    if values.size == 0:
        return False
    lo, hi = values.min() / 1.4, values.max() * 1.4
    if dynamic_range_db is not None:
        lo = max(lo, values.max() * 10 ** (-dynamic_range_db / 20))
    if hi / lo < 4:
        mid = np.sqrt(lo * hi)
        lo, hi = mid / 2, mid * 2
    log_axis(ax, "y", max_ticks=max_ticks, minor=False)
    ax.set_ylim(lo, hi)
    return True


def _positive(rpm, values):
    values = np.asarray(values, dtype=float)
    ok = np.isfinite(values) & (values > 0)
    return np.asarray(rpm)[ok], values[ok]


def plot_runup(results, path=None, quantities=("synthesis", "order_2", "order_4"),
               signal="velocity", *, ax=None, channel=None, quantity=None, provenance=None):
    """RMS curves of one or more run-ups: rows = mount × direction, columns = ``quantities``.

    Rows that do not fit one A4 page are written as pages ``path``, ``NAME_p2.png`` ….

    Parameters
    ----------
    results : list of (label, RunupResult)
    path : str or Path, optional
        PNG written atomically (the first page).
    quantities : sequence of str
        ``synthesis`` and/or ``order_<n>``.
    signal : {"velocity", "displacement", "acceleration", "mount_force"}
    ax : None, Axes, Figure or SubFigure
        Where to draw (:func:`grid`).
    channel, quantity : optional
        Only this channel ((mount, direction)) and quantity.
    provenance : Provenance, optional
        Foot line of a new figure.

    Returns
    -------
    matplotlib Figure (or SubFigure)
        The first page; its ``pages`` attribute lists the files written.
    """
    rows, picked = select_panels(results[0][1].channels, list(quantities), channel, quantity)
    if is_axes(ax):
        return _runup_page(results, rows, picked, signal, ax, provenance, path, "")
    return draw_pages(rows, GRID_FRAME_IN, ax, path, lambda chunk, _, file, note: _runup_page(
        results, chunk, picked, signal, ax, provenance, file, note))


def _runup_page(results, rows, quantities, signal, ax, provenance, path, note):
    """One page of :func:`plot_runup`: the grid of ``rows`` × ``quantities``."""
    fig, panels, own, axes = grid(ax, rows, quantities)
    scale, unit = SIGNAL_UNITS[signal]
    for (mount, direction, q), a in panels.items():
        values = []
        for label, res in results:
            if (mount, direction) not in res.channels:
                continue
            r, v = _positive(res.rpm, res.curve(mount, direction, q, signal) * scale)
            a.plot(r, v, "o-", ms=2, lw=1.1, label=label)
            values.append(v)
        title = panel_title(mount, direction, q)
        if not style_panel(a, title, np.concatenate(values) if values else []):
            no_data(a, "zero at every speed (not excited)")
    label_grid(fig, axes, f"RMS {signal.replace('_', ' ')} [{unit}]")
    if len(results) > 1:
        legend(fig, axes, ax)
    return finish(fig, own, path, provenance,
                  title=f"run-up: RMS {signal.replace('_', ' ')} at the mounts{SYNTHESIS_NOTE}"
                  f"{note}" if not is_axes(ax) else None)


def plot_whatif(whatif, path=None, *, ax=None, channel=None, quantity=None, provenance=None, view="levels"):
    """A what-if study against speed: levels, or each variant's change Δ = 20 log10(v/v0) [dB].

    Paged as :func:`plot_runup`; the legend gives each variant's mean change
    (``docs/reference/figures.md``).

    Parameters
    ----------
    whatif : powertrain.workflows.whatif.WhatIfResult
    path : str, optional
        PNG written atomically (the first page).
    ax, channel, quantity, provenance
        As for :func:`plot_runup`.
    view : {"levels", "delta"}

    Returns
    -------
    matplotlib Figure (or SubFigure)
        The first page; its ``pages`` attribute lists the files written.
    """
    if view not in ("levels", "delta"):
        raise InputError(f"{view!r} is not one of 'levels', 'delta'", key="view")
    base = whatif.baseline
    rows, picked = select_panels(base.channels, list(whatif.quantities), channel, quantity)
    signal = getattr(whatif, "signal", "velocity")
    title = _whatif_title(view, signal)
    entries = len(whatif.variants) + 1 + (whatif.measured is not None and view == "levels")
    frame = GRID_FRAME_IN + 0.16 * (wrap(title, PRINT_WIDTH_IN * 0.95, 9).count("\n") + 1 + entries)
    overall = {v.name: _mean_change(whatif, v.name, base.channels, list(whatif.quantities))
               for v in whatif.variants}

    def page(chunk, height, file, note):
        fig, panels, own, axes = grid(ax, chunk, picked, panel_height=height, frame_in=frame)
        for key, a in panels.items():
            (_delta_panel if view == "delta" else _levels_panel)(a, whatif, key, overall)
        if view == "delta":
            _share_delta_axis(panels.values())
        label_grid(fig, axes, "Δ = 20 log10(v/v0) [dB]" if view == "delta" else
                   f"RMS {signal.replace('_', ' ')} [{SIGNAL_UNITS[signal][1]}]")
        legend(fig, axes, ax)
        return finish(fig, own, file, provenance, title=title + note if not is_axes(ax) else None)
    return draw_pages(rows, frame, ax, path, page)


def _levels_panel(a, whatif, key, overall):
    mount, direction, q = key
    base, signal = whatif.baseline, getattr(whatif, "signal", "velocity")
    scale = SIGNAL_UNITS[signal][0]
    values = []
    if whatif.measured is not None and signal == "velocity" and key in whatif.measured.curves:
        r, v = _positive(*whatif.measured.curves[key])
        a.plot(r, v * 1e3, ".", color="0.55", ms=2.5, label="measured")
        values.append(v * 1e3)
    r, v = _positive(base.rpm, base.curve(mount, direction, q, signal) * scale)
    a.plot(r, v, "k-", lw=1.6, label="baseline")
    values.append(v)
    for k, var in enumerate(whatif.variants):
        r, v = _positive(var.result.rpm, var.result.curve(mount, direction, q, signal) * scale)
        a.plot(r, v, "o-", ms=2, lw=1.0, color=colour(k),
               label=f"{var.name} (mean {signed(overall[var.name], 2)} dB)")
        values.append(v)
    if not style_panel(a, panel_title(mount, direction, q), np.concatenate(values)):
        no_data(a, "zero at every speed (not excited)")


def _delta_panel(a, whatif, key, overall):
    mount, direction, q = key
    a.axhline(0.0, color="k", lw=1.0, label="baseline (0 dB)")
    for k, var in enumerate(whatif.variants):
        d = whatif.delta_db(var.name, mount, direction, q)
        a.plot(var.result.rpm, d, "-", lw=1.1, color=colour(k),
               label=f"{var.name} (mean {signed(overall[var.name], 2)} dB)")
    a.set_title(panel_title(mount, direction, q), fontsize=TITLE_SIZE)
    a.grid(True, alpha=0.35)
    a.tick_params(labelsize=TICK_SIZE)


def _share_delta_axis(axes):
    """One symmetric Δ range for every panel, at least ±1 dB."""
    top = 1.0
    for a in axes:
        for line in a.get_lines():
            y = np.asarray(line.get_ydata(), float)
            if np.isfinite(y).any():
                top = max(top, float(np.nanmax(np.abs(y))) * 1.1)
    for a in axes:
        a.set_ylim(-top, top)


def _whatif_title(view, signal) -> str:
    if view == "delta":
        return ("what-if: change of each variant against the baseline, "
                f"Δ = 20 log10(v/v0) of the RMS {signal.replace('_', ' ')} [dB]"
                + SYNTHESIS_NOTE)
    return f"what-if: baseline vs variants, RMS {signal.replace('_', ' ')}{SYNTHESIS_NOTE}"


def _mean_change(whatif, name, channels, quantities) -> float:
    """Mean change [dB] of variant ``name`` over ``channels``, ``quantities`` and speeds."""
    d = [whatif.delta_db(name, m, di, q) for m, di in channels for q in quantities]
    d = np.concatenate([np.atleast_1d(x) for x in d]) if d else np.array([])
    d = d[np.isfinite(d)]
    return float(d.mean()) if d.size else float("nan")
