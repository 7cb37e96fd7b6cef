"""Diagnosis figures: gap map, gap against frequency and speed, before/after overlays."""

from __future__ import annotations

import numpy as np

from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, at_floor
from powertrain.errors import InputError
from powertrain.plotting.runup import style_panel
from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    OKABE_ITO,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colorbar,
    finish,
    is_axes,
    legend,
    log_axis,
    no_data,
    panels_error,
    quantity_label,
    series_style,
    subplots,
    whole_figure,
    wrap,
)

#: Colour scale of the gap map [dB]; cells beyond are clipped (the colour bar shows arrows).
GAP_SCALE_DB = 6.0
#: Gap outlined on the map [dB] ...
GAP_OUTLINE_DB = 3.0
#: ... where it holds over at least this many neighbouring speeds (a lone noisy cell is not
#: outlined).
GAP_OUTLINE_RUN = 3


def _censored(diagnosis):
    """Measured points at the noise floor (the one rule, :mod:`powertrain.analysis.noise_floor`)
    and the rule's margin."""
    d = diagnosis.data
    return np.isfinite(d.level) & at_floor(d.level, d.floor), NOISE_FLOOR_MARGIN


def plot_gap_map(diagnosis, path=None, *, ax=None, quantity=None, provenance=None):
    """Gap map of a :class:`powertrain.diagnosis.DiagnosisResult`: one panel per quantity
    with a point above the censoring limit (3 × noise floor; the other quantities are named
    in the title), channels against speed, colour = gap 20 log10(sim/measured) [dB] on a
    ±6 dB scale (arrows on the colour bar when cells lie beyond); outlined: runs of at least
    :data:`GAP_OUTLINE_RUN` neighbouring speeds beyond ±3 dB (single noisy cells are not);
    cells measured below the censoring limit grey.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
        PNG written atomically.
    ax : None, Axes, Figure or SubFigure
        An Axes takes one panel: the one quantity shown, or ``quantity``; else an
        InputError saying to pass a Figure.
    quantity : str, optional
        Only this quantity.
    provenance : Provenance, optional
    """
    d = diagnosis.data
    cens, margin = _censored(diagnosis)
    valid = np.isfinite(diagnosis.gap) & ~cens
    shown = [q for k, q in enumerate(d.quantities) if valid[:, :, k].any()]
    empty = [q for q in d.quantities if q not in shown]
    qs = shown or list(d.quantities)[:1]
    if quantity is not None:
        if quantity not in d.quantities:
            raise InputError(f"no quantity {quantity!r} (quantities: "
                             f"{', '.join(d.quantities)})", key="quantity")
        qs = [quantity]
    if is_axes(ax):
        if len(qs) != 1:
            raise InputError(panels_error(len(qs), ", or choose one with quantity="),
                             key="ax")
        fig, axes, own = subplots(ax)
    else:
        ncol = 1 if len(qs) == 1 else 2
        nrow = -(-len(qs) // ncol)
        fig, axes, own = subplots(ax, nrow, ncol, sharex=True, sharey=True,
                                  figsize=(PRINT_WIDTH_IN, 0.2 * _n_rows(valid) * nrow + 2.6))
    im = _gap_panels(axes, diagnosis, qs, cens, valid)
    for a in axes.flat[len(qs):]:
        a.set_visible(False)
    for a in axes[-1]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    if im is not None:
        colorbar(fig, im, axes.ravel().tolist(), diagnosis.gap[valid], -GAP_SCALE_DB,
                 GAP_SCALE_DB, f"gap 20 log10(sim/measured) [dB]; grey: below {margin:g}× "
                               "the noise floor")
    title = f"gap map (baseline): {diagnosis.verdict_text}"
    if empty:
        title += (f". Every measured point below {margin:g}× the noise floor, not drawn: "
                  + ", ".join(quantity_label(q) for q in empty))
    title += (f". Outlined: ≥ {GAP_OUTLINE_RUN} neighbouring speeds beyond "
              f"±{GAP_OUTLINE_DB:g} dB")
    return finish(fig, own, path, provenance, title=title if whole_figure(ax) else None)


def _gap_panels(axes, diagnosis, qs, cens, valid):
    """Draw the gap panels; returns the last colour mesh (None when nothing was drawn)."""
    from matplotlib.colors import ListedColormap  # deferred: heavy optional package
    d = diagnosis.data
    rows = np.flatnonzero(valid.any(axis=(0, 2))) if valid.any() else \
        np.arange(len(d.channels))                       # channels with a point to show
    y = np.arange(rows.size)
    im = None
    for a, q in zip(axes.flat, qs):
        k = d.quantities.index(q)
        g = diagnosis.gap[:, rows, k].T
        ok = valid[:, rows, k].T
        a.set_title(quantity_label(q), fontsize=TITLE_SIZE)
        a.set_yticks(y, [f"{d.channels[c][0]} {d.channels[c][1].upper()}" for c in rows])
        a.tick_params(labelsize=TICK_SIZE)
        if not ok.any():
            no_data(a, "every point below the censoring limit")
            continue
        grey = np.where(cens[:, rows, k].T, 0.0, np.nan)
        a.pcolormesh(d.rpm, y, np.ma.masked_invalid(grey), shading="nearest",
                     cmap=ListedColormap(["0.7"], name="censored grey"))
        im = a.pcolormesh(d.rpm, y, np.ma.masked_where(~ok, g), cmap="RdBu_r",
                          vmin=-GAP_SCALE_DB, vmax=GAP_SCALE_DB, shading="nearest")
        runs = _runs_beyond(np.where(ok, np.abs(g), 0.0) > GAP_OUTLINE_DB, GAP_OUTLINE_RUN)
        if runs.any():
            a.contour(d.rpm, y, runs.astype(float), [0.5], colors="k", linewidths=0.8)
    return im


def _n_rows(valid) -> int:
    """Channels drawn in the gap map: those with a point above the censoring limit."""
    return max(1, int(valid.any(axis=(0, 2)).sum()))


def _runs_beyond(mask, run):
    """Cells of ``mask`` (channels × speeds) in runs of at least ``run`` along speed."""
    out = np.zeros_like(mask)
    for c, row in enumerate(mask):
        edges = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(int), [0]])))
        for start, stop in zip(edges[::2], edges[1::2]):
            if stop - start >= run:
                out[c, start:stop] = True
    return out


