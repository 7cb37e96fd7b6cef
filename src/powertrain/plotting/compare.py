"""Comparison figure: measured and simulated run-up order curves, level gap shaded, order
phase under each level panel with phase on both sides."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.errors import InputError
from powertrain.plotting.runup import (
    SYNTHESIS_NOTE,
    grid,
    label_grid,
    panel_title,
    select_panels,
    style_panel,
)
from powertrain.plotting.style import (
    GAP_ABOVE,
    GAP_BELOW,
    LABEL_SIZE,
    MAX_HEIGHT_IN,
    OKABE_ITO,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    finish,
    is_axes,
    legend,
    no_data,
    panels_error,
    quantity_label,
    signed,
    subplots,
)

#: Display factor of the levels: m/s -> mm/s.
MM = 1e3
#: Height of one panel row [in]: between these, as much as fits :data:`MAX_HEIGHT_IN` (the
#: lower keeps three log ticks apart at 8 pt).
ROW_HEIGHT_IN = (0.62, 1.35)
#: Figure height outside the panel rows [in]: title, legend, x label, provenance line.
FRAME_HEIGHT_IN = 1.6
#: Most labelled ticks on a level axis (1-2-5 per decade collide on a compact row).
MAX_LEVEL_TICKS = 3
#: Drawn height of a phase panel [in] (two 8-pt labels 180° apart need 0.29 in) and its
#: labelled ticks [deg], inside ±180° so none reaches the level panel above.
PHASE_AXES_IN = 0.32
PHASE_TICKS = (-90.0, 90.0)
#: Phase axis limit [deg]: beyond ±180° so points at the wrap stay visible.
PHASE_LIMIT_DEG = 200.0
#: Vertical pad around each panel with phase rows [in] (half the default), and a level
#: row's height besides its axes: its title and pads [in].
PHASE_FIGURE_PAD_IN = 1.5 / 72
LEVEL_DECORATION_IN = 0.2
#: Said in the title of a figure with phase rows, and the height of its two lines [in].
PHASE_NOTE_HEIGHT_IN = 0.3
PHASE_NOTE = ("; under a level panel, where both sides give it: the order phase φ re "
              "cylinder-1 firing TDC (√2·RMS·cos(kθ + φ))")
#: Simulated speeds are marked when there are at most this many (else a line).
MAX_MARKED_SPEEDS = 30
#: Marker of a measured-not-modelled point.
NOT_MODELLED_STYLE = {"marker": "^", "ls": "none", "ms": 2.5, "mew": 0, "color": OKABE_ITO["reddish purple"]}
#: Text of an empty panel per reason it was not compared (:attr:`ComparisonResult.missing`).
EMPTY_TEXT = {"not in the measured data": "not measured",
              "not in the simulation": "not simulated",
              "no comparable point": "every point below the limit"}


def row_height(n_rows: int, n_phase_rows: int = 0) -> float:
    """Level row height [in] fitting ``n_rows`` level and ``n_phase_rows`` phase rows in
    :data:`MAX_HEIGHT_IN`, within :data:`ROW_HEIGHT_IN` (with phase rows, below its lower
    bound rather than past the page)."""
    lo, hi = ROW_HEIGHT_IN
    room = MAX_HEIGHT_IN - FRAME_HEIGHT_IN - n_phase_rows * phase_row_height() - \
        (PHASE_NOTE_HEIGHT_IN if n_phase_rows else 0.0)
    fit = room / max(n_rows, 1)
    return float(min(fit, hi) if n_phase_rows else np.clip(fit, lo, hi))


def phase_row_height() -> float:
    """Height of a phase row [in]: its panel and the pads above and below."""
    return PHASE_AXES_IN + 4 * PHASE_FIGURE_PAD_IN


def phased_channels(comparison) -> dict:
    """``{(mount, direction, quantity): ChannelComparison}`` of ``comparison``'s
    channel-quantities with a phase gap."""
    return {(c.mount, c.direction, c.quantity): c for c in comparison.channels
            if c.stats.get("n_phase_compared")}


def plot_comparison(comparison, path=None, quantities=None, *, ax=None, channel=None,
                    quantity=None, provenance=None, phase=True):
    """Measured and simulated RMS velocity against speed, level gap shaded.

    Kovarik 2016's layout (Figs 45-71): a row per mount and direction, a column per
    quantity, log velocity [mm/s]; phase panels under channels with phase on both sides
    (``docs/reference/figures.md``).

    Parameters
    ----------
    comparison : ComparisonResult
    path : str or Path, optional
        PNG file written atomically.
    quantities : sequence of str, optional
        Columns; default ``comparison.requested_quantities()``.
    ax : None, Axes, Figure or SubFigure
        Where to draw; an Axes takes one panel (``channel``, ``quantity``, no phase).
    channel, quantity : optional
        Only this channel ((mount, direction)) and quantity.
    provenance : Provenance, optional
        Foot line of a new figure.
    phase : bool
        Draw the phase panels.
    """
    rows = list(comparison.simulated.channels)
    rows += [c for c in comparison.measured.channels if c not in rows]
    rows, quantities = select_panels(rows, list(quantities or
                                                comparison.requested_quantities()), channel, quantity)
    phased = {k: c for k, c in phased_channels(comparison).items()
              if k[:2] in rows and k[2] in quantities} if phase else {}
    if is_axes(ax) and phased:
        raise InputError(panels_error(2, ", or phase=False for the level panel alone"), key="ax")
    fig, panels, phase_panels, own, axes = _grid(ax, rows, quantities, None, None, phased)
    limit, margin_titles = comparison.exclusion_limit * MM, not is_axes(ax)
    _level_panels(panels, comparison, rows[0], limit, margin_titles)
    bottom = set(map(id, axes[-1]))
    for key, a in phase_panels.items():
        if key in phased:
            _phase_panel(a, comparison, phased[key])
        else:
            _no_phase(a, id(a) in bottom)
    if margin_titles:
        _margin_labels(axes, panels, rows, quantities[0])
    label_grid(fig, axes, "RMS velocity [mm/s]" + (", under it phase φ [°]" if phased else ""))
    legend(fig, axes, ax)
    return finish(fig, own, path, provenance,
                  title=_title(comparison, bool(phased)) if not is_axes(ax) else None)


def _level_panels(panels, comparison, top_channel, limit, margin_titles):
    """Draw every level panel, or label it empty."""
    compared = {(c.mount, c.direction, c.quantity): c for c in comparison.channels}
    unmodelled = {(e["mount"], e["direction"], e["quantity"]): e for e in comparison.not_modelled}
    missing = {(m["mount"], m["direction"], m["quantity"]): m["reason"] for m in comparison.missing}
    for key, a in panels.items():
        head = _head(key, top_channel, margin_titles)
        if key in compared or key in unmodelled:
            _panel(a, key, comparison, compared.get(key), unmodelled.get(key), limit, head)
        else:
            _empty_panel(a, head, missing.get(key, "no comparable point"))


def _margin_labels(axes, panels, rows, first_quantity):
    """Speed ticks of the grid and each row's channel on the left."""
    from matplotlib.ticker import MaxNLocator  # deferred: heavy optional package
    axes[0, 0].xaxis.set_major_locator(MaxNLocator(nbins=3, steps=[1, 2, 5, 10]))
    for mount, direction in rows:
        panels[(mount, direction, first_quantity)].set_ylabel(f"{mount} {direction.upper()}",
                                                              fontsize=LABEL_SIZE)


