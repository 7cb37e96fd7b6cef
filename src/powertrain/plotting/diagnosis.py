"""Diagnosis figures: gap map, gap against frequency and speed, before/after overlays."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.analysis.channel import split_side
from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, at_floor
from powertrain.errors import InputError
from powertrain.plotting.runup import style_panel
from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    OKABE_ITO,
    PALETTE,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colorbar,
    figure_legend,
    finish,
    is_axes,
    legend,
    log_axis,
    no_data,
    panels_error,
    quantity_label,
    series_style,
    subplots,
    wrap,
)

#: Smallest colour scale of the gap map [dB], and the scales the largest gap is rounded up to.
GAP_SCALE_DB = 6.0
GAP_SCALES_DB = (3.0, 6.0, 10.0, 20.0, 30.0, 40.0, 60.0, 80.0, 100.0)
#: Channels beyond which the gap against frequency is small multiples (base and direction).
MAX_CHANNELS_ONE_AXIS = 8
#: Gap outlined on the map [dB] where it holds over at least this many neighbouring speeds.
GAP_OUTLINE_DB = 3.0
GAP_OUTLINE_RUN = 3


def _censored(diagnosis):
    """Measured points at the noise floor."""
    d = diagnosis.data
    return np.isfinite(d.level) & at_floor(d.level, d.floor)


def plot_gap_map(diagnosis, path=None, *, ax=None, quantity=None, provenance=None):
    """Gap map: per quantity, channels against speed coloured by the gap [dB].

    Runs of :data:`GAP_OUTLINE_RUN` speeds beyond ±3 dB outlined, censored cells grey
    (``docs/reference/figures.md``, ``gap_map.png``).

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
        PNG written atomically.
    ax : None, Axes, Figure or SubFigure
        An Axes takes one panel (one quantity, or ``quantity``).
    quantity : str, optional
        Only this quantity.
    provenance : Provenance, optional
    """
    d = diagnosis.data
    cens, margin = _censored(diagnosis), NOISE_FLOOR_MARGIN
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
            raise InputError(panels_error(len(qs), ", or choose one with quantity="), key="ax")
        fig, axes, own = subplots(ax)
    else:
        ncol = 1 if len(qs) == 1 else 2
        nrow = -(-len(qs) // ncol)
        fig, axes, own = subplots(ax, nrow, ncol, sharey=True,
                                  figsize=(PRINT_WIDTH_IN, 0.2 * _n_rows(valid) * nrow
                                           + 0.45 * nrow + 2.2))
    scale = gap_scale(diagnosis.gap[valid])
    im = _gap_panels(axes, diagnosis, qs, cens, valid, scale)
    for a in axes.flat[len(qs):]:
        a.set_visible(False)
    for a in axes.flat[:len(qs)]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
        a.set_ylabel("channel", fontsize=LABEL_SIZE)
    if im is not None:
        colorbar(fig, im, axes.ravel().tolist(), diagnosis.gap[valid], -scale, scale,
                 f"gap 20 log10(sim/measured) [dB]; grey: below {margin:g}× the noise floor")
    title = f"gap map (baseline){_run_name(diagnosis)}; verdict: {diagnosis.verdict}"
    title += (f"; outlined: ≥ {GAP_OUTLINE_RUN} neighbouring speeds beyond "
              f"±{GAP_OUTLINE_DB:g} dB")
    if empty:
        title += f"; {len(empty)} quantities all below {margin:g}× the floor, not drawn"
    return finish(fig, own, path, provenance, title=title if not is_axes(ax) else None)


def gap_scale(gaps) -> float:
    """Colour scale [dB]: the largest finite |``gaps``| [dB] rounded up to one of
    :data:`GAP_SCALES_DB`, at least :data:`GAP_SCALE_DB`."""
    g = np.abs(np.asarray(gaps, float))
    top = float(g[np.isfinite(g)].max()) if np.isfinite(g).any() else 0.0
    return next((v for v in GAP_SCALES_DB if v >= max(top, GAP_SCALE_DB)), GAP_SCALES_DB[-1])


def _run_name(diagnosis) -> str:
    """' of run 1 (FILE) of N' for a plan's figures (its first run), else ''."""
    runs = getattr(diagnosis, "runs", None) or []
    if not runs:
        return ""
    return f" of run 1 ({Path(runs[0]['file']).name}) of {len(runs)}"


