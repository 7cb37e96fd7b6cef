"""Figures of the mounting system: modes, both sides of each mount, path contributions."""

from __future__ import annotations

import numpy as np

from powertrain.analysis.channel import passive_name
from powertrain.plotting import SIGNAL_UNITS
from powertrain.plotting.pages import draw_pages
from powertrain.plotting.runup import SYNTHESIS_NOTE, panel_title, style_panel
from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    OKABE_ITO,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    finish,
    is_axes,
    legend,
    no_data,
    series_style,
    subplots,
    wrap,
)

#: Height of a both-sides figure outside its panel rows [in]: title, legend, x labels, foot.
FRAME_IN = 1.9
#: Rigid-body coordinates, as in :data:`powertrain.solvers.modes.COORDINATES`.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")
_COLOURS = dict(zip(COORDINATES, (OKABE_ITO[c] for c in (
    "blue", "orange", "bluish green", "vermillion", "reddish purple", "sky blue"))))


def plot_modes(result, path=None, ax=None, provenance=None):
    """Kinetic-energy distribution of each mode of ``result`` as stacked bars, labelled with
    frequency, damping ratio and angle to the torque-roll axis; PNG to ``path``, into ``ax``
    (None, Axes, Figure, SubFigure), ``provenance`` at the foot."""
    fig, axes, own = subplots(ax, figsize=(PRINT_WIDTH_IN, 4.6))
    ax = axes[0, 0]
    n = len(result.modes)
    x, bottom = np.arange(n), np.zeros(n)
    ked = np.array([np.clip(m.ked_percent, 0, None) for m in result.modes]).reshape(n, 6)
    for j, c in enumerate(COORDINATES):
        ax.bar(x, ked[:, j], bottom=bottom, color=_COLOURS[c], label=c, width=0.7)
        bottom += ked[:, j]
    ax.set_xticks(x)
    ax.set_xticklabels([f"{m.frequency_hz:.2f} Hz\nζ={m.damping_ratio:.3f}\n"
                        f"TRA {m.angle_to_torque_roll_axis_deg:.0f}°"
                        + ("" if m.kind == "rigid-body" else f"\n{m.kind}")
                        for m in result.modes], fontsize=TICK_SIZE)
    ax.tick_params(labelsize=TICK_SIZE)
    ax.set_ylabel("kinetic energy [%]", fontsize=LABEL_SIZE)
    ax.set_ylim(0, 100)
    if own:
        fig.legend(*ax.get_legend_handles_labels(), ncol=6, fontsize=LEGEND_SIZE,
                   loc="outside upper center", frameon=False)
    else:
        ax.legend(ncol=6, fontsize=LEGEND_SIZE, loc="upper center")
    ax.set_title(f"{result.engine} — {result.method.split(':')[0]} modes", fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance)


def plot_static(result, path=None, ax=None, provenance=None):
    """Static deflection [mm] of every mount's local x, y, z against speed under the weight
    and mean torque reaction; ``path``, ``ax``, ``provenance`` as :func:`plot_modes`'s."""
    fig, axes, own = subplots(ax, figsize=(PRINT_WIDTH_IN, 4.2))
    a = axes[0, 0]
    rpm, deflection = result.rpm, result.stack("deflection") * 1e3     # (n_rpm, n_m, 3)
    for m, name in enumerate(result.mounts):
        for k, d in enumerate("xyz"):
            a.plot(rpm, deflection[:, m, k], marker="o", ms=2.5, lw=1.1,
                   label=f"{name} {d}", **series_style(3 * m + k))
    a.axhline(0.0, color="0.5", lw=0.5)
    a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    a.set_ylabel("static deflection [mm]", fontsize=LABEL_SIZE)
    a.grid(True, alpha=0.3)
    a.tick_params(labelsize=TICK_SIZE)
    legend(fig, axes, ax)
    title = ("static operating point" + (f" of {result.engine}" if result.engine else "")
             + ": mount deflections (local axes) under the weight and the mean drive-torque "
             "reaction")
    return finish(fig, own, path, provenance, title=title if not is_axes(ax) else None)


def _positive(values):
    """Mask non-positive values (a log axis cannot show an exact zero)."""
    return np.ma.masked_less_equal(np.asarray(values, float), 0.0)


def plot_runup_both_sides(result, path=None, quantities=("synthesis", "order_2", "order_4"),
                          signal="velocity", ax=None, provenance=None):
    """Run-up curves of ``result`` with a body model: a panel per mount direction with both
    sides, then per body-point direction, columns ``quantities`` of ``signal``; paged as
    :func:`~powertrain.plotting.runup.plot_runup` (``path``, ``ax``, ``provenance``)."""
    rows = [(m, d, True) for m in result.mounts for d in "xyz"]
    points = [(p, d, False) for p in result.points for d in "xyz"]
    silent = [(p, d) for p, d, _ in points
              if not any(np.any(result.curve(p, d, q, signal) > 0) for q in quantities)]
    rows += [r for r in points if r[:2] not in silent]
    title = "run-up with the body model: both sides of each mount, then the body points"
    title += SYNTHESIS_NOTE
    if any(not np.any(result.curve(passive_name(m), d, q, signal) > 0)
           for m, d, _ in rows[:3 * len(result.mounts)] for q in quantities):
        title += ". \"body side zero\": the body model does not move there at any speed"
    if silent:
        title += (". Zero at every speed (no mount path moves them), not drawn: "
                  + ", ".join(f"{p} {d.upper()}" for p, d in silent))
    frame = FRAME_IN + 0.16 * wrap(title, PRINT_WIDTH_IN * 0.95, 9).count("\n")

    def page(chunk, height, file, note):
        fig, axes, own = subplots(ax, len(chunk), len(quantities), sharex=True,
                                  figsize=(PRINT_WIDTH_IN, height * len(chunk) + frame))
        _both_sides_grid(fig, axes, result, chunk, quantities, signal)
        legend(fig, axes, ax)
        return finish(fig, own, file, provenance, title=title + note if not is_axes(ax) else None)
    return draw_pages(rows, frame, ax, path, page)


