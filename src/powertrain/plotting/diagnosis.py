"""Diagnosis figures: gap map, gap against frequency and speed, before/after overlays."""

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
    quantity_label,
    subplots,
)

#: Colour scale of the gap map [dB]; cells beyond are clipped (the colour bar shows arrows).
GAP_SCALE_DB = 6.0
#: Gap outlined on the map [dB].
GAP_OUTLINE_DB = 3.0


def _censored(diagnosis):
    """Measured points at the noise floor (the one rule, :mod:`powertrain.analysis.noise_floor`)
    and the rule's margin."""
    from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, at_floor
    d = diagnosis.data
    return np.isfinite(d.level) & at_floor(d.level, d.floor), NOISE_FLOOR_MARGIN


def plot_gap_map(diagnosis, path=None, *, ax=None, quantity=None, provenance=None):
    """Gap map of a :class:`powertrain.diagnosis.DiagnosisResult`: one panel per quantity,
    channels against speed, colour = gap 20 log10(sim/measured) [dB] on a ±6 dB scale
    (arrows on the colour bar when cells lie beyond), ±3 dB contours; cells measured below
    the censoring limit (3 × noise floor) grey; a quantity with no point above it is
    labelled instead of drawn.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
        PNG written atomically.
    ax : None, Axes, Figure or SubFigure
        An Axes gets the one panel ``quantity`` (default: the first).
    provenance : Provenance, optional
    """
    from matplotlib.colors import ListedColormap
    d = diagnosis.data
    cens, margin = _censored(diagnosis)
    qs = list(d.quantities)
    if ax is not None and not hasattr(ax, "subplots"):
        qs = [quantity or qs[0]]
        fig, axes, own = subplots(ax)
    else:
        ncol = {1: 1, 2: 2, 3: 3, 4: 2}.get(len(qs), 3)
        nrow = int(np.ceil(len(qs) / ncol))
        fig, axes, own = subplots(ax, nrow, ncol, figsize=(4.4 * ncol + 1.4, 2.7 * nrow + 1.3),
                                  sharex=True, sharey=True)
    y = np.arange(len(d.channels))
    im = None
    shown = []
    for a, q in zip(axes.flat, qs):
        k = d.quantities.index(q)
        g = diagnosis.gap[:, :, k].T
        valid = np.isfinite(g) & ~cens[:, :, k].T
        a.set_title(quantity_label(q), fontsize=TITLE_SIZE)
        a.set_yticks(y, [f"{m} {di.upper()}" for m, di in d.channels])
        a.tick_params(labelsize=TICK_SIZE)
        if not valid.any():
            no_data(a, f"every measured point below {margin:g}× the noise floor")
            continue
        grey = np.where(cens[:, :, k].T, 0.0, np.nan)
        a.pcolormesh(d.rpm, y, np.ma.masked_invalid(grey), cmap=ListedColormap(["0.7"]),
                     shading="nearest")
        im = a.pcolormesh(d.rpm, y, np.ma.masked_where(~valid, g), cmap="RdBu_r",
                          vmin=-GAP_SCALE_DB, vmax=GAP_SCALE_DB, shading="nearest")
        shown.append(np.where(valid, g, np.nan))
        if np.nanmax(np.abs(np.where(valid, g, np.nan))) > GAP_OUTLINE_DB:
            a.contour(d.rpm, y, np.where(valid, np.abs(g), 0.0), [GAP_OUTLINE_DB],
                      colors="k", linewidths=0.6)
    for a in axes.flat[len(qs):]:
        a.set_visible(False)
    for a in axes[-1]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    if im is not None:
        colorbar(fig, im, axes.ravel().tolist(), np.concatenate([s.ravel() for s in shown]),
                 -GAP_SCALE_DB, GAP_SCALE_DB,
                 f"gap 20 log10(sim/measured) [dB]; contour ±{GAP_OUTLINE_DB:g} dB; grey: "
                 f"below {margin:g}× noise floor")
    return finish(fig, own, path, provenance,
                  title=f"gap map (baseline): {diagnosis.verdict_text}" if own else None)