def _gap_panels(axes, diagnosis, qs, cens, valid, scale=GAP_SCALE_DB):
    """Draw the gap panels; returns the last colour mesh (None when nothing was drawn)."""
    from matplotlib.colors import ListedColormap  # deferred: heavy optional package
    d = diagnosis.data
    rows = np.flatnonzero(valid.any(axis=(0, 2))) if valid.any() else np.arange(len(d.channels))
    y = np.arange(rows.size)
    im = None
    for a, q in zip(axes.flat, qs):
        k = d.quantities.index(q)
        g, ok = diagnosis.gap[:, rows, k].T, valid[:, rows, k].T
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
                          vmin=-scale, vmax=scale, shading="nearest")
        runs = _runs_beyond(np.where(ok, np.abs(g), 0.0) > GAP_OUTLINE_DB, GAP_OUTLINE_RUN)
        if runs.any():
            a.contour(d.rpm, y, runs.astype(float), [0.5], colors="k", linewidths=0.8)
    return im


def _n_rows(valid) -> int:
    """Channels drawn in the gap map: those with an uncensored point."""
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
    """Order gaps (a) per channel against frequency with the fitted structure part, and
    (b) per order, averaged over channels, against speed with the fitted excitation part.

    Beyond :data:`MAX_CHANNELS_ONE_AXIS` channels (a) is small multiples per base and
    direction (``docs/reference/figures.md``, ``gap_vs_frequency.png``).

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
    ax : None, Figure or SubFigure
    provenance : Provenance, optional
    """
    d, p = diagnosis.data, diagnosis.parts
    with_data = [k for k in np.flatnonzero(d.order_mask) if np.isfinite(diagnosis.gap[:, :, k]).any()]
    chans = [c for c in range(len(d.channels)) if np.isfinite(diagnosis.gap[:, c, with_data]).any()]
    many = len(chans) > MAX_CHANNELS_ONE_AXIS
    fig, own, small, a2 = _frequency_layout(ax, diagnosis, with_data, chans, many)
    for a in small:
        log_axis(a, "x", max_ticks=4 if many else 9)
        a.set_xlabel("frequency [Hz]" if many else "frequency = order × rpm / 60 [Hz]", fontsize=LABEL_SIZE)
        a.set_ylabel("gap [dB]" if many else "gap per channel [dB]", fontsize=LABEL_SIZE)
    a2.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a2.set_ylabel("gap, mean over channels [dB]", fontsize=LABEL_SIZE)
    for a in small + [a2]:
        a.axhline(0, color="0.5", lw=0.5)
        a.grid(True, alpha=0.3)
        a.tick_params(which="both", labelsize=TICK_SIZE)
    if many:
        figure_legend(fig, small)
    else:
        _legend_above(small[0], "(a) gap of every order per channel against frequency; line: "
                                "the channel's fitted structure part dH(f) + constant")
    _legend_above(a2, "(b) gap per order, mean over the channels, against speed; dashed: the "
                      "order's fitted excitation part")
    sh = p["share_alone"]
    title = (f"gap split{_run_name(diagnosis)}: structure {sh['structure']:.0%}, excitation "
             f"{sh['excitation']:.0%}, channel constant {sh['const']:.0%} (each alone)"
             + ("; (a) per base and direction, line: fitted structure part" if many else ""))
    return finish(fig, own, path, provenance, title=title if not is_axes(ax) else None)


