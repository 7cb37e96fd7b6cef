"""All plotting. matplotlib is imported lazily here and nowhere else."""

from __future__ import annotations


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(fig, path):
    """Save atomically (no half-written PNG on failure)."""
    from powertrain.iotools.atomic import atomic_path
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    _pyplot().close(fig)


def plot_stiffness(curves, path=None, measured=None, ax=None):
    """Real and imaginary part of K*(f) [N/mm] for one or more stiffness tables.

    Parameters
    ----------
    curves : list of (label, StiffnessTable)
    measured : (frequency_hz, kcp [N/m]) or None
    """
    plt = _pyplot()
    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 4.5))
    if measured is not None:
        f, k = measured
        ax.plot(f, k.real / 1e3, "k.", ms=3, label="measured, real")
        ax.plot(f, k.imag / 1e3, ".", color="0.5", ms=3, label="measured, imaginary")
    for label, t in curves:
        line, = ax.plot(t.frequency_hz, t.kcp.real / 1e3, "-", label=f"{label}, real")
        ax.plot(t.frequency_hz, t.kcp.imag / 1e3, "--", color=line.get_color(),
                label=f"{label}, imaginary")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("cross-point dynamic stiffness [N/mm]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    if fig is not None and path:
        fig.tight_layout()
        save_figure(fig, path)
    return ax


def plot_runup(results, path=None, quantities=("synthesis", "order_2", "order_4"),
               signal="velocity"):
    """Grid of RMS curves: rows = mount × direction, columns = ``quantities``.

    Parameters
    ----------
    results : list of (label, RunupResult)
    """
    plt = _pyplot()
    first = results[0][1]
    rows = first.channels
    fig, axes = plt.subplots(len(rows), len(quantities), figsize=(4 * len(quantities),
                             1.9 * len(rows)), sharex=True, squeeze=False)
    scale = {"velocity": (1e3, "mm/s"), "displacement": (1e6, "µm"),
             "acceleration": (1.0, "m/s²"), "mount_force": (1.0, "N")}[signal]
    for r, (mount, direction) in enumerate(rows):
        for q, quantity in enumerate(quantities):
            ax = axes[r, q]
            for label, res in results:
                if (mount, direction) not in res.channels:
                    continue
                ax.semilogy(res.rpm, res.curve(mount, direction, quantity, signal) * scale[0],
                            "o-", ms=3, lw=1.2, label=label)
            title = "synthesis (orders ≤ 8)" if quantity == "synthesis" else \
                quantity.replace("order_", "order ")
            ax.set_title(f"{mount} {direction.upper()} — {title}", fontsize=8)
            ax.grid(True, which="both", alpha=0.3)
            ax.tick_params(labelsize=7)
            if q == 0:
                ax.set_ylabel(f"RMS {signal} [{scale[1]}]", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("engine speed [rpm]", fontsize=8)
    if len(results) > 1:
        axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig


def plot_excitation(exc, path=None):
    """Summary figure of an :class:`~powertrain.models.engine.Excitation` over one cycle.

    Four panels against the crank angle of cylinder 1 [deg]: cylinder pressures [bar];
    per-cylinder crank torque [N·m]; total forces [N] and moments [N·m] on the powertrain
    about its CG (engine axes); and the order spectrum (0.5..8) of the load components.

    Parameters
    ----------
    exc : Excitation
    path : str, optional
        PNG file to write.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import numpy as np
    plt = _pyplot()
    deg = np.degrees(exc.crank_angle)
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    ax = axes[0, 0]
    for i in range(exc.pressure.shape[1]):
        ax.plot(deg, exc.pressure[:, i] / 1e5, label=f"cylinder {i + 1}")
    ax.set_ylabel("cylinder pressure [bar]")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for i in range(exc.torque.shape[1]):
        ax.plot(deg, exc.torque[:, i], lw=0.8, label=f"cylinder {i + 1}")
    ax.plot(deg, exc.torque.sum(axis=1), "k", lw=1.2, label="sum")
    ax.set_ylabel("crank torque [N·m]")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    for j, name in enumerate(["Fx [N]", "Fy [N]", "Fz [N]"]):
        ax.plot(deg, exc.load[:, j], label=name)
    for j, name in enumerate(["Mx [N·m]", "My [N·m]", "Mz [N·m]"]):
        ax.plot(deg, exc.load[:, 3 + j], "--", label=name)
    ax.set_ylabel("load on the powertrain about its CG")
    ax.legend(fontsize=8, ncol=2)
    for a in (axes[0, 0], axes[0, 1], axes[1, 0]):
        a.set_xlabel("crank angle of cylinder 1 [deg]")
        a.set_xlim(0, 720)
        a.set_xticks(np.arange(0, 721, 90))
        a.grid(True, alpha=0.3)
    ax = axes[1, 1]
    orders, amp = exc.order_spectrum(8.0)
    names = ["Fx [N]", "Fy [N]", "Fz [N]", "Mx [N·m]", "My [N·m]", "Mz [N·m]"]
    width = 0.5 / 7
    for j, name in enumerate(names):
        ax.bar(orders[1:] + (j - 2.5) * width, np.abs(amp[1:, j]), width=width, label=name)
    ax.set_xlabel("engine order")
    ax.set_ylabel("amplitude [N or N·m]")
    ax.set_xticks(np.arange(0.5, 8.01, 0.5))
    ax.tick_params(axis="x", labelsize=7)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.suptitle(f"Excitation at {exc.rpm:g} rpm")
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig
