"""All plotting. matplotlib is imported lazily here and nowhere else."""

from __future__ import annotations

#: Display factor and unit of each run-up signal (SI -> plot unit).
SIGNAL_UNITS = {"velocity": (1e3, "mm/s"), "displacement": (1e6, "µm"),
                "acceleration": (1.0, "m/s²"), "mount_force": (1.0, "N")}


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
    scale = SIGNAL_UNITS[signal]
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
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(which="both", labelsize=6)
            if q == 0:
                ax.set_ylabel(f"RMS {signal} [{scale[1]}]", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("engine speed [rpm]", fontsize=8)
    if len(results) > 1:
        axes[0, 0].legend(fontsize=7)
    # fixed margins: tight_layout on 27 log axes costs seconds of tick layout
    fig.subplots_adjust(left=0.08, right=0.99, bottom=0.04, top=0.98, hspace=0.45, wspace=0.25)
    if path:
        save_figure(fig, path)
    return fig


def plot_comparison(comparison, path=None, quantities=("synthesis", "order_2", "order_4")):
    """Measured and simulated RMS velocity against speed, level gap shaded.

    The thesis's layout (Kovarik 2016, Figs 45-71): one row per mount and direction, one
    column per quantity (synthesis, 2nd and 4th order), log-scaled velocity [mm/s]. The
    measured curve is a thin black line, the simulation markers at its speeds joined by
    straight lines (on the log axis these are exactly the log-level interpolation used for the
    gaps); the gap at the compared speeds is shaded red where the simulation is higher, green
    where it is lower. Points excluded at the noise floor are grey crosses, the exclusion
    limit a dotted line. Channel titles give the RMS gap and bias [dB].

    Parameters
    ----------
    comparison : ComparisonResult
    path : str or Path, optional
        PNG file written atomically.
    quantities : sequence of str
        Columns.
    """
    import numpy as np
    from matplotlib.lines import Line2D
    from matplotlib.ticker import NullFormatter

    from powertrain.analysis.compare import NOISE_FLOOR_MARGIN
    plt = _pyplot()
    sim = comparison.simulated
    rows = list(sim.channels)
    rows += [c for c in comparison.measured.channels if c not in rows]
    fig, axes = plt.subplots(len(rows), len(quantities),
                             figsize=(4.3 * len(quantities), 1.75 * len(rows) + 0.8),
                             sharex=True, squeeze=False)
    mm = 1e3
    limit = NOISE_FLOOR_MARGIN * comparison.noise_floor * mm
    compared = {(c.mount, c.direction, c.quantity): c for c in comparison.channels}
    for r, (mount, direction) in enumerate(rows):
        for q, quantity in enumerate(quantities):
            ax = axes[r, q]
            key = (mount, direction, quantity)
            title = "synthesis (orders ≤ 8)" if quantity == "synthesis" else \
                quantity.replace("order_", "order ")
            c = compared.get(key)
            if key in comparison.measured.curves:
                rm, vm = comparison.measured.curves[key]
                ax.plot(rm, vm * mm, "-", color="k", lw=0.9, label="measured")
            if key in sim.curves:
                rs, vs = sim.curves[key]
                pos = vs > 0
                ax.plot(rs[pos], vs[pos] * mm, "o-", color="C0", ms=3, lw=1.2,
                        label="simulated")
            if c is not None:
                s = np.where(c.scored, c.simulated, np.nan) * mm
                m = np.where(c.scored, c.measured, np.nan) * mm
                ax.fill_between(c.rpm, m, s, where=c.scored & (s >= m), interpolate=True,
                                color="C3", alpha=0.3, lw=0, label="sim > measured")
                ax.fill_between(c.rpm, m, s, where=c.scored & (s < m), interpolate=True,
                                color="C2", alpha=0.35, lw=0, label="sim < measured")
                if c.at_floor.any():
                    ax.plot(c.rpm[c.at_floor], np.maximum(c.measured[c.at_floor] * mm,
                                                          limit * 0.5),
                            "x", color="0.55", ms=3, label="excluded (noise floor)")
                title += (f"   ΔL rms {c.stats['rms_db']:.1f} dB, "
                          f"bias {c.stats['bias_db']:+.1f} dB")
            else:
                ax.text(0.5, 0.5, "not compared", transform=ax.transAxes, ha="center",
                        va="center", fontsize=8, color="0.4")
            ax.set_yscale("log")
            vals = [v for k in (key,) for src_ in (comparison.measured.curves, sim.curves)
                    if k in src_ for v in src_[k][1] * mm if v > 0]
            if vals:
                # at least one decade, so that a labelled power of ten is always visible
                lo, hi = min(vals) / 1.6, max(vals) * 1.6
                if hi / lo < 10:
                    mid = np.sqrt(lo * hi)
                    lo, hi = mid / np.sqrt(10), mid * np.sqrt(10)
                lo = max(lo, limit / 2) if limit > 0 and limit < hi / 10 else lo
                ax.set_ylim(lo, hi)
                if limit > 0 and lo < limit < hi:
                    ax.axhline(limit, color="0.5", ls=":", lw=0.8)
            ax.yaxis.set_minor_formatter(NullFormatter())
            ax.set_title(f"{mount} {direction.upper()} — {title}", fontsize=7.5)
            ax.grid(True, which="both", alpha=0.25)
            ax.tick_params(labelsize=7)
            if q == 0:
                ax.set_ylabel("RMS velocity [mm/s]", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("engine speed [rpm]", fontsize=8)
    handles, labels = {}, []
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in handles:
                handles[lab] = h
                labels.append(lab)
    labels.append(f"noise-floor limit ({limit:g} mm/s)")
    handles[labels[-1]] = Line2D([], [], color="0.5", ls=":", lw=0.8)
    from pathlib import Path
    src = Path(comparison.measured.source).name
    tag = "SYNTHETIC measurement" if comparison.measured.synthetic else "measurement"
    fig.suptitle(f"{tag}: {src}   overall RMS gap {comparison.overall_rms_db:.2f} dB "
                 "(gap = 20 log10(sim/measured))", fontsize=9)
    fig.legend([handles[lab] for lab in labels], labels, loc="upper center", ncol=len(labels),
               fontsize=8, bbox_to_anchor=(0.5, 1 - 0.35 / fig.get_figheight()),
               frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.7 / fig.get_figheight()))
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


def plot_mount_fit(frequency_hz, kcp_measured, kcp_fitted, *, label="fit", title=None,
                   ax=None, path=None):
    """Measured (dots) and fitted (lines) real and imaginary K*(f) [N/mm].

    The presentation of Kovarik (2016), Figs. 15–29 and 37–42.

    Parameters
    ----------
    frequency_hz : ndarray
        [Hz]
    kcp_measured, kcp_fitted : ndarray of complex
        Cross-point dynamic stiffness [N/m].
    label : str
        Legend label of the fitted curves.
    title : str, optional
    ax : matplotlib Axes, optional
        Draw into it; otherwise a new figure is made (and saved when ``path`` is given).
    path : str, optional
        PNG file, written atomically.

    Returns
    -------
    matplotlib Axes
    """
    import numpy as np
    plt = _pyplot()
    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 4.5))
    f = np.asarray(frequency_hz)
    km = np.asarray(kcp_measured) / 1e3
    kf = np.asarray(kcp_fitted) / 1e3
    ax.plot(f, km.real, "k.", ms=3, label="measured, real")
    ax.plot(f, km.imag, ".", color="0.5", ms=3, label="measured, imaginary")
    line, = ax.plot(f, kf.real, "-", label=f"{label}, real")
    ax.plot(f, kf.imag, "--", color=line.get_color(), label=f"{label}, imaginary")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("cross-point dynamic stiffness [N/mm]")
    if title:
        ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    if fig is not None and path:
        fig.tight_layout()
        save_figure(fig, path)
    return ax