def _both_sides_grid(fig, axes, result, rows, quantities, signal):
    """Panels of one page of :func:`plot_runup_both_sides` and their axis labels."""
    factor, unit = SIGNAL_UNITS[signal][:2]
    for r, row in enumerate(rows):
        for q, quantity in enumerate(quantities):
            _both_sides_panel(axes[r, q], result, row, quantity, signal, factor)
    for a in axes[-1]:
        a.set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    fig.supylabel(f"RMS {signal.replace('_', ' ')} [{unit}]", fontsize=LABEL_SIZE + 0.5)


def _both_sides_panel(a, result, row, quantity, signal, factor):
    name, d, is_mount = row
    y = result.curve(name, d, quantity, signal) * factor
    values = [y]
    a.plot(result.rpm, _positive(y), "o-", ms=2, lw=1.1,
           color=OKABE_ITO["blue"] if is_mount else OKABE_ITO["bluish green"],
           label="engine side" if is_mount else "body point")
    title = panel_title(name, d, quantity)
    if is_mount:
        yb = result.curve(passive_name(name), d, quantity, signal) * factor
        if np.any(yb > 0):
            a.plot(result.rpm, _positive(yb), "s--", ms=2, lw=1.1,
                   color=OKABE_ITO["vermillion"], label="body side")
            values.append(yb)
        else:
            title += "\nbody side zero"
    if not style_panel(a, title, np.concatenate(values)):
        no_data(a, "zero at every speed")


def plot_path_contributions(result, path=None, order=2.0, n_paths=6, ax=None, provenance=None):
    """Transfer paths of every body-point direction at ``order``: each path's velocity in
    phase with the total, Re(v_path·conj(v)/|v|) [mm/s] (they add up to |v|), for the
    ``n_paths`` largest, and |v|; ``path``, ``ax``, ``provenance`` as :func:`plot_modes`'s."""
    rows, silent = [], []
    for p in result.points:
        for d in "xyz":
            pc = result.path_contributions(p, d, order) * 1e3
            (rows if np.abs(pc.sum(axis=1)).max(initial=0.0) > 1e-9 else silent).append((p, d, pc))
    if not rows:
        rows, silent = silent[:1], silent[1:]
    fig, axes, own = subplots(ax, len(rows), 1, sharex=True, figsize=(PRINT_WIDTH_IN, 2.4 * len(rows) + 2.0))
    labels = [f"{m} {d}" for m, d in result.paths]
    colours = {}
    for a, (p, d, pc) in zip(axes[:, 0], rows):
        if np.abs(pc).max(initial=0.0) > 1e-9:
            _paths_panel(a, result.rpm, pc, labels, n_paths, colours)
        else:
            no_data(a, "no response in this direction (zero at every speed)")
        a.set_title(f"{p} {d.upper()}", fontsize=TITLE_SIZE)
        a.set_ylabel("velocity [mm/s]", fontsize=LABEL_SIZE)
        a.grid(True, alpha=0.3)
        a.tick_params(labelsize=TICK_SIZE)
    axes[-1, 0].set_xlabel("engine speed [rpm]", fontsize=LABEL_SIZE)
    legend(fig, axes, ax)
    title = (f"transfer paths at order {order:g}: each path's velocity in phase with the "
             "total (they add up to |v|), the largest paths")
    if silent:
        title += ". No response at every speed, not drawn: " + ", ".join(
            f"{p} {d.upper()}" for p, d, _ in silent)
    return finish(fig, own, path, provenance, title=title if not is_axes(ax) else None)


def _paths_panel(a, rpm, pc, labels, n_paths, colours):
    """Largest in-phase path parts (equal curves merged) and the total; ``colours`` keeps a
    colour per label across panels."""
    total = pc.sum(axis=1)
    mag = np.abs(total)
    unit = np.where(mag > 0, np.conj(total) / np.where(mag > 0, mag, 1.0), 0.0)
    inphase = (pc * unit[:, None]).real
    groups = []
    for j in np.argsort(np.abs(inphase).max(axis=0))[::-1][:n_paths]:
        same = [g for g in groups if np.allclose(inphase[:, g[0]], inphase[:, j], rtol=1e-6, atol=1e-9)]
        (same[0].append(j) if same else groups.append([j]))
    for g in groups:
        label = " = ".join(labels[j] for j in g)
        k = colours.setdefault(label, len(colours))
        a.plot(rpm, inphase[:, g[0]], marker="o", ms=2.5, lw=1.1, label=label, **series_style(k))
    a.plot(rpm, mag, "k-", lw=2, label="total |v|")
    a.axhline(0.0, color="0.5", lw=0.6)