def _grid(ax, rows, quantities, channel, quantity, phased):
    """``(fig, {key: level Axes}, {key: phase Axes}, own, all panels)``: the level grid of
    :func:`~powertrain.plotting.runup.grid`, a phase row under each row with phase."""
    with_phase = [ch for ch in rows if any(k[:2] == tuple(ch) for k in phased)]
    height = row_height(len(rows), len(with_phase))
    if not with_phase:
        fig, panels, own, axes = grid(ax, rows, quantities, channel, quantity, panel_height=height)
        return fig, panels, {}, own, axes
    kinds = [(tuple(ch), kind) for ch in rows
             for kind in (("level", "phase") if ch in with_phase else ("level",))]
    rows_in = [height if kind == "level" else phase_row_height() for _, kind in kinds]
    axes_in = [height - LEVEL_DECORATION_IN if kind == "level" else PHASE_AXES_IN for _, kind in kinds]
    fig, all_axes, own = subplots(ax, len(kinds), len(quantities), sharex=True,
                                  figsize=(PRINT_WIDTH_IN, sum(rows_in) + FRAME_HEIGHT_IN
                                           + PHASE_NOTE_HEIGHT_IN), gridspec_kw={"height_ratios": axes_in})
    if own:
        fig.get_layout_engine().set(h_pad=PHASE_FIGURE_PAD_IN)
    level = [i for i, (_, kind) in enumerate(kinds) if kind == "level"]
    panels = {(*rows[r], q): all_axes[i, j] for r, i in enumerate(level) for j, q in enumerate(quantities)}
    phase_panels = {(*ch, q): all_axes[i, j] for i, (ch, kind) in enumerate(kinds)
                    if kind == "phase" for j, q in enumerate(quantities)}
    return fig, panels, phase_panels, own, all_axes


def _no_phase(ax, bottom):
    """A phase slot without phase: hidden, or on the ``bottom`` row only its speed axis."""
    if not bottom:
        ax.set_visible(False)
        return
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)
    ax.tick_params(axis="y", left=False, labelleft=False)
    ax.tick_params(axis="x", labelsize=TICK_SIZE)
    ax.patch.set_visible(False)