def plot_gap_frequency(diagnosis, path=None, *, ax=None, provenance=None):
    """Order gaps re-plotted (a) against frequency f = order·rpm/60 [Hz], one colour per
    channel with that channel's fitted structure part dH(f) + constant (a structural cause
    lines up across orders at one frequency), and (b), averaged over the channels, against
    speed, one colour per order with that order's fitted excitation part (dashed; an
    excitation cause lines up at one order). Only orders with a gap above the noise floor
    are drawn and listed; each panel's legend sits above it, off the data.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
    ax : None, Figure or SubFigure
    provenance : Provenance, optional
    """
    d = diagnosis.data
    p = diagnosis.parts
    fig, axes, own = subplots(ax, 2, 1, figsize=(PRINT_WIDTH_IN, 8.4))
    a1, a2 = axes[:, 0]
    with_data = [k for k in np.flatnonzero(d.order_mask)
                 if np.isfinite(diagnosis.gap[:, :, k]).any()]
    _gap_by_channel(a1, diagnosis, with_data)
    _gap_by_order(a2, diagnosis, with_data)
    log_axis(a1, "x", max_ticks=9)
    a1.set_xlabel("frequency = order × rpm / 60 [Hz]", fontsize=LABEL_SIZE)
    a1.set_ylabel("gap per channel [dB]", fontsize=LABEL_SIZE)
    a2.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a2.set_ylabel("gap, mean over channels [dB]", fontsize=LABEL_SIZE)
    titles = ("(a) gap of every order per channel against frequency; line: the channel's "
              "fitted structure part dH(f) + constant",
              "(b) gap per order, mean over the channels, against speed; dashed: the "
              "order's fitted excitation part")
    for a, title in zip((a1, a2), titles):
        a.axhline(0, color="0.5", lw=0.5)
        a.grid(True, alpha=0.3)
        a.tick_params(which="both", labelsize=TICK_SIZE)
        _legend_above(a, title)
    s = p["share_alone"]
    title = (f"gap split: structure {s['structure']:.0%}, excitation {s['excitation']:.0%}, "
             f"channel constant {s['const']:.0%} of the gap's sum of squares (each alone)")
    return finish(fig, own, path, provenance, title=title if whole_figure(ax) else None)