def plot_gap_frequency(diagnosis, path=None, *, ax=None, provenance=None):
    """Order gaps re-plotted against frequency f = order·rpm/60 [Hz] per channel (left; a
    structural cause lines up across orders at one frequency) and, averaged over the
    channels, against speed per order (right; an excitation cause lines up at one order),
    with the fitted smooth parts.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
    ax : None, Figure or SubFigure
    provenance : Provenance, optional
    """
    from matplotlib.lines import Line2D
    d = diagnosis.data
    p = diagnosis.parts
    fig, axes, own = subplots(ax, 1, 2, figsize=(12, 5.0))
    a1, a2 = axes[0]
    for j, k in enumerate(np.flatnonzero(d.order_mask)):
        colour = f"C{j % 10}"
        f = (d.harmonic[k] + 1) / 2.0 * d.rpm / 60.0
        g = diagnosis.gap[:, :, k]
        for c in range(len(d.channels)):
            a1.plot(f, g[:, c], ".", ms=1.8, color=colour,
                    label=quantity_label(d.quantities[k]) if c == 0 else None)
        n_ok = np.isfinite(g).sum(axis=1)
        mean = np.where(n_ok > 0, np.nansum(g, axis=1) / np.maximum(n_ok, 1), np.nan)
        a2.plot(d.rpm, mean, "-", color=colour, lw=1)
    sc = p["structure_curves"]
    for c, row in enumerate(sc["by_channel"]):
        a1.plot(sc["frequency_hz"], np.array(row) + p["channel_const_db"][c], "k-", lw=0.6,
                alpha=0.6)
    ec = p["excitation_curves"]
    for row in ec["by_quantity"]:
        a2.plot(ec["rpm"], row, "--", color="k", lw=0.6, alpha=0.6)
    log_axis(a1, "x", max_ticks=9)
    a1.set_xlabel("frequency = order × rpm / 60 [Hz]", fontsize=LABEL_SIZE)
    a1.set_ylabel("gap per channel [dB]", fontsize=LABEL_SIZE)
    a2.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a2.set_ylabel("gap, mean over channels [dB]", fontsize=LABEL_SIZE)
    for a in (a1, a2):
        a.axhline(0, color="0.5", lw=0.5)
        a.grid(True, alpha=0.3)
        a.tick_params(which="both", labelsize=TICK_SIZE)
    if own:
        figure_legend(fig, axes, [
            (Line2D([], [], color="k", lw=0.6), "fitted structure part dH(f) + channel constant"),
            (Line2D([], [], color="k", ls="--", lw=0.6), "fitted excitation part (per order)")])
    s = p["share_alone"]
    title = (f"gap split: structure {s['structure']:.0%}, excitation {s['excitation']:.0%}, "
             f"channel constant {s['const']:.0%} of the gap's sum of squares (each alone)")
    return finish(fig, own, path, provenance, title=title if own else None)


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
    ncol = 3
    nrow = max(1, int(np.ceil(len(score) / ncol)))
    fig, axes, own = subplots(ax, nrow, ncol, figsize=(12.5, 3.2 * nrow + 1.4))
    held = np.isin(d.rpm, diagnosis.split["heldout_rpm"])
    for a, (rms, c, k) in zip(axes.flat, score):
        _overlay_panel(a, diagnosis, c, k, held, rms)
    if not score:
        no_data(axes.flat[0], "no channel-order above the noise floor")
    for a in axes.flat[max(1, len(score)):]:
        a.set_visible(False)
    for a in axes.flat[:len(score)]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    fig.supylabel("RMS velocity [mm/s]", fontsize=LABEL_SIZE + 1)
    if own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance,
                  title=f"before / after / measured: {diagnosis.verdict_text}" if own else None)


def _overlay_panel(ax, diagnosis, c, k, held, rms):
    from powertrain.plotting.runup import style_panel
    d = diagnosis.data
    g = diagnosis.gap
    m = d.level[:, c, k] * 1e3
    sim0 = m * 10 ** (g[:, c, k] / 20)
    ax.plot(d.rpm, m, "k.", ms=2.5, label="measured")
    ax.plot(d.rpm[held], m[held], "o", mfc="none", mec="0.6", ms=4, label="held-out speeds")
    ax.plot(d.rpm, sim0, "C3-", lw=1, label="baseline simulation")
    values = [m, sim0]
    if diagnosis.gap_after is not None and diagnosis.chosen is not None:
        after = m * 10 ** (diagnosis.gap_after[:, c, k] / 20)
        ax.plot(d.rpm, after, "C0-", lw=1, label=f"baseline + {diagnosis.chosen.label}")
        values.append(after)
    mnt, dr = d.channels[c]
    style_panel(ax, f"{mnt} {dr.upper()} — {quantity_label(d.quantities[k])}: "
                    f"gap {rms:.1f} dB RMS", np.concatenate(values))
