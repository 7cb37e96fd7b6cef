"""Excitation figure: pressures, crank torque, load on the powertrain and its order spectrum
over one engine cycle."""

from __future__ import annotations

import numpy as np

from powertrain.plotting.style import (
    LABEL_SIZE,
    OKABE_ITO,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    finish,
    is_axes,
    legend,
    subplots,
)

#: Legend label of the x, y and z component (one colour each in every load panel).
COMPONENTS = ("x: Fx, Mx", "y: Fy, My", "z: Fz, Mz")
#: Colours of the components, apart from the cylinders'.
_COMPONENT_COLOURS = (OKABE_ITO["reddish purple"], OKABE_ITO["sky blue"], "0.3")


def plot_excitation(exc, path=None, *, ax=None, provenance=None):
    """Summary figure of an :class:`~powertrain.models.engine.Excitation` over one cycle.

    Cylinder pressures [bar] and crank torques [N·m] against cylinder 1's crank angle
    [deg]; forces [N] and moments [N·m] about the CG (engine axes); their order spectra.

    Parameters
    ----------
    exc : Excitation
    path : str, optional
        PNG file to write.
    ax : None, Figure or SubFigure
        Where to draw the six panels.
    provenance : Provenance, optional
        Foot line of a new figure.
    """
    deg = np.degrees(exc.crank_angle)
    fig, axes, own = subplots(ax, 3, 2, figsize=(PRINT_WIDTH_IN, 8.6))
    for i in range(exc.pressure.shape[1]):
        axes[0, 0].plot(deg, exc.pressure[:, i] / 1e5, color=colour(i), lw=1.1, label=f"cylinder {i + 1}")
        axes[0, 1].plot(deg, exc.torque[:, i], color=colour(i), lw=0.8)
    axes[0, 1].plot(deg, exc.torque.sum(axis=1), "k", lw=1.4, label="sum of the cylinders")
    axes[0, 0].set_ylabel("cylinder pressure [bar]", fontsize=LABEL_SIZE)
    axes[0, 1].set_ylabel("crank torque [N·m]", fontsize=LABEL_SIZE)
    for j in range(3):
        axes[1, 0].plot(deg, exc.load[:, j], color=_COMPONENT_COLOURS[j], lw=1.1, label=COMPONENTS[j])
        axes[1, 1].plot(deg, exc.load[:, j + 3], color=_COMPONENT_COLOURS[j], lw=1.1)
    axes[1, 0].set_ylabel("force on the powertrain [N]", fontsize=LABEL_SIZE)
    axes[1, 1].set_ylabel("moment about the CG [N·m]", fontsize=LABEL_SIZE)
    for a in axes[:2].flat:
        a.set_xlabel("crank angle of cylinder 1 [deg]", fontsize=LABEL_SIZE)
        a.set_xlim(0, 720)
        a.set_xticks(np.arange(0, 721, 180))
        a.grid(True, alpha=0.3)
        a.tick_params(labelsize=TICK_SIZE)
    _spectrum(axes[2], exc)
    legend(fig, axes, ax)
    return finish(fig, own, path, provenance,
                  title=f"Excitation at {exc.rpm:g} rpm" if not is_axes(ax) else None)


def _spectrum(axes, exc):
    """Order amplitudes of the forces (left) and moments (right) as grouped bars."""
    orders, amp = exc.order_spectrum(8.0)
    width = 0.12
    for a, first, unit in ((axes[0], 0, "N"), (axes[1], 3, "N·m")):
        for j in range(3):
            v = np.abs(amp[1:, first + j])
            a.bar(orders[1:] + (j - 1) * width, np.where(v > 0, v, np.nan), width=width,
                  color=_COMPONENT_COLOURS[j])
        a.set_title(f"order spectrum of the {'forces' if first == 0 else 'moments'}", fontsize=TITLE_SIZE)
        a.set_xlabel("engine order", fontsize=LABEL_SIZE)
        a.set_ylabel(f"amplitude [{unit}]", fontsize=LABEL_SIZE)
        a.set_xticks(np.arange(1, 8.01, 1.0))
        a.set_xticks(np.arange(0.5, 8.01, 0.5), minor=True)
        a.tick_params(labelsize=TICK_SIZE)
        a.grid(True, axis="y", alpha=0.3)
