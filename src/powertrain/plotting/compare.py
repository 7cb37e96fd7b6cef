"""Comparison figure: measured and simulated run-up order curves, level gap shaded."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.plotting.runup import SYNTHESIS_NOTE, grid, label_grid, panel_title, style_panel
from powertrain.plotting.style import (
    GAP_ABOVE,
    GAP_BELOW,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    figure_legend,
    finish,
    no_data,
)


def comparison_quantities(comparison) -> list:
    """Every quantity requested: the default three and all measured or compared ones."""
    return comparison.requested_quantities()


def plot_comparison(comparison, path=None, quantities=None, *, ax=None, channel=None,
                    quantity=None, provenance=None):
    """Measured and simulated RMS velocity against speed, level gap shaded.

    The thesis's layout (Kovarik 2016, Figs 45-71): one row per mount and direction, one
    column per quantity (synthesis and every measured order), log-scaled velocity [mm/s].
    The measured curve is a thin black line, the simulation markers at its speeds joined by
    straight lines (on the log axis these are exactly the log-level interpolation used for
    the gaps); the gap at the compared speeds is shaded orange where the simulation is
    higher, sky blue where it is lower (colour-blind safe). Points excluded at the noise
    floor are grey crosses, the exclusion limit a dotted line; a panel with no point above
    it says so. Under each panel title: the RMS gap and bias [dB].

    Parameters
    ----------
    comparison : ComparisonResult
    path : str or Path, optional
        PNG file written atomically.
    quantities : sequence of str, optional
        Columns; default :func:`comparison_quantities` (nothing requested is left out).
    ax : None, Axes, Figure or SubFigure
        Where to draw; an Axes gets the one panel ``channel``/``quantity``.
    provenance : Provenance, optional
        Foot line of a new figure.
    """
    from matplotlib.lines import Line2D

    from powertrain.analysis.compare import NOISE_FLOOR_MARGIN
    sim = comparison.simulated
    rows = list(sim.channels)
    rows += [c for c in comparison.measured.channels if c not in rows]
    quantities = list(quantities or comparison_quantities(comparison))
    fig, panels, own, axes = grid(ax, rows, quantities, channel, quantity, panel_height=1.35)
    limit = NOISE_FLOOR_MARGIN * comparison.noise_floor * 1e3
    compared = {(c.mount, c.direction, c.quantity): c for c in comparison.channels}
    missing = {(m["mount"], m["direction"], m["quantity"]): m["reason"]
               for m in comparison.missing}
    for key, a in panels.items():
        c = compared.get(key)
        if c is None or not c.scored.any():
            a.set_title(panel_title(*key), fontsize=TITLE_SIZE)
            no_data(a, "not compared: " + missing.get(key, "every measured point at the "
                                                          "noise floor"))
            a.tick_params(labelsize=TICK_SIZE)
            continue
        _panel(a, key, comparison, c, limit)
    label_grid(fig, axes, "RMS velocity [mm/s]")
    if own:
        extra = [(Line2D([], [], color="0.5", ls=":", lw=0.8),
                  f"noise-floor limit ({limit:g} mm/s)")] if limit > 0 else []
        figure_legend(fig, axes, extra)
    src = Path(comparison.measured.source).name
    tag = "SYNTHETIC measurement" if comparison.measured.synthetic else "measurement"
    title = (f"{tag} {src} vs simulation: overall RMS gap {comparison.overall_rms_db:.2f} dB "
             f"(gap = 20 log10(sim/measured); under each panel title its RMS and bias "
             f"[dB]){SYNTHESIS_NOTE}")
    return finish(fig, own, path, provenance, title=title if own else None)


def _panel(ax, key, comparison, c, limit):
    """One compared channel-quantity: curves, shaded gap, excluded points, title with the
    gap."""
    mm = 1e3
    mount, direction, q = key
    values = []
    if key in comparison.measured.curves:
        rm, vm = comparison.measured.curves[key]
        ok = vm > 0
        ax.plot(rm[ok], vm[ok] * mm, "-", color="k", lw=0.9, label="measured")
        values.append(vm[ok] * mm)
    if key in comparison.simulated.curves:
        rs, vs = comparison.simulated.curves[key]
        ok = vs > 0
        ax.plot(rs[ok], vs[ok] * mm, "o-", color=colour(0), ms=2, lw=1.0, label="simulated")
        values.append(vs[ok] * mm)
    title = panel_title(mount, direction, q)
    if c.scored.any():
        s = np.where(c.scored, c.simulated, np.nan) * mm
        m = np.where(c.scored, c.measured, np.nan) * mm
        ax.fill_between(c.rpm, m, s, where=c.scored & (s >= m), interpolate=True,
                        color=GAP_ABOVE, alpha=0.45, lw=0, label="sim > measured")
        ax.fill_between(c.rpm, m, s, where=c.scored & (s < m), interpolate=True,
                        color=GAP_BELOW, alpha=0.45, lw=0, label="sim < measured")
        title += f"\n{c.stats['rms_db']:.1f} rms, {c.stats['bias_db']:+.1f} bias"
    if c.at_floor.any():
        ax.plot(c.rpm[c.at_floor], np.maximum(c.measured[c.at_floor] * mm, limit * 0.5), "x",
                color="0.55", ms=3, label="excluded (noise floor)")
    values = np.concatenate(values) if values else np.array([])
    if style_panel(ax, title, values) and limit > 0:
        lo, hi = ax.get_ylim()
        if limit / 2 < hi and lo < limit:
            ax.set_ylim(max(lo, limit / 2), hi)
        if lo < limit < hi:
            ax.axhline(limit, color="0.5", ls=":", lw=0.8)
