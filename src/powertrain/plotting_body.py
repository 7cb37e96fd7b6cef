"""Figures of the mounting system: modes, both sides of each mount, path contributions.

matplotlib comes through :mod:`powertrain.plotting` (imported lazily there only).
"""

from __future__ import annotations

import numpy as np

from powertrain.plotting import _pyplot, save_figure

_COLOURS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green", "rx": "tab:red",
            "ry": "tab:purple", "rz": "tab:brown"}


def plot_modes(result, path=None, ax=None):
    """Kinetic-energy distribution of each mode as stacked bars, labelled with frequency,
    damping ratio and the angle of its rotation axis to the torque-roll axis."""
    from powertrain.solvers.modes import COORDINATES
    plt = _pyplot()
    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(9, 4.8))
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
    ax.legend(ncol=6, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.28))
    ax.set_title(f"{result.engine} — {result.method.split(':')[0]} modes", fontsize=9)
    if fig is not None:
        fig.tight_layout()
        if path:
            save_figure(fig, path)
    return ax


def _positive(values):
    """Mask non-positive values (a log axis cannot show an exact zero)."""
    return np.ma.masked_less_equal(np.asarray(values, float), 0.0)


def plot_runup_both_sides(result, path=None, quantities=("synthesis", "order_2", "order_4"),
                          signal="velocity"):
    """Run-up curves with a body model: one panel per mount and direction holding the
    engine side (solid) and the body side (dashed), then one per body-point direction;
    columns = ``quantities``; log-scaled RMS [mm/s for velocity]."""
    from powertrain.models.chassis import passive_name
    from powertrain.plotting import SIGNAL_UNITS
    plt = _pyplot()
    rows = [(m, d, True) for m in result.mounts for d in "xyz"]
    rows += [(p, d, False) for p in result.points for d in "xyz"]
    fig, axes = plt.subplots(len(rows), len(quantities), figsize=(4 * len(quantities),
                             1.9 * len(rows)), sharex=True, squeeze=False)
    factor, unit = SIGNAL_UNITS[signal]
    for r, (name, d, is_mount) in enumerate(rows):
        for q, quantity in enumerate(quantities):
            ax = axes[r, q]
            y = result.curve(name, d, quantity, signal) * factor
            label = "engine side" if is_mount else "body point"
            ax.semilogy(result.rpm, _positive(y), "o-", ms=3, lw=1.2, color="tab:blue",
                        label=label)
            if is_mount:
                yb = result.curve(passive_name(name), d, quantity, signal) * factor
                ax.semilogy(result.rpm, _positive(yb), "s--", ms=3, lw=1.2,
                            color="tab:red", label="body side")
            title = "synthesis" if quantity == "synthesis" else quantity.replace("_", " ")
            ax.set_title(f"{name} {d.upper()} — {title}", fontsize=8)
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(which="both", labelsize=6)
            if q == 0:
                ax.set_ylabel(f"RMS {signal.replace('_', ' ')} [{unit}]", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("engine speed [rpm]", fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.subplots_adjust(left=0.08, right=0.99, bottom=0.04, top=0.98, hspace=0.45, wspace=0.25)
    if path:
        save_figure(fig, path)
    return fig


def plot_path_contributions(result, path=None, order=2.0, n_paths=6):
    """Transfer-path view of every body-point direction at one order: the part of each
    path's velocity in phase with the total, Re(v_path·conj(v)/|v|) [mm/s] (these add up to
    |v|), for the ``n_paths`` largest paths, and the total |v| (black)."""
    plt = _pyplot()
    rows = [(p, d) for p in result.points for d in "xyz"]
    fig, axes = plt.subplots(len(rows), 1, figsize=(8, 2.4 * len(rows)), sharex=True,
                             squeeze=False)
    labels = [f"{m} {d}" for m, d in result.paths]
    for ax, (p, d) in zip(axes[:, 0], rows):
        pc = result.path_contributions(p, d, order) * 1e3          # (n_rpm, n_paths)
        total = pc.sum(axis=1)
        unit = np.where(np.abs(total) > 0, np.conj(total) / np.maximum(np.abs(total), 1e-300),
                        0.0)
        inphase = (pc * unit[:, None]).real
        top = np.argsort(np.abs(inphase).max(axis=0))[::-1][:n_paths]
        for j in top:
            ax.plot(result.rpm, inphase[:, j], "o-", ms=3, lw=1.1, label=labels[j])
        ax.plot(result.rpm, np.abs(total), "k-", lw=2, label="total |v|")
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.set_title(f"{p} {d.upper()} — order {order:g}: path contributions in phase "
                     "with the total", fontsize=8)
        ax.set_ylabel("velocity [mm/s]", fontsize=7)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=6)
        ax.legend(fontsize=6, ncol=4)
    axes[-1, 0].set_xlabel("engine speed [rpm]", fontsize=8)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig
