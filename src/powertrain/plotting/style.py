"""Shared figure helpers: figure set-up, provenance line, plain-number log axes, colour bars
with ``extend``, one legend per figure, empty-panel labels, atomic saving.

matplotlib is imported lazily; nothing here switches the backend (the CLI picks Agg).
"""

from __future__ import annotations

import dataclasses
import math
import os
import textwrap

import numpy as np

from powertrain import __version__
from powertrain.errors import InputError
from powertrain.outputs import atomic_path
from powertrain.provenance import Provenance

#: Display factor and unit of each run-up signal (SI -> plot unit).
SIGNAL_UNITS = {"velocity": (1e3, "mm/s"), "displacement": (1e6, "µm"),
                "acceleration": (1.0, "m/s²"), "mount_force": (1.0, "N")}

#: Print width of every figure [in]: an A4 page's text width, 16 cm (font sizes print as is).
PRINT_WIDTH_IN = 16 / 2.54
#: Tallest figure [in]: an A4 page's text height less a three-line caption, 22 cm.
MAX_HEIGHT_IN = 22 / 2.54
#: Smallest printed text [pt] (titles, labels, ticks, legends, provenance line).
MIN_PRINT_PT = 8.0
#: Resolution of saved PNGs [dots per inch].
DPI = 300
#: Font sizes [pt]: panel titles, axis labels, tick labels, legends, provenance line.
TITLE_SIZE, LABEL_SIZE, TICK_SIZE, LEGEND_SIZE, FOOT_SIZE = 8.5, 8.5, 8, 8, 8

#: Colour-blind-safe palette (Okabe & Ito 2008, "Color Universal Design"); PALETTE omits
#: black (baselines, totals) and yellow (too light on white).
OKABE_ITO = {"blue": "#0072B2", "orange": "#E69F00", "bluish green": "#009E73",
             "vermillion": "#D55E00", "reddish purple": "#CC79A7", "sky blue": "#56B4E9",
             "yellow": "#F0E442", "black": "#000000"}
PALETTE = tuple(OKABE_ITO[n] for n in ("blue", "orange", "bluish green", "vermillion",
                                       "reddish purple", "sky blue"))
#: Gap shading: simulation above, below the measurement (told apart by every deficiency).
GAP_ABOVE, GAP_BELOW = OKABE_ITO["orange"], OKABE_ITO["sky blue"]
_LINE_STYLES = ("-", "--", ":", "-.")
#: Average glyph width as a fraction of the font size (DejaVu Sans).
_GLYPH = 0.6


def subplots(target, nrows=1, ncols=1, figsize=(PRINT_WIDTH_IN, 3.6), **kwargs):
    """Figure and a 2-D array of axes for a plot function's ``ax`` argument.

    Parameters
    ----------
    target : None, matplotlib Axes, Figure or SubFigure
        None: a new pyplot figure, constrained layout. Figure or SubFigure: panels made in
        it. Axes: used as is, for a single panel only (else InputError).
    nrows, ncols : int
    figsize : (float, float)
        Size of a new figure [in].
    kwargs
        Passed to ``subplots`` (sharex, sharey, gridspec_kw ...).

    Returns
    -------
    fig : Figure or SubFigure
    axes : ndarray of Axes, shape (nrows, ncols)
    own : bool
        True when the figure was made here.
    """
    from matplotlib.axes import Axes  # deferred: heavy optional package
    from matplotlib.figure import FigureBase  # deferred: heavy optional package
    if target is None:
        import matplotlib.pyplot as plt  # deferred: heavy optional package
        fig = plt.figure(figsize=figsize, layout="constrained")
        return fig, _use_palette(fig.subplots(nrows, ncols, squeeze=False, **kwargs)), True
    if isinstance(target, FigureBase):
        return target, _use_palette(target.subplots(nrows, ncols, squeeze=False, **kwargs)), False
    if isinstance(target, Axes):
        if nrows * ncols != 1:
            raise InputError(panels_error(nrows * ncols), key="ax")
        return target.figure, np.array([[target]]), False
    raise InputError(f"must be a matplotlib Axes, Figure or SubFigure, not "
                     f"{type(target).__name__}", key="ax")


