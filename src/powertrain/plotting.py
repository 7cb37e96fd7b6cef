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