def plot_whatif(whatif, path=None):
    """Baseline, variants and measurement overlaid: RMS velocity [mm/s] (or the signal of
    ``whatif.signal``) against speed.

    One row per mount and direction, one column per quantity of ``whatif.quantities``
    (synthesis, 2nd and 4th order by default); the baseline black, each variant in colour
    with its mean change [dB] in the legend of the first row, the measurement (when given)
    as grey dots.

    Parameters
    ----------
    whatif : powertrain.whatif.WhatIfResult
    path : str, optional
        PNG written atomically.
    """
    import numpy as np
    plt = _pyplot()
    base = whatif.baseline
    signal = getattr(whatif, "signal", "velocity")
    scale, unit = SIGNAL_UNITS[signal]
    rows = base.channels
    quantities = whatif.quantities
    fig, axes = plt.subplots(len(rows), len(quantities),
                             figsize=(4 * len(quantities), 1.9 * len(rows)),
                             sharex=True, squeeze=False)
    for r, (mount, direction) in enumerate(rows):
        for q, quantity in enumerate(quantities):
            ax = axes[r, q]
            if whatif.measured is not None and signal == "velocity":
                try:
                    rpm_m, lev_m = whatif.measured.curve(mount, direction, quantity)
                    ax.semilogy(rpm_m, lev_m * 1e3, ".", color="0.55", ms=3,
                                label="measured")
                except KeyError:
                    pass
            ax.semilogy(base.rpm, base.curve(mount, direction, quantity, signal) * scale, "k-", lw=1.6,
                        label="baseline")
            for v in whatif.variants:
                d = whatif.delta_db(v.name, mount, direction, quantity)
                mean = float(np.nanmean(d)) if np.isfinite(d).any() else float("nan")
                ax.semilogy(v.result.rpm, v.result.curve(mount, direction, quantity, signal) * scale,
                            "o-", ms=2.5, lw=1.1, label=f"{v.name} ({mean:+.2f} dB)")
            title = "synthesis (orders ≤ 8)" if quantity == "synthesis" else \
                quantity.replace("order_", "order ")
            ax.set_title(f"{mount} {direction.upper()} — {title}", fontsize=8)
            ax.grid(True, which="both", alpha=0.3)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=5.5, loc="best")
            if q == 0:
                ax.set_ylabel(f"RMS {signal.replace('_', ' ')} [{unit}]", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("engine speed [rpm]", fontsize=8)
    fig.suptitle("what-if: baseline vs variants (legend: mean change over the speed steps)",
                 fontsize=9)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig


def plot_retune(target_fit, path=None):
    """Baseline, requested and fitted K_CP of a retune target: |K| [N/mm] and phase [deg].

    Parameters
    ----------
    target_fit : powertrain.retune.TargetFit
    path : str, optional
        PNG written atomically.
    """
    import numpy as np
    plt = _pyplot()
    tf = target_fit
    f = tf.frequency_hz[1:]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, style, label in ((tf.kcp_baseline, "k-", "baseline"),
                            (tf.kcp_target, "C1--", "requested"),
                            (tf.kcp_fitted, "C0-", f"fitted {tf.model.topology.name}")):
        ax1.loglog(f, np.abs(k[1:]) / 1e3, style, lw=1.3, label=label)
        ax2.semilogx(f, np.degrees(np.angle(k[1:])), style, lw=1.3, label=label)
    for ax in (ax1, ax2):
        ax.axvspan(tf.target.f_lo, tf.target.f_hi, color="0.9", zorder=0)
        ax.grid(True, which="both", alpha=0.3)
    ax1.set_ylabel("|K_CP| [N/mm]")
    ax2.set_ylabel("loss angle [deg]")
    ax2.set_xlabel("frequency [Hz]")
    ax1.legend(fontsize=8)
    ax1.set_title(f"{tf.target.spec}: max error in band {100 * tf.max_band_error:.1f} %, "
                  f"mean change {100 * tf.mean_band_change:+.1f} %", fontsize=9)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig


# ---------------------------------------------------------------------------- diagnosis
def plot_gap_map(diagnosis, path=None):
    """Gap map of a :class:`powertrain.diagnosis.DiagnosisResult`: one panel per quantity,
    channels against speed, colour = gap 20 log10(sim/measured) [dB] (±6 dB scale), the
    ±3 dB regions outlined."""
    import numpy as np
    plt = _pyplot()
    d = diagnosis.data
    nq = len(d.quantities)
    ncol = min(3, nq)
    nrow = int(np.ceil(nq / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 2.6 * nrow + 0.6), squeeze=False,
                             sharex=True, sharey=True)
    im = None
    for k, q in enumerate(d.quantities):
        ax = axes.flat[k]
        g = diagnosis.gap[:, :, k].T
        im = ax.pcolormesh(d.rpm, np.arange(len(d.channels)), np.ma.masked_invalid(g),
                           cmap="RdBu_r", vmin=-6, vmax=6, shading="nearest")
        if np.isfinite(g).any() and np.nanmax(np.abs(g)) > 3:
            ax.contour(d.rpm, np.arange(len(d.channels)), np.nan_to_num(np.abs(g)), [3.0],
                       colors="k", linewidths=0.6)
        ax.set_title(q, fontsize=9)
        ax.set_yticks(range(len(d.channels)))
        ax.set_yticklabels([f"{m} {a}" for m, a in d.channels], fontsize=7)
    for ax in axes.flat[nq:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("speed [rpm]")
    if im is not None:
        fig.colorbar(im, ax=axes.ravel().tolist(), label="gap sim/measured [dB]", shrink=0.8)
    fig.suptitle(f"gap map (baseline): {diagnosis.verdict_text[:110]}", fontsize=8)
    if path:
        save_figure(fig, path)
    return fig


def plot_gap_frequency(diagnosis, path=None):
    """Order gaps re-plotted against frequency f = order·rpm/60 [Hz] per channel (left; a
    structural cause lines up across orders at one frequency) and against speed per order
    (right; an excitation cause lines up at one order), with the fitted smooth parts."""
    import numpy as np
    plt = _pyplot()
    d = diagnosis.data
    p = diagnosis.parts
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.5))
    qs = np.flatnonzero(d.order_mask)
    for j, k in enumerate(qs):
        o = (d.harmonic[k] + 1) / 2.0
        f = o * d.rpm / 60.0
        g = diagnosis.gap[:, :, k]
        for c in range(len(d.channels)):
            a1.plot(f, g[:, c], ".", ms=1.5, color=f"C{j % 10}",
                    label=d.quantities[k] if c == 0 else None)
        n_ok = np.isfinite(g).sum(axis=1)
        mean = np.where(n_ok > 0, np.nansum(g, axis=1) / np.maximum(n_ok, 1), np.nan)
        a2.plot(d.rpm, mean, "-", color=f"C{j % 10}", lw=1,
                label=f"{d.quantities[k]} (mean over channels)")
    sc = p["structure_curves"]
    for c, row in enumerate(sc["by_channel"]):
        a1.plot(sc["frequency_hz"], np.array(row) + p["channel_const_db"][c], "k-", lw=0.6,
                alpha=0.6, label="fitted dH_channel(f) + g_channel" if c == 0 else None)
    ec = p["excitation_curves"]
    for row in ec["by_quantity"]:
        a2.plot(ec["rpm"], row, "--", color="k", lw=0.6, alpha=0.6)
    a1.set_xscale("log")
    a1.set_xlabel("frequency = order x rpm / 60 [Hz]")
    a2.set_xlabel("speed [rpm]")
    for ax in (a1, a2):
        ax.set_ylabel("gap [dB]")
        ax.axhline(0, color="0.5", lw=0.5)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, markerscale=4)
    s = p["share_alone"]
    fig.suptitle(f"structure {s['structure']:.0%}, excitation {s['excitation']:.0%}, channel "
                 f"constant {s['const']:.0%} of the gap's sum of squares (each alone)",
                 fontsize=9)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig


def plot_diagnosis_overlay(diagnosis, path=None, n_panels=6):
    """Measured vs baseline vs baseline + chosen effect for the channel-quantities with the
    largest baseline gaps; held-out speeds marked."""
    import numpy as np
    plt = _pyplot()
    d = diagnosis.data
    g = diagnosis.gap
    score = []
    for c in range(len(d.channels)):
        for k in np.flatnonzero(d.order_mask):
            v = g[:, c, k]
            if np.isfinite(v).sum() > 2:
                score.append((float(np.sqrt(np.nanmean(v ** 2))), c, k))
    score.sort(reverse=True)
    score = score[:n_panels]
    ncol = 3
    nrow = max(1, int(np.ceil(len(score) / ncol)))
    fig, axes = plt.subplots(nrow, ncol, figsize=(13, 3.2 * nrow), squeeze=False)
    held = np.isin(d.rpm, diagnosis.split["heldout_rpm"])
    for ax, (_, c, k) in zip(axes.flat, score):
        m = d.level[:, c, k] * 1e3
        sim0 = m * 10 ** (g[:, c, k] / 20)
        ax.semilogy(d.rpm, m, "k.", ms=2, label="measured")
        ax.semilogy(d.rpm[held], m[held], "o", mfc="none", mec="0.6", ms=3,
                    label="held-out speeds")
        ax.semilogy(d.rpm, sim0, "C3-", lw=1, label="baseline")
        if diagnosis.gap_after is not None:
            ax.semilogy(d.rpm, m * 10 ** (diagnosis.gap_after[:, c, k] / 20), "C0-", lw=1,
                        label=f"+ {diagnosis.chosen.label}")
        mnt, dr = d.channels[c]
        ax.set_title(f"{mnt} {dr} {d.quantities[k]}", fontsize=9)
        ax.set_xlabel("speed [rpm]")
        ax.set_ylabel("velocity RMS [mm/s]")
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes.flat[len(score):]:
        ax.set_visible(False)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle(f"before / after / measured: {diagnosis.verdict_text[:120]}", fontsize=8)
    fig.tight_layout()
    if path:
        save_figure(fig, path)
    return fig