def _gap_by_channel(ax, diagnosis, orders):
    d, p = diagnosis.data, diagnosis.parts
    sc = p["structure_curves"]
    for c, (mount, direction) in enumerate(d.channels):
        if not np.isfinite(diagnosis.gap[:, c, orders]).any():
            continue
        style = series_style(c)
        marker = "o^s"[(c // 6) % 3]
        for k in orders:
            f = (d.harmonic[k] + 1) / 2.0 * d.rpm / 60.0
            ax.plot(f, diagnosis.gap[:, c, k], marker, ms=1.6, color=style["color"],
                    alpha=0.6, ls="none")
        ax.plot(sc["frequency_hz"], np.array(sc["by_channel"][c]) + p["channel_const_db"][c],
                lw=1.2, marker=marker, ms=3, markevery=4,
                label=f"{mount} {direction.upper()}", **style)


def _gap_by_order(ax, diagnosis, orders):
    d, p = diagnosis.data, diagnosis.parts
    ec = p["excitation_curves"]
    for j, k in enumerate(orders):
        g = diagnosis.gap[:, :, k]
        n_ok = np.isfinite(g).sum(axis=1)
        mean = np.where(n_ok > 0, np.nansum(g, axis=1) / np.maximum(n_ok, 1), np.nan)
        style = series_style(j)
        ax.plot(d.rpm, mean, lw=1.0, color=style["color"], ls=style["ls"],
                label=quantity_label(d.quantities[k]))
        ax.plot(ec["rpm"], ec["by_quantity"][k], lw=2.0, ls=(0, (4, 2)), color=style["color"],
                alpha=0.7)


def _legend_above(ax, title):
    """The panel's legend above it (outside the data), carrying the panel title."""
    n = len(ax.get_legend_handles_labels()[1])
    leg = ax.legend(loc="lower left", bbox_to_anchor=(0, 1.01, 1, 0), mode="expand",
                    ncol=max(1, min(n, 5)), fontsize=LEGEND_SIZE, frameon=False,
                    title=wrap(title, PRINT_WIDTH_IN * 0.9, TITLE_SIZE),
                    title_fontsize=TITLE_SIZE, borderaxespad=0.2)
    leg.get_title().set_multialignment("left")
    leg._legend_box.align = "left"


def plot_diagnosis_overlay(diagnosis, path=None, n_panels=6, *, ax=None, provenance=None):
    """Measured vs baseline vs baseline + chosen effect for the channel-orders with the
    largest baseline gaps; held-out speeds circled.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
    n_panels : int
        Channel-orders shown (largest RMS gap first).
    ax : None, Figure or SubFigure
    provenance : Provenance, optional
    """
    d = diagnosis.data
    g = diagnosis.gap
    cens, _ = _censored(diagnosis)
    score = []
    for c in range(len(d.channels)):
        for k in np.flatnonzero(d.order_mask):
            v = np.where(cens[:, c, k], np.nan, g[:, c, k])
            if np.isfinite(v).sum() > 2:
                score.append((float(np.sqrt(np.nanmean(v ** 2))), c, k))
    score = sorted(score, reverse=True)[:n_panels]
    ncol = 2
    nrow = max(1, int(np.ceil(len(score) / ncol)))
    fig, axes, own = subplots(ax, nrow, ncol, figsize=(PRINT_WIDTH_IN, 2.3 * nrow + 2.0))
    held = np.isin(d.rpm, diagnosis.split["heldout_rpm"])
    for a, (rms, c, k) in zip(axes.flat, score):
        _overlay_panel(a, diagnosis, c, k, held, rms)
    if not score:
        no_data(axes.flat[0], "no channel-order above the noise floor")
    for a in axes.flat[max(1, len(score)):]:
        a.set_visible(False)
    for a in axes.flat[:len(score)]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    fig.supylabel("RMS velocity [mm/s]", fontsize=LABEL_SIZE + 0.5)
    legend(fig, axes, ax)
    return finish(fig, own, path, provenance, title=f"before / after / measured: "
                  f"{diagnosis.verdict_text}" if whole_figure(ax) else None)


def _overlay_panel(ax, diagnosis, c, k, held, rms):
    d = diagnosis.data
    g = diagnosis.gap
    m = d.level[:, c, k] * 1e3
    sim0 = m * 10 ** (g[:, c, k] / 20)
    ax.plot(d.rpm, m, "k.", ms=2.5, label="measured")
    ax.plot(d.rpm[held], m[held], "o", mfc="none", mec="0.6", ms=4, label="held-out speeds")
    ax.plot(d.rpm, sim0, "-", color=OKABE_ITO["vermillion"], lw=1,
            label="baseline simulation")
    # the axis spans the points above the noise floor: a censored point far below (a
    # level of 1e-300) would stretch it over hundreds of decades
    values = [np.where(_censored(diagnosis)[0][:, c, k], np.nan, m), sim0]
    if diagnosis.gap_after is not None and diagnosis.chosen is not None:
        after = m * 10 ** (diagnosis.gap_after[:, c, k] / 20)
        ax.plot(d.rpm, after, "-", color=OKABE_ITO["blue"], lw=1,
                label=f"baseline + {diagnosis.chosen.label}")
        values.append(after)
    mnt, dr = d.channels[c]
    style_panel(ax, f"{mnt} {dr.upper()} — {quantity_label(d.quantities[k])}: "
                    f"gap {rms:.1f} dB RMS", np.concatenate(values))