def panels_error(n: int, choose: str = "") -> str:
    """Message for an Axes given to a figure of ``n`` panels (``choose``: how to pick one)."""
    return (f"this figure has {n} panels: pass a Figure or SubFigure (e.g. fig or "
            f"fig.subfigures()), not one Axes{choose}")


def legend(fig, axes, target, extra=()):
    """Legend of a plot: above the panels of ``fig`` (:func:`figure_legend`, ``axes``,
    ``extra``), or inside the Axes when ``target`` is one."""
    if not is_axes(target):
        return figure_legend(fig, axes, extra)
    a = np.ravel(axes)[0]
    handles, labels = a.get_legend_handles_labels()
    handles += [h for h, _ in extra]
    labels += [lab for _, lab in extra]
    return a.legend(handles, labels, fontsize=LEGEND_SIZE, loc="best") if labels else None


def colour(k: int) -> str:
    """The ``k``-th colour of :data:`PALETTE` (cyclic)."""
    return PALETTE[k % len(PALETTE)]


def series_style(k: int) -> dict:
    """Colour and line style of the ``k``-th series: the palette solid, then dashed, dotted,
    dash-dotted (24 distinct)."""
    return {"color": colour(k), "ls": _LINE_STYLES[(k // len(PALETTE)) % len(_LINE_STYLES)]}


def order_style(order) -> dict:
    """Colour and line style of an engine order, the same in every figure.

    Orders 2, 4, 6, 8 solid; 1, 3, 5, 7 dashed; half orders dotted (6.5, 7.5 dash-dotted);
    the 16 orders 0.5 … 8 all differ; any other order dash-dot-dot.

    Parameters
    ----------
    order : float or str
        The order [-] (``2.0``) or its quantity name (``"order_2"``).

    Returns
    -------
    dict
        ``color`` and ``ls`` for ``Axes.plot``.
    """
    if isinstance(order, str):
        order = float(order.replace("order_", "").replace("order ", ""))
    halves = round(2 * float(order))
    if abs(2 * float(order) - halves) > 1e-9:
        return {"color": colour(round(4 * float(order))), "ls": (0, (3, 1, 1, 1, 1, 1))}
    if halves % 4 == 0:
        return {"color": colour(halves // 4 - 1), "ls": "-"}
    if halves % 2 == 0:
        return {"color": colour(halves // 4 + 4), "ls": "--"}
    return {"color": colour(halves // 2), "ls": ":" if halves // 2 < len(PALETTE) else "-."}


def quantity_style(quantity: str) -> dict:
    """Style of a run-up ``quantity``: synthesis, overall black; an order :func:`order_style`."""
    totals = {"synthesis": "-", "overall": "--"}
    return {"color": "k", "ls": totals[quantity]} if quantity in totals else order_style(quantity)


def _use_palette(axes):
    for a in np.ravel(axes):
        a.set_prop_cycle(color=list(PALETTE))
    return axes


def is_axes(target) -> bool:
    """True for a single matplotlib Axes ``target``."""
    if target is None:
        return False
    from matplotlib.axes import Axes  # deferred: heavy optional package
    return isinstance(target, Axes)


def root_figure(fig):
    """The top-level figure holding ``fig`` (a Figure, SubFigure or Axes)."""
    while getattr(fig, "figure", None) is not None and fig.figure is not fig:
        fig = fig.figure
    return fig


def root_size(fig):
    """(width, height) [in] of the top-level figure holding ``fig``."""
    root = root_figure(fig)
    return root.get_figwidth(), root.get_figheight()


def finish(fig, own, path=None, provenance=None, title=None):
    """Title, provenance line (when ``own``) and saving to ``path`` of a figure."""
    if title:
        text = wrap(title, root_size(fig)[0] * 0.95, 9)
        if fig.legends:   # the legend above the panels carries the title (no collision)
            fig.legends[0].set_title(text, prop={"size": 9})
            fig.legends[0].get_title().set_multialignment("center")
        else:
            fig.suptitle(text, fontsize=9)
    laid_out = False
    if own:
        add_provenance(fig, provenance)
        laid_out = keep_inside(fig)
    if path:
        save_figure(fig, path, laid_out=laid_out)
    return fig


def keep_inside(fig, tries=3) -> bool:
    """Shrink a figure's constrained-layout area by any text overhang at its edges (the
    layout contains overhangs only when its area is the whole figure); True when none."""
    engine = fig.get_layout_engine()
    if engine is None or "rect" not in engine.get():
        return False
    for _ in range(tries):
        fig.draw_without_rendering()   # the layout, computed at drawing time (no pixels)
        width, height = fig.get_figwidth(), fig.get_figheight()
        box = fig.get_tightbbox(fig.canvas.get_renderer())   # [in]
        over = np.array([-box.x0, -box.y0, box.x1 - width, box.y1 - height])
        over = np.maximum(over, 0) + np.where(over > 0, 1 / 72, 0)   # 1 pt clear of the edge
        if not over.any():
            return True
        x0, y0, w, h = engine.get()["rect"]
        engine.set(rect=(x0 + over[0] / width, y0 + over[1] / height,
                         w - (over[0] + over[2]) / width, h - (over[1] + over[3]) / height))
    return False


def wrap(text, width_in, fontsize) -> str:
    """``text`` wrapped to lines that fit ``width_in`` [in] at ``fontsize`` [pt]."""
    chars = max(20, int(width_in * 72 / (fontsize * _GLYPH) * 0.95))
    return "\n".join(textwrap.wrap(text, chars, break_long_words=True, break_on_hyphens=False)) or text


def add_provenance(fig, provenance):
    """Write the provenance line at the foot of ``fig``, in a strip kept from the layout.

    Parameters
    ----------
    fig : Figure
    provenance : powertrain.provenance.Provenance, dict or None
        A :class:`~powertrain.provenance.Provenance` or its record; None: the version only.
    """
    width, height = fig.get_figwidth(), fig.get_figheight()
    text = foot_text(provenance, width * 0.98)
    n_lines = text.count("\n") + 1
    strip = (n_lines * FOOT_SIZE * 1.25 + 4) / 72 / height
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set") and "rect" in engine.get():
        engine.set(rect=(0, strip, 1, 1 - strip))
    fig.text(0.008, 1.5 / 72 / height, text, fontsize=FOOT_SIZE, color="0.35",
             ha="left", va="bottom", linespacing=1.1)


def foot_text(provenance, width_in) -> str:
    """The provenance line in lines of ``width_in`` at :data:`FOOT_SIZE`: one when it fits,
    else the command on lines of its own broken with shell continuations, runnable as printed.

    Parameters
    ----------
    provenance : powertrain.provenance.Provenance, dict or None
        As for :func:`add_provenance`.
    width_in : float
        Width of a line [in].
    """
    if isinstance(provenance, dict):
        provenance = Provenance.from_record(provenance)
    if provenance is None:
        return f"powertrain {__version__}"
    chars = max(20, int(width_in * 72 / (FOOT_SIZE * _GLYPH) * 0.95))
    line = provenance.line()
    if len(line) <= chars or not provenance.command:
        return wrap(line, width_in, FOOT_SIZE)
    head = wrap(dataclasses.replace(provenance, command="").line(), width_in, FOOT_SIZE)
    return head + "  ·\n" + "\n".join(shell_lines("$ " + provenance.command, chars))


def shell_lines(command: str, chars: int) -> list:
    """``command`` in lines of at most ``chars``, broken between arguments with shell
    continuations, indented; an option stays with its value."""
    words = []
    for word in command.split(" "):
        if words and words[-1].startswith("-") and not word.startswith("-") and " " not in words[-1]:
            words[-1] += " " + word
        else:
            words.append(word)
    lines, current = [], ""
    for word in words:
        indent = "  " if lines else ""
        if current and len(indent + current + " " + word) + 2 > chars:
            lines.append(indent + current + " \\")
            current = word
        else:
            current = f"{current} {word}" if current else word
    lines.append(("  " if lines else "") + current)
    return lines


def quantity_label(quantity: str) -> str:
    """``quantity`` label: ``order_2`` -> ``order 2``; ``synthesis`` stays."""
    return quantity.replace("order_", "order ")


def signed(value, decimals: int = 1) -> str:
    """``value`` signed with ``decimals`` decimals (``+0.1``); zero is ``0.0``, never signed."""
    text = f"{value:+.{decimals}f}"
    return text[1:] if float(text) == 0 else text


def no_data(ax, text="no data above the noise floor", width=42):
    """Label the empty panel ``ax`` with ``text`` wrapped to ``width`` characters."""
    ax.text(0.5, 0.5, "\n".join(textwrap.wrap(text, width)), transform=ax.transAxes,
            ha="center", va="center", fontsize=LABEL_SIZE, color="0.4")
    ax.tick_params(axis="y", labelleft=False)


def _plain(value, _pos=None) -> str:
    """Tick label of a log axis as a plain number (0.00001, never 1e-5)."""
    if value <= 0 or not math.isfinite(value):
        return ""
    return np.format_float_positional(float(f"{value:.6g}"), trim="-")


def _log_ticks(vmin, vmax, max_ticks, min_gap=0.0):
    """Log ticks in [vmin, vmax]: 1-2-5 per decade, thinned beyond ``max_ticks`` or closer
    than ``min_gap`` decades, refined to 1..9 when fewer than two."""
    if vmin > vmax:
        vmin, vmax = vmax, vmin
    if not (vmax > 0 and math.isfinite(vmax)):
        return np.array([])
    vmin = vmin if vmin > 0 else vmax * 1e-6
    lo, hi = math.floor(math.log10(vmin)), math.ceil(math.log10(vmax))

    def inside(subs, every=1):
        t = [s * 10.0 ** e for e in range(lo, hi + 1) if (e - lo) % every == 0 for s in subs]
        return [v for v in t if vmin * (1 - 1e-9) <= v <= vmax * (1 + 1e-9)]

    candidates = [inside(s) for s in ((1, 2, 5), (1, 3), (1,))]
    candidates += [inside((1,), n) for n in range(2, 12)]
    for ticks in candidates:
        gaps = np.diff(np.log10(ticks)) if len(ticks) > 1 else [np.inf]
        if len(ticks) <= max_ticks and min(gaps) >= min_gap:
            break
    if len(ticks) >= 2:
        return np.array(ticks)
    for subs in ((1, 2, 5), range(1, 10)):
        fine = _spaced(inside(subs), min_gap)
        if 2 <= len(fine) <= max_ticks:
            return np.array(fine)
    from matplotlib.ticker import MaxNLocator  # deferred: heavy optional package
    lin = MaxNLocator(nbins=3, steps=[1, 2, 2.5, 5, 10]).tick_values(vmin, vmax)
    return np.array(_spaced([v for v in lin if vmin <= v <= vmax and v > 0], min_gap))


def _spaced(ticks, min_gap):
    """Ascending ``ticks`` thinned to at least ``min_gap`` decades apart."""
    kept = []
    for t in ticks:
        if not kept or math.log10(t / kept[-1]) >= min_gap:
            kept.append(t)
    return kept


def log_axis(ax, axis="x", max_ticks=8, minor=True):
    """Make ``ax``'s x or y axis logarithmic with plain-number tick labels.

    Parameters
    ----------
    ax : matplotlib Axes
    axis : {"x", "y"}
    max_ticks : int
        Most labelled ticks; the 1-2-5 sequence is thinned beyond it.
    minor : bool
        Unlabelled minor ticks at 2..9 × 10^n.
    """
    from matplotlib.ticker import (  # deferred: heavy optional package
        FuncFormatter,
        Locator,
        LogLocator,
        NullFormatter,
    )

    class PlainLogLocator(Locator):
        def __call__(self):
            return self.tick_values(*self.axis.get_view_interval())

        def tick_values(self, vmin, vmax):
            return _log_ticks(vmin, vmax, max_ticks, self._min_gap(vmin, vmax))

        def _min_gap(self, vmin, vmax):
            """Decades between two stacked y labels (1.25 font sizes); 0 on an x axis."""
            if axis != "y" or not (vmin > 0 and vmax > 0):
                return 0.0
            a = self.axis.axes
            height_pt, span = a.bbox.height * 72 / a.figure.dpi, abs(math.log10(vmax / vmin))
            return 1.25 * TICK_SIZE * span / height_pt if height_pt > 0 else 0.0

    target = ax.xaxis if axis == "x" else ax.yaxis
    (ax.set_xscale if axis == "x" else ax.set_yscale)("log")
    target.set_major_locator(PlainLogLocator())
    target.set_major_formatter(FuncFormatter(_plain))
    if minor:
        target.set_minor_locator(LogLocator(subs=np.arange(2, 10), numticks=100))
    else:
        from matplotlib.ticker import NullLocator  # deferred: heavy optional package
        target.set_minor_locator(NullLocator())
    target.set_minor_formatter(NullFormatter())


def colorbar(fig, mappable, axes, data, vmin, vmax, label):
    """Colour bar of ``mappable`` on ``axes`` labelled ``label``, with ``extend`` arrows where
    ``data`` is clipped by ``[vmin, vmax]``."""
    finite = np.asarray(data, dtype=float)
    finite = finite[np.isfinite(finite)]
    below = bool(finite.size and finite.min() < vmin)
    above = bool(finite.size and finite.max() > vmax)
    extend = ("neither", "min", "max", "both")[below + 2 * above]
    cb = fig.colorbar(mappable, ax=axes, extend=extend, shrink=0.9, aspect=30)
    cb.set_label(label, fontsize=LABEL_SIZE)
    cb.ax.tick_params(labelsize=TICK_SIZE)
    return cb


def figure_legend(fig, axes, extra=(), fontsize=LEGEND_SIZE):
    """One legend above the panels: the distinct labels of ``axes`` and ``extra`` (handle,
    label) pairs, in as many columns as fit at ``fontsize``."""
    handles, labels = [], []
    for ax in np.ravel(axes):
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels and not lab.startswith("_"):
                handles.append(h)
                labels.append(lab)
    for h, lab in extra:
        handles.append(h)
        labels.append(lab)
    if not labels:
        return None
    width = root_size(fig)[0] * 0.96 * 72
    entry = max(len(lab) for lab in labels) * fontsize * _GLYPH + 3.2 * fontsize
    ncol = max(1, min(len(labels), int(width // entry)))
    return fig.legend(handles, labels, loc="outside upper center", ncol=ncol,
                      fontsize=fontsize, frameon=False, markerscale=1.5)


def save_figure(fig, path, laid_out=False):
    """Save ``fig`` as PNG to ``path`` atomically; ``laid_out``: keep :func:`keep_inside`'s
    layout (engine held off while saving)."""
    root = root_figure(fig)
    engine = root.get_layout_engine() if laid_out else None
    with atomic_path(path) as tmp:
        if engine is not None:
            root.set_layout_engine("none")
        try:
            root.savefig(tmp, dpi=DPI, format="png")
        finally:
            if engine is not None:
                root.set_layout_engine(engine)


def target_and_path(ax, path):
    """``(ax, path)``, a path given as ``ax`` taken as the output file."""
    if isinstance(ax, (str, os.PathLike)):
        return None, ax
    return ax, path


def close_figure(fig):
    """Release the pyplot figure ``fig``."""
    import matplotlib.pyplot as plt  # deferred: heavy optional package
    plt.close(fig)