def _frequency_layout(ax, diagnosis, orders, chans, many):
    """``(fig, own, panels of (a), panel (b))`` of :func:`plot_gap_frequency`, drawn."""
    groups = _channel_groups(diagnosis.data.channels, chans)
    ncol = 3 if many else 1
    nrow = -(-len(groups) // ncol) if many else 1
    fig, axes, own = subplots(ax, nrow + 2, ncol,
                              figsize=(PRINT_WIDTH_IN, (2.0 * nrow if many else 4.2) + 4.2))
    gs = axes[0, 0].get_gridspec()
    for a in axes.flat:
        a.remove()
    small = []
    for j, (key, cs) in enumerate(groups.items() if many else [(None, chans)]):
        a = fig.add_subplot(gs[j // ncol, j % ncol])
        _gap_by_channel(a, diagnosis, orders, cs, sides=many)
        if many:
            a.set_title(f"{key[0]} {key[1].upper()}", fontsize=TITLE_SIZE)
        small.append(a)
    a2 = fig.add_subplot(gs[nrow:, :])
    _gap_by_order(a2, diagnosis, orders)
    return fig, own, small, a2


def _channel_groups(channels, chans) -> dict:
    """``{(base, direction): [channel indices]}`` of ``chans`` (both sides of a mount share)."""
    out = {}
    for c in chans:
        mount, direction = channels[c]
        out.setdefault((split_side(mount)[0], direction), []).append(c)
    return out


def _gap_by_channel(ax, diagnosis, orders, chans, sides):
    """Gap points and structure line of ``chans``: a series style each, or by ``sides``
    (engine, body side, body point: marked so no order's line of panel (b) looks alike)."""
    d, p = diagnosis.data, diagnosis.parts
    sc = p["structure_curves"]
    for j, c in enumerate(chans):
        mount, direction = d.channels[c]
        base, side = split_side(mount)
        if sides:
            k = 0 if side != "passive" and c < d.n_active else 1 if side == "passive" else 2
            style = {"color": PALETTE[k], "ls": ("-", "--", ":")[k], "marker": "os^"[k],
                     "ms": 3, "markevery": 6}
            label = ("engine side", "body side (passive)", "body point")[k]
        else:
            style = series_style(j)
            label = f"{mount} {direction.upper()}"
        for k in orders:
            f = (d.harmonic[k] + 1) / 2.0 * d.rpm / 60.0
            ax.plot(f, diagnosis.gap[:, c, k], "o", ms=1.6, color=style["color"], alpha=0.6, ls="none")
        ax.plot(sc["frequency_hz"], np.array(sc["by_channel"][c]) + p["channel_const_db"][c],
                lw=1.2, label=label, **style)


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
        ax.plot(ec["rpm"], ec["by_quantity"][k], lw=2.0, ls=(0, (4, 2)), color=style["color"], alpha=0.7)
    if orders:
        ax.plot([], [], lw=2.0, ls=(0, (4, 2)), color="0.45",
                label="fitted excitation part (dashed, the order's colour)")


def _legend_above(ax, title):
    """The panel's legend above it, carrying ``title``."""
    n = len(ax.get_legend_handles_labels()[1])
    leg = ax.legend(loc="lower left", bbox_to_anchor=(0, 1.01, 1, 0), mode="expand",
                    ncol=max(1, min(n, 5)), fontsize=LEGEND_SIZE, frameon=False,
                    title=wrap(title, PRINT_WIDTH_IN * 0.9, TITLE_SIZE),
                    title_fontsize=TITLE_SIZE, borderaxespad=0.2)
    leg.get_title().set_multialignment("left")
    leg._legend_box.align = "left"


def plot_diagnosis_overlay(diagnosis, path=None, n_panels=6, *, ax=None, provenance=None):
    """Measured, baseline and baseline + chosen effect for the largest-gap channel-orders.

    Held-out speeds circled, censored points hollow at the censoring level.

    Parameters
    ----------
    diagnosis : DiagnosisResult
    path : str, optional
    n_panels : int
        Channel-orders shown (largest RMS gap first).
    ax : None, Figure or SubFigure
    provenance : Provenance, optional
    """
    d, g, cens = diagnosis.data, diagnosis.gap, _censored(diagnosis)
    score = []
    for c in range(len(d.channels)):
        for k in np.flatnonzero(d.order_mask):
            v = np.where(cens[:, c, k], np.nan, g[:, c, k])
            if np.isfinite(v).sum() > 2:
                score.append((float(np.sqrt(np.nanmean(v ** 2))), c, k))
    score = sorted(score, reverse=True)[:n_panels]
    ncol = 2
    nrow = max(1, int(np.ceil(len(score) / ncol)))
    fig, axes, own = subplots(ax, nrow, ncol, figsize=(PRINT_WIDTH_IN, 2.5 * nrow + 2.0))
    held = np.isin(d.rpm, diagnosis.split["heldout_rpm"])
    for a, (rms, c, k) in zip(axes.flat, score):
        _overlay_panel(a, diagnosis, c, k, held, rms, cens[:, c, k])
    if not score:
        no_data(axes.flat[0], "no channel-order above the noise floor")
    for a in axes.flat[max(1, len(score)):]:
        a.set_visible(False)
    for a in axes.flat[:len(score)]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
        a.set_ylabel("RMS velocity [mm/s]", fontsize=LABEL_SIZE)
    legend(fig, axes, ax)
    return finish(fig, own, path, provenance,
                  title=f"before / after / measured{_run_name(diagnosis)}: verdict "
                        f"{diagnosis.verdict}" if not is_axes(ax) else None)


def _overlay_panel(ax, diagnosis, c, k, held, rms, cens):
    d = diagnosis.data
    m, cl = d.level[:, c, k] * 1e3, NOISE_FLOOR_MARGIN * d.floor * 1e3
    up = np.isfinite(m) & ~cens
    ax.plot(d.rpm[up], m[up], "k.", ms=2.5, label="measured")
    if cens.any():
        ax.plot(d.rpm[cens], np.full(int(cens.sum()), cl), "o", mfc="none", mec="k", ms=2.5,
                mew=0.6, label=f"measured below {NOISE_FLOOR_MARGIN:g}× the floor (censored)")
    ax.plot(d.rpm[held & up], m[held & up], "o", mfc="none", mec="0.6", ms=4, label="held-out speeds")
    values = [m[up], [cl] if cens.any() else []]
    sim0 = _sim_curve(diagnosis, diagnosis.sim_levels, diagnosis.gap, c, k, m)
    ax.plot(d.rpm, sim0, "-", color=OKABE_ITO["vermillion"], lw=1, label="baseline simulation")
    values.append(sim0)
    if diagnosis.chosen is not None:
        after = _sim_curve(diagnosis, diagnosis.sim_after, diagnosis.gap_after, c, k, m)
        if after is None:
            ax.text(0.02, 0.03, f"baseline + {diagnosis.chosen.label} not drawn: no steady "
                    "state", transform=ax.transAxes, fontsize=LABEL_SIZE, color="0.4")
        else:
            ax.plot(d.rpm, after, "-", color=OKABE_ITO["blue"], lw=1,
                    label=f"baseline + {diagnosis.chosen.label}")
            values.append(after)
    mnt, dr = d.channels[c]
    style_panel(ax, f"{mnt} {dr.upper()} — {quantity_label(d.quantities[k])}: "
                    f"gap {rms:.1f} dB RMS", np.concatenate([np.ravel(v) for v in values]))


def _sim_curve(diagnosis, levels, gap, c, k, measured_mm):
    """Simulated curve [mm/s]: ``levels``, else measured × 10^(gap/20); None without either."""
    if levels is not None:
        return levels[:, c, k] * 1e3
    if gap is None:
        return None
    return measured_mm * 10 ** (gap[:, c, k] / 20)