def _phase_panel(ax, comparison, c):
    """Order phase [deg] of one channel-quantity ``c``: measured off the floor, simulated
    where its level is not zero."""
    key = (c.mount, c.direction, c.quantity)
    meas = np.asarray(comparison.measured.phases[key], float)
    _phase_line(ax, c.rpm, np.where(c.at_floor, np.nan, meas), "-", color="k", lw=0.7,
                label="measured", zorder=3)
    rpm, level = comparison.simulated.curves[key]
    sim = np.where(level > 0, comparison.simulated.phases[key], np.nan)
    sparse = len(comparison.sim_rpm) <= MAX_MARKED_SPEEDS
    _phase_line(ax, rpm, sim, "o-" if sparse else "-", color=colour(0), ms=2, lw=1.2, label="simulated")
    ax.set_ylim(-PHASE_LIMIT_DEG, PHASE_LIMIT_DEG)
    ax.set_yticks(PHASE_TICKS)
    ax.set_yticks([-180.0, 0.0, 180.0], minor=True)
    ax.grid(True, which="both", alpha=0.35)
    ax.tick_params(which="both", labelsize=TICK_SIZE)


def _phase_line(ax, rpm, phase_deg, fmt, **style):
    """Draw a wrapped phase against speed, broken at each wrap (a step over 180°)."""
    rpm, phase = np.asarray(rpm, float), np.asarray(phase_deg, float)
    jump = np.abs(np.diff(phase)) > 180.0
    at = np.nonzero(jump)[0] + 1
    ax.plot(np.insert(rpm, at, np.nan), np.insert(phase, at, np.nan), fmt, **style)


def _head(key, top_channel, margin_titles) -> str:
    """First title line: ``left Z · order 2`` alone; in a grid the quantity on the top row."""
    if not margin_titles:
        return panel_title(*key)
    return quantity_label(key[2]) if tuple(key[:2]) == tuple(top_channel) else ""


def _empty_panel(a, head, reason):
    a.set_title(head, fontsize=TITLE_SIZE)
    short = next((t for r, t in EMPTY_TEXT.items() if reason.startswith(r)), reason)
    no_data(a, "not compared: " + short, width=16)
    a.tick_params(labelsize=TICK_SIZE)


def limit_label(limit) -> str:
    """Legend label of the noise-floor exclusion limit [mm/s]."""
    return f"noise-floor limit ({limit:g} mm/s)"


def _title(comparison, phased=False) -> str:
    src = Path(comparison.measured.source).name
    tag = "SYNTHETIC measurement" if comparison.measured.synthetic else "measurement"
    n = comparison.n_not_modelled
    unmodelled = (f"; {n} points measured, not modelled (simulation below the "
                  f"{comparison.noise_floor * MM:g} mm/s floor; in no gap)") if n else ""
    return (f"{tag} {src} vs simulation: overall RMS gap {comparison.overall_rms_db:.2f} dB"
            f"{unmodelled} (gap = 20 log10(sim/measured); over each panel its RMS and bias "
            f"[dB]){SYNTHESIS_NOTE}" + (PHASE_NOTE if phased else ""))


def _panel(ax, key, comparison, c, unmodelled, limit, head):
    """One channel-quantity: curves, shaded gap, excluded and not-modelled points."""
    sparse = len(comparison.sim_rpm) <= MAX_MARKED_SPEEDS
    values = [_curve(ax, comparison.measured.curves, key, "-", color="k", lw=0.7,
                     label="measured", zorder=3),
              _curve(ax, comparison.simulated.curves, key, "o-" if sparse else "-",
                     color=colour(0), ms=2, lw=1.2, label="simulated")]
    title = head
    if c is not None and c.scored.any():
        s = np.where(c.scored, c.simulated, np.nan) * MM
        m = np.where(c.scored, c.measured, np.nan) * MM
        ax.fill_between(c.rpm, m, s, where=c.scored & (s >= m), interpolate=True,
                        color=GAP_ABOVE, alpha=0.45, lw=0, label="sim > measured")
        ax.fill_between(c.rpm, m, s, where=c.scored & (s < m), interpolate=True,
                        color=GAP_BELOW, alpha=0.45, lw=0, label="sim < measured")
        title += ("\n" if title else "") + \
            f"rms {c.stats['rms_db']:.1f}, bias {signed(c.stats['bias_db'])} dB"
    if c is not None and c.at_floor.any():
        ax.plot(c.rpm[c.at_floor], np.maximum(c.measured[c.at_floor] * MM, limit * 0.5), "x",
                color="0.55", ms=3, label="excluded (noise floor)")
    if unmodelled is not None:
        ax.plot(unmodelled["rpm"], np.asarray(unmodelled["measured_m_per_s"], float) * MM,
                label="measured, not modelled", **NOT_MODELLED_STYLE)
    values = np.concatenate(values)
    if style_panel(ax, title, values, max_ticks=MAX_LEVEL_TICKS) and limit > 0:
        lo, hi = ax.get_ylim()
        if limit / 2 < hi and lo < limit:
            ax.set_ylim(max(lo, limit / 2), hi)
        if lo < limit < hi:
            ax.axhline(limit, color="0.5", ls=":", lw=0.8, label=limit_label(limit))


def _curve(ax, curves, key, fmt, **style):
    """Draw the positive part of one curve; its drawn levels [mm/s]."""
    if key not in curves:
        return np.array([])
    rpm, level = curves[key]
    ok = level > 0
    ax.plot(rpm[ok], level[ok] * MM, fmt, **style)
    return level[ok] * MM
