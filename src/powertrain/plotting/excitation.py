"""Excitation figure: pressures, crank torque, load on the powertrain and its order spectrum
over one engine cycle."""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    TICK_SIZE,
    finish,
    subplots,
)

LOAD_NAMES = ["Fx [N]", "Fy [N]", "Fz [N]", "Mx [N·m]", "My [N·m]", "Mz [N·m]"]


def plot_excitation(exc, path=None, *, ax=None, provenance=None):
    """Summary figure of an :class:`~powertrain.models.engine.Excitation` over one cycle.

    Four panels against the crank angle of cylinder 1 [deg]: cylinder pressures [bar];
    per-cylinder crank torque [N·m]; total forces [N] and moments [N·m] on the powertrain
    about its CG (engine axes); and the order spectrum (0.5..8) of the load components.

    Parameters
    ----------
    exc : Excitation
    path : str, optional
        PNG file to write.
    ax : None, Figure or SubFigure
        Where to draw the four panels.
    provenance : Provenance, optional
        Foot line of a new figure.

    Returns
    -------
    matplotlib Figure (or SubFigure)
    """
    deg = np.degrees(exc.crank_angle)
    fig, axes, own = subplots(ax, 2, 2, figsize=(11, 7.8))
    a = axes[0, 0]
    for i in range(exc.pressure.shape[1]):
        a.plot(deg, exc.pressure[:, i] / 1e5, label=f"cylinder {i + 1}")
    a.set_ylabel("cylinder pressure [bar]", fontsize=LABEL_SIZE)
    a.legend(fontsize=LEGEND_SIZE)
    a = axes[0, 1]
    for i in range(exc.torque.shape[1]):
        a.plot(deg, exc.torque[:, i], lw=0.8, label=f"cylinder {i + 1}")
    a.plot(deg, exc.torque.sum(axis=1), "k", lw=1.2, label="sum")
    a.set_ylabel("crank torque [N·m]", fontsize=LABEL_SIZE)
    a.legend(fontsize=LEGEND_SIZE, ncol=2)
    a = axes[1, 0]
    for j in range(3):
        a.plot(deg, exc.load[:, j], label=LOAD_NAMES[j])
    for j in range(3, 6):
        a.plot(deg, exc.load[:, j], "--", label=LOAD_NAMES[j])
    a.set_ylabel("load on the powertrain about its CG", fontsize=LABEL_SIZE)
    a.legend(fontsize=LEGEND_SIZE, ncol=2)
    for a in (axes[0, 0], axes[0, 1], axes[1, 0]):
        a.set_xlabel("crank angle of cylinder 1 [deg]", fontsize=LABEL_SIZE)
        a.set_xlim(0, 720)
        a.set_xticks(np.arange(0, 721, 90))
        a.grid(True, alpha=0.3)
        a.tick_params(labelsize=TICK_SIZE)
    _spectrum(axes[1, 1], exc)
    return finish(fig, own, path, provenance,
                  title=f"Excitation at {exc.rpm:g} rpm" if own else None)


def _spectrum(ax, exc):
    """Order amplitudes of the six load components as grouped bars."""
    orders, amp = exc.order_spectrum(8.0)
    width = 0.5 / 7
    for j, name in enumerate(LOAD_NAMES):
        a = np.abs(amp[1:, j])
        ax.bar(orders[1:] + (j - 2.5) * width, np.where(a > 0, a, np.nan), width=width,
               label=name)
    ax.set_xlabel("engine order", fontsize=LABEL_SIZE)
    ax.set_ylabel("amplitude [N or N·m]", fontsize=LABEL_SIZE)
    ax.set_xticks(np.arange(1, 8.01, 1.0))
    ax.set_xticks(np.arange(0.5, 8.01, 0.5), minor=True)
    ax.tick_params(labelsize=TICK_SIZE)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=LEGEND_SIZE, ncol=2)
