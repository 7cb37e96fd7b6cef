"""Figures of the mounting system: modes, both sides of each mount, path contributions.

matplotlib comes through :mod:`powertrain.plotting` (imported lazily there only).
"""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import finish, subplots

_COLOURS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green", "rx": "tab:red",
            "ry": "tab:purple", "rz": "tab:brown"}


def plot_modes(result, path=None, ax=None, provenance=None):
    """Kinetic-energy distribution of each mode as stacked bars, labelled with frequency,
    damping ratio and the angle of its rotation axis to the torque-roll axis; returns the
    figure (``ax``: None, an Axes, Figure or SubFigure)."""
    from powertrain.solvers.modes import COORDINATES
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
