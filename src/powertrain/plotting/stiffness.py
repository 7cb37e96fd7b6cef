"""Dynamic-stiffness figures K*(f): mount models, measured-vs-fitted, retune targets.

Forms: ``real-imag``, real and imaginary part [N/mm] in one panel (Kovarik 2016 Figs
15–29); ``magnitude-phase``, |K*| [N/mm] above the loss angle [deg] (ISO 10846).
"""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.plotting.style import (
    LABEL_SIZE,
    LEGEND_SIZE,
    PRINT_WIDTH_IN,
    TICK_SIZE,
    TITLE_SIZE,
    colour,
    finish,
    log_axis,
    root_size,
    subplots,
    wrap,
)

FORMS = ("magnitude-phase", "real-imag")
FREQ_AXES = ("log", "linear")
#: Defaults: the datasheet form (ISO 10846) over log frequency.
DEFAULT_FORM, DEFAULT_FREQ_AXIS = "magnitude-phase", "log"


def stiffness_axes(ax, form, figsize=(PRINT_WIDTH_IN, 5.2)):
    """Figure and axes of a stiffness plot of ``form`` and ``figsize`` [in]: one Axes
    (``real-imag``) or two (``magnitude-phase``; ``ax`` may be a pair)."""
    if form not in FORMS:
        raise InputError(f"{form!r} is not one of {', '.join(map(repr, FORMS))}", key="--form")
    if form == "magnitude-phase" and isinstance(ax, (list, tuple)) and len(ax) == 2:
        return ax[0].figure, list(ax), False
    if form == "real-imag":
        fig, axes, own = subplots(ax, 1, 1, figsize=(figsize[0], figsize[1] * 0.8))
        return fig, [axes[0, 0]], own
    fig, axes, own = subplots(ax, 2, 1, figsize=figsize, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    return fig, list(axes[:, 0]), own


def draw_stiffness(axes, f, kcp, form, *, label, style="-", color=None, marker=None,
                   freq_axis=DEFAULT_FREQ_AXIS):
    """Draw ``kcp`` [N/m] at ``f`` [Hz] into ``axes`` in ``form``: data as ``marker``, models
    as lines (``style``; imaginary dashed), on ``freq_axis``, with ``label``, ``color``."""
    f, k = np.asarray(f, dtype=float), np.asarray(kcp) / 1e3
    if freq_axis == "log":
        ok = f > 0
        f, k = f[ok], k[ok]
    kw = {"ls": "none", "marker": marker, "ms": 3} if marker else {"ls": style, "lw": 1.3}
    kw_imag = kw if marker else {"ls": "--", "lw": 1.3}
    if form == "real-imag":
        line, = axes[0].plot(f, k.real, color=color, label=f"{label}, real", **kw)
        axes[0].plot(f, k.imag, color="0.55" if marker else line.get_color(),
                     label=f"{label}, imaginary", **kw_imag)
        return line
    line, = axes[0].plot(f, np.abs(k), color=color, label=label, **kw)
    axes[1].plot(f, np.degrees(np.angle(k)), color=line.get_color(), label=label, **kw)
    return line


def style_stiffness(axes, form, freq_axis, band=None, own=False):
    """Labels, grid, ``freq_axis``, shaded ``band`` (f_lo, f_hi) [Hz]; the legend above the
    panels when ``own``."""
    if freq_axis not in FREQ_AXES:
        raise InputError(f"{freq_axis!r} is not one of {', '.join(map(repr, FREQ_AXES))}", key="--freq-axis")
    if form == "real-imag":
        axes[0].set_ylabel("dynamic stiffness K* [N/mm]", fontsize=LABEL_SIZE)
    else:
        axes[0].set_ylabel("|K*| [N/mm]", fontsize=LABEL_SIZE)
        axes[1].set_ylabel("loss angle [deg]", fontsize=LABEL_SIZE)
    axes[-1].set_xlabel("frequency [Hz]", fontsize=LABEL_SIZE)
    for a in axes:
        if freq_axis == "log":
            log_axis(a, "x", max_ticks=10)
        if band is not None:
            a.axvspan(*band, color="0.9", zorder=0)
        a.grid(True, which="major", alpha=0.35)
        a.grid(True, which="minor", alpha=0.12)
        a.tick_params(which="both", labelsize=TICK_SIZE)
    if form == "magnitude-phase":
        axes[0].tick_params(labelbottom=False)
    if own:
        axes[0].figure.legend(*axes[0].get_legend_handles_labels(), loc="outside upper center",
                   fontsize=LEGEND_SIZE, frameon=False, ncol=2)
    else:
        axes[0].legend(fontsize=LEGEND_SIZE, loc="best")


def plot_stiffness(curves, path=None, measured=None, ax=None, *, form=DEFAULT_FORM,
                   freq_axis=DEFAULT_FREQ_AXIS, title=None, provenance=None, measured_label="measured"):
    """Cross-point dynamic stiffness K*(f) of one or more mount models (and a measurement).

    Parameters
    ----------
    curves : list of (label, StiffnessTable) or (label, frequency_hz, kcp [N/m])
    path : str, optional
        PNG written atomically.
    measured : (frequency_hz, kcp [N/m]) or None
        Drawn as dots.
    ax : None, Axes, Figure, SubFigure, or (Axes, Axes) for ``magnitude-phase``
    form : {"magnitude-phase", "real-imag"}
    freq_axis : {"log", "linear"}
    title : str, optional
    provenance : Provenance, optional
        Foot line of a new figure.
    measured_label : str
        Legend label of ``measured``.
    """
    fig, axes, own = stiffness_axes(ax, form)
    if measured is not None:
        draw_stiffness(axes, measured[0], measured[1], form, label=measured_label, color="k",
                       marker=".", freq_axis=freq_axis)
    for k, item in enumerate(curves):
        label, f, kcp = (item[0], item[1].frequency_hz, item[1].kcp) if len(item) == 2 else item
        draw_stiffness(axes, f, kcp, form, label=label, color=colour(k), freq_axis=freq_axis)
    style_stiffness(axes, form, freq_axis, own=own)
    if title:
        axes[0].set_title(wrap(title, root_size(axes[0].figure)[0] * 0.95, TITLE_SIZE), fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance)


#: Points of a fitted curve drawn over the data's frequency range.
FIT_POINTS = 400


def fit_frequencies(frequency_hz, freq_axis=DEFAULT_FREQ_AXIS) -> np.ndarray:
    """:data:`FIT_POINTS` frequencies [Hz] spanning ``frequency_hz``, even on ``freq_axis``."""
    f = np.asarray(frequency_hz, dtype=float)
    if freq_axis == "log" and (f > 0).any():
        return np.geomspace(f[f > 0].min(), f.max(), FIT_POINTS)
    return np.linspace(f.min(), f.max(), FIT_POINTS)


def data_label(synthetic: bool) -> str:
    """Legend word of data points: ``SYNTHETIC data`` if ``synthetic``, else ``measured``."""
    return "SYNTHETIC data" if synthetic else "measured"


def plot_mount_fit(frequency_hz, kcp_measured, kcp_fitted, *, label="fit", title=None,
                   ax=None, path=None, form=DEFAULT_FORM, freq_axis=DEFAULT_FREQ_AXIS,
                   provenance=None, synthetic=False):
    """Measured (dots) and fitted (lines) K*(f) of a mount fit (Kovarik 2016, Figs. 15–29).

    Parameters
    ----------
    frequency_hz : ndarray
        [Hz]
    kcp_measured : ndarray of complex
        Cross-point dynamic stiffness [N/m] at ``frequency_hz``.
    kcp_fitted : ndarray of complex, or (frequencies [Hz], ndarray of complex)
        The fitted model's [N/m], at ``frequency_hz`` or its own (:func:`fit_frequencies`).
    label : str
        Legend label of the fitted curves.
    title : str, optional
    ax, path, form, freq_axis, provenance
        As for :func:`plot_stiffness`.
    synthetic : bool
        Label the data and title ``SYNTHETIC``.
    """
    f_fit, k_fit = kcp_fitted if isinstance(kcp_fitted, tuple) else (frequency_hz, kcp_fitted)
    if synthetic:
        title = "SYNTHETIC data" + (f" · {title}" if title else "")
    return plot_stiffness([(label, f_fit, k_fit)], path,
                          measured=(frequency_hz, kcp_measured), ax=ax, form=form,
                          freq_axis=freq_axis, title=title, provenance=provenance,
                          measured_label=data_label(synthetic))


def plot_retune(target_fit, path=None, *, ax=None, form=DEFAULT_FORM,
                freq_axis=DEFAULT_FREQ_AXIS, provenance=None):
    """Baseline, requested and fitted K_CP of a retune target, the band shaded.

    Parameters
    ----------
    target_fit : powertrain.workflows.retune.TargetFit
    path : str, optional
        PNG written atomically.
    ax, form, freq_axis, provenance
        As for :func:`plot_stiffness`.
    """
    tf = target_fit
    fig, axes, own = stiffness_axes(ax, form)
    for k, style, label, color in ((tf.kcp_baseline, "-", "baseline", "k"),
                                   (tf.kcp_target, "--", "requested", colour(1)),
                                   (tf.kcp_fitted, "-", f"fitted {tf.model.topology.name}", colour(0))):
        draw_stiffness(axes, tf.frequency_hz, k, form, label=label, style=style, color=color,
                       freq_axis=freq_axis)
    style_stiffness(axes, form, freq_axis, band=(tf.target.f_lo, tf.target.f_hi), own=own)
    axes[0].set_title(f"{tf.target.spec}: max error in band {100 * tf.max_band_error:.1f} %, "
                      f"mean change {100 * tf.mean_band_change:+.1f} %", fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance)


def plot_amplitude_fit(curves, path=None, *, ax=None, form=DEFAULT_FORM,
                       freq_axis=DEFAULT_FREQ_AXIS, title=None, provenance=None, synthetic=False):
    """Measured (dots) and fitted (lines) K*(f) per test amplitude (Kovarik 2016, Fig. 14).

    Parameters
    ----------
    curves : list of (label, frequency_hz, kcp_measured, kcp_fitted)
        Per amplitude [Hz, N/m]; ``kcp_fitted`` may be its own (frequencies, K*) pair.
    path, ax, form, freq_axis, title, provenance
        As for :func:`plot_stiffness`.
    synthetic : bool
        Label the data and title ``SYNTHETIC``.
    """
    fig, axes, own = stiffness_axes(ax, form)
    for k, (label, f, measured, fitted) in enumerate(curves):
        draw_stiffness(axes, f, measured, form, label=f"{label} {data_label(synthetic)}",
                       color=colour(k), marker=".", freq_axis=freq_axis)
        f_fit, k_fit = fitted if isinstance(fitted, tuple) else (f, fitted)
        draw_stiffness(axes, f_fit, k_fit, form, label=f"{label} fitted", color=colour(k),
                       freq_axis=freq_axis)
    style_stiffness(axes, form, freq_axis, own=own)
    if synthetic:
        title = "SYNTHETIC data" + (f" · {title}" if title else "")
    if title:
        axes[0].set_title(wrap(title, root_size(axes[0].figure)[0] * 0.95, TITLE_SIZE), fontsize=TITLE_SIZE)
    return finish(fig, own, path, provenance)
