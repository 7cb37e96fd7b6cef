"""Figures of the mounting system: modes, both sides of each mount, path contributions.

matplotlib comes through :mod:`powertrain.plotting` (imported lazily there only).
"""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import figure_legend, finish, no_data, subplots

#: Rigid-body coordinates, as in :data:`powertrain.solvers.modes.COORDINATES`.
COORDINATES = ("x", "y", "z", "rx", "ry", "rz")
_COLOURS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green", "rx": "tab:red",
            "ry": "tab:purple", "rz": "tab:brown"}


def plot_modes(result, path=None, ax=None, provenance=None):
    """Kinetic-energy distribution of each mode as stacked bars, labelled with frequency,
    damping ratio and the angle of its rotation axis to the torque-roll axis; returns the
    figure (``ax``: None, an Axes, Figure or SubFigure)."""
    fig, axes, own = subplots(ax, figsize=(9, 5.2))
    ax = axes[0, 0]
    n = len(result.modes)
    x = np.arange(n)
    bottom = np.zeros(n)
    ked = np.array([np.clip(m.ked_percent, 0, None) for m in result.modes]).reshape(n, 6)
    for j, c in enumerate(COORDINATES):
        ax.bar(x, ked[:, j], bottom=bottom, color=_COLOURS[c], label=c, width=0.7)
        bottom += ked[:, j]
    ax.set_xticks(x)
    ax.set_xticklabels([f"{m.frequency_hz:.2f} Hz\nζ={m.damping_ratio:.3f}\n"
                        f"TRA {m.angle_to_torque_roll_axis_deg:.0f}°"
                        + ("" if m.kind == "rigid-body" else f"\n{m.kind}")
                        for m in result.modes], fontsize=8)
    ax.set_ylabel("kinetic energy [%]")
    ax.set_ylim(0, 100)
    if own:
        fig.legend(*ax.get_legend_handles_labels(), ncol=6, fontsize=8,
                   loc="outside upper center", frameon=False)
    else:
        ax.legend(ncol=6, fontsize=8, loc="upper center")
    ax.set_title(f"{result.engine} — {result.method.split(':')[0]} modes", fontsize=9)
    return finish(fig, own, path, provenance)


def _positive(values):
    """Mask non-positive values (a log axis cannot show an exact zero)."""
    return np.ma.masked_less_equal(np.asarray(values, float), 0.0)


def plot_runup_both_sides(result, path=None, quantities=("synthesis", "order_2", "order_4"),
                          signal="velocity", ax=None, provenance=None):
    """Run-up curves with a body model: one panel per mount and direction holding the
    engine side (solid) and the body side (dashed), then one per body-point direction;
    columns = ``quantities``; log-scaled RMS [mm/s for velocity]. Returns the figure
    (``ax``: None, a Figure or SubFigure)."""
    from powertrain.assembly import passive_name
    from powertrain.plotting import SIGNAL_UNITS
    from powertrain.plotting.runup import style_panel
    from powertrain.plotting.style import quantity_label
    rows = [(m, d, True) for m in result.mounts for d in "xyz"]
    rows += [(p, d, False) for p in result.points for d in "xyz"]
    fig, axes, own = subplots(ax, len(rows), len(quantities),
                              figsize=(4 * len(quantities), 1.9 * len(rows)), sharex=True)
    factor, unit = SIGNAL_UNITS[signal][:2]
    for r, (name, d, is_mount) in enumerate(rows):
        for q, quantity in enumerate(quantities):
            a = axes[r, q]
            y = _positive(result.curve(name, d, quantity, signal) * factor)
            values = [y.compressed()]
            a.plot(result.rpm, y, "o-", ms=3, lw=1.2,
                   color="tab:blue" if is_mount else "tab:green",
                   label="engine side" if is_mount else "body point")
            if is_mount:
                yb = _positive(result.curve(passive_name(name), d, quantity, signal) * factor)
                a.plot(result.rpm, yb, "s--", ms=3, lw=1.2, color="tab:red", label="body side")
                values.append(yb.compressed())
            if not style_panel(a, f"{name} {d.upper()} — {quantity_label(quantity)}",
                               np.concatenate(values)):
                no_data(a, "zero at every speed")
            if q == 0:
                a.set_ylabel(f"RMS {signal.replace('_', ' ')} [{unit}]", fontsize=7)
    for a in axes[-1]:
        a.set_xlabel("engine speed [rpm]", fontsize=8)
    if own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance)


def plot_path_contributions(result, path=None, order=2.0, n_paths=6, ax=None,
                            provenance=None):
    """Transfer-path view of every body-point direction at one order: the part of each
    path's velocity in phase with the total, Re(v_path·conj(v)/|v|) [mm/s] (these add up to
    |v|), for the ``n_paths`` largest paths, and the total |v| (black). Returns the figure."""
    rows = [(p, d) for p in result.points for d in "xyz"]
    fig, axes, own = subplots(ax, len(rows), 1, figsize=(8, 2.6 * len(rows)), sharex=True)
    labels = [f"{m} {d}" for m, d in result.paths]
    for a, (p, d) in zip(axes[:, 0], rows):
        pc = result.path_contributions(p, d, order) * 1e3          # (n_rpm, n_paths)
        total = pc.sum(axis=1)
        mag = np.abs(total)
        unit = np.where(mag > 0, np.conj(total) / np.where(mag > 0, mag, 1.0), 0.0)
        inphase = (pc * unit[:, None]).real
        if not mag.max(initial=0.0) > 1e-9:        # [mm/s]: no response in this direction
            a.set_title(f"{p} {d.upper()} — order {order:g}", fontsize=8)
            no_data(a, "no response in this direction (zero at every speed)")
            continue
        top = np.argsort(np.abs(inphase).max(axis=0))[::-1][:n_paths]
        for j in top:   # one colour per path in every panel: one legend for the figure
            a.plot(result.rpm, inphase[:, j], "o-", ms=3, lw=1.1, color=f"C{j % 10}",
                   label=labels[j])
        a.plot(result.rpm, mag, "k-", lw=2, label="total |v|")
        a.axhline(0.0, color="0.5", lw=0.6)
        a.set_title(f"{p} {d.upper()} — order {order:g}: path contributions in phase "
                    "with the total", fontsize=8)
        a.set_ylabel("velocity [mm/s]", fontsize=7)
        a.grid(True, alpha=0.3)
        a.tick_params(labelsize=6)
    axes[-1, 0].set_xlabel("engine speed [rpm]", fontsize=8)
    if own:
        figure_legend(fig, axes)
    return finish(fig, own, path, provenance)
