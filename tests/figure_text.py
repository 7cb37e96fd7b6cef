"""Checks of a rendered figure: no two text elements overlap, none leaves the figure, all
text is at least 8 pt when printed at the report's page width, no legend covers data,
every coloured line or area is drawn from the colour-blind-safe palette, the legend lists
exactly the series drawn, every data axis is labelled with its unit, and the figure fits an
A4 page at 300 dpi.

The figure is drawn once at its dpi (matplotlib's ``draw_without_rendering``: the Agg draw's
layout and text extents, no pixels) while every :class:`~matplotlib.text.Text` draw call is
recorded, so exactly the text that appears in the PNG is checked — titles, axis
labels, tick labels (only the ticks inside the view), legend entries and titles, colour-bar
labels, annotations and the provenance line — each by its renderer bounding box.

Tolerance: :data:`TOLERANCE_PX` pixels at the figure's dpi. Two boxes overlap when they share
more than that in both width and height; a box leaves the figure when it crosses an edge by
more than that. One pixel absorbs the anti-aliasing fringe and rounding of glyph extents;
any real collision of two labels is several pixels deep.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

#: Allowed overlap / overshoot [px] (see the module docstring).
TOLERANCE_PX = 1.0


@contextmanager
def recording_texts():
    from matplotlib.text import Text
    drawn = []
    last = {}   # savefig draws twice with a layout engine (layout pass, then pixels)
    original = Text.draw

    def draw(self, renderer):
        original(self, renderer)
        if self.get_visible() and self.get_text().strip():
            last[id(self)] = (self, self.get_window_extent(renderer))

    Text.draw = draw
    try:
        yield drawn
    finally:
        Text.draw = original
        drawn.extend(last.values())


def drawn_texts(fig):
    """(Text, Bbox in display pixels) of every text drawn when ``fig`` is rendered: the
    figure is drawn at its dpi without pixels (``draw_without_rendering``: the same layout
    and text extents as the Agg draw, whose pixels no check reads)."""
    with recording_texts() as drawn:
        fig.draw_without_rendering()
    return drawn


def text_problems(fig, tol=TOLERANCE_PX, drawn=None) -> list[str]:
    """Descriptions of overlapping texts and texts outside the figure (empty list: fine);
    ``drawn``: the figure's :func:`drawn_texts` if already recorded."""
    drawn = drawn_texts(fig) if drawn is None else drawn
    return check_boxes(drawn, fig.bbox.width, fig.bbox.height, tol)


def texts_outside(drawn, width, height, tol=TOLERANCE_PX) -> list[str]:
    """Recorded (Text, Bbox [px]) whose window extent is not inside the ``width`` x
    ``height`` px figure (clipped in the PNG: a tick label, title or axis label of the last
    column running past the right edge)."""
    return [f"outside the figure: {text.get_text()!r} at ({bb.x0:.0f}, {bb.y0:.0f})-"
            f"({bb.x1:.0f}, {bb.y1:.0f}) px, figure {width:.0f}x{height:.0f} px"
            for text, bb in drawn
            if bb.x0 < -tol or bb.y0 < -tol or bb.x1 > width + tol or bb.y1 > height + tol]


def outside_problems(fig) -> list[str]:
    """:func:`texts_outside` of ``fig`` drawn at its own dpi."""
    return texts_outside(drawn_texts(fig), fig.bbox.width, fig.bbox.height)


def check_boxes(drawn, width, height, tol=TOLERANCE_PX) -> list[str]:
    """Problems among recorded (Text, Bbox [px]) in a ``width`` x ``height`` px figure:
    :func:`texts_outside`, then every overlapping pair."""
    problems = texts_outside(drawn, width, height, tol)
    if len(drawn) < 2:
        return problems
    box = np.array([[b.x0, b.y0, b.x1, b.y1] for _, b in drawn])
    dx = np.minimum(box[:, None, 2], box[None, :, 2]) - np.maximum(box[:, None, 0],
                                                                   box[None, :, 0])
    dy = np.minimum(box[:, None, 3], box[None, :, 3]) - np.maximum(box[:, None, 1],
                                                                   box[None, :, 1])
    hit = (dx > tol) & (dy > tol)
    for i, j in zip(*np.nonzero(np.triu(hit, 1))):
        problems.append(f"overlap {dx[i, j]:.0f}x{dy[i, j]:.0f} px: "
                        f"{drawn[i][0].get_text()!r} and {drawn[j][0].get_text()!r}")
    return problems


def small_texts(drawn, fig_width_in) -> list[str]:
    """Texts smaller than :data:`powertrain.plotting.style.MIN_PRINT_PT` when the figure is
    printed at :data:`powertrain.plotting.style.PRINT_WIDTH_IN` (a wider figure is scaled
    down to it; a narrower one is printed at its own size)."""
    from powertrain.plotting.style import MIN_PRINT_PT, PRINT_WIDTH_IN
    scale = min(1.0, PRINT_WIDTH_IN / fig_width_in)
    return [f"{t.get_fontsize() * scale:.1f} pt at {PRINT_WIDTH_IN * 2.54:.0f} cm print "
            f"width: {t.get_text()[:40]!r}" for t, _ in drawn
            if t.get_fontsize() * scale < MIN_PRINT_PT - 1e-6]


def legends_over_data(fig) -> list[str]:
    """Legends (of an axes or the figure) whose box holds a data point of a line, in display
    coordinates after drawing."""
    problems = []
    for ax in fig.axes:
        lines = [ln for ln in ax.get_lines() if ln.get_visible() and len(ln.get_xdata())]
        legends = [ax.get_legend()] + list(fig.legends)
        for leg in [g for g in legends if g is not None and g.get_visible()]:
            box = leg.get_window_extent()
            for ln in lines:
                xy = np.ma.filled(np.ma.asarray(ln.get_xydata(), float), np.nan)
                xy = xy[np.isfinite(xy).all(axis=1)]
                if not xy.size:
                    continue
                px = ln.get_transform().transform(xy)
                inside = ax.bbox.contains          # points outside the axes are clipped
                hit = [(x, y) for x, y in px if box.contains(x, y) and inside(x, y)]
                if hit:
                    problems.append(f"legend covers {len(hit)} point(s) of "
                                    f"{ln.get_label()!r} in {ax.get_title()!r}")
    return problems


def off_palette_colours(fig) -> list[str]:
    """Line, bar and shading colours that are neither grey/black nor in the Okabe-Ito
    palette (colour maps of images and meshes are checked by name in the tests)."""
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_hex, to_rgb
    from matplotlib.patches import Rectangle

    from powertrain.plotting.style import OKABE_ITO
    allowed = {c.lower() for c in OKABE_ITO.values()}
    found = set()
    for ax in fig.axes:
        colours = [ln.get_color() for ln in ax.get_lines()]
        colours += [p.get_facecolor() for p in ax.patches if isinstance(p, Rectangle)]
        colours += [c.get_facecolor()[0] for c in ax.collections
                    if isinstance(c, PolyCollection) and len(c.get_facecolor())]
        for c in colours:
            r, g, b = to_rgb(c)
            if not (abs(r - g) < 1e-6 and abs(g - b) < 1e-6) and to_hex(c) not in allowed:
                found.add(f"{to_hex(c)} in {ax.get_title()!r}")
    return sorted(found)


# --------------------------------------------------------------------------- legends, units, size
#: Axis labels that name a dimensionless quantity (no unit to give).
UNITLESS_LABELS = {"order"}


def _in_view(ax, artist) -> bool:
    """Some data point of the line ``artist`` is drawn inside ``ax`` (display coordinates,
    so lines in axes coordinates such as ``axhline`` count where they are drawn)."""
    xy = np.ma.filled(np.ma.asarray(artist.get_xydata(), float), np.nan)
    xy = xy[np.isfinite(xy).all(axis=1)] if xy.ndim == 2 else xy[:0]
    if not xy.size:
        return False
    px = artist.get_transform().transform(xy)
    box = ax.bbox
    tol = 0.5
    inside = ((px[:, 0] >= box.x0 - tol) & (px[:, 0] <= box.x1 + tol)
              & (px[:, 1] >= box.y0 - tol) & (px[:, 1] <= box.y1 + tol))
    return bool(inside.any())


def drawn_series(fig) -> dict:
    """{label: where} of every line, shaded area and bar series visible inside an axes'
    view after drawing; unlabelled lines (matplotlib's ``_child`` names) under
    ``"(unlabelled line)"``."""
    from matplotlib.collections import PolyCollection
    found = {}
    for ax in fig.axes:
        if not ax.get_visible() or hasattr(ax, "_colorbar"):
            continue
        for ln in ax.get_lines():
            if ln.get_visible() and _in_view(ax, ln):
                label = ln.get_label()
                found.setdefault("(unlabelled line)" if label.startswith("_") else label,
                                 ax.get_title())
        for c in ax.collections:
            if isinstance(c, PolyCollection) and c.get_visible() and c.get_paths() \
                    and not c.get_label().startswith("_"):
                found.setdefault(c.get_label(), ax.get_title())
        for cont in ax.containers:
            if not cont.get_label().startswith("_"):
                found.setdefault(cont.get_label(), ax.get_title())
    return found


def legend_entries(fig) -> set:
    """The texts of every legend entry (figure and axes legends, not their titles)."""
    legends = list(fig.legends) + [a.get_legend() for a in fig.axes if a.get_legend()]
    return {t.get_text() for g in legends for t in g.get_texts()}


def legend_problems(fig) -> list[str]:
    """A drawn series missing from the legend or a legend entry not drawn anywhere. A figure
    without a legend may draw one labelled series (its title says what it is); unlabelled
    lines are allowed only then."""
    drawn, entries = drawn_series(fig), legend_entries(fig)
    if not entries:
        return [f"{len(drawn)} series drawn and no legend: {sorted(drawn)[:6]}"] \
            if len(drawn) > 1 else []
    return ([f"drawn, not in the legend: {lab!r} (in {where!r})"
             for lab, where in drawn.items() if lab not in entries]
            + [f"in the legend, not drawn: {lab!r}" for lab in sorted(entries)
               if lab not in drawn])


def _has_unit(label: str) -> bool:
    label = label.strip()
    return ("[" in label and "]" in label) or label in UNITLESS_LABELS


def unit_problems(fig) -> list[str]:
    """Data axes whose x or y axis has no label with a unit ``[…]``: its own label, one of a
    panel sharing the axis (a grid labels its bottom row or one column), or the figure's
    ``supxlabel`` / ``supylabel``."""
    problems = []
    for ax in fig.axes:
        if not ax.get_visible() or hasattr(ax, "_colorbar") or not (
                ax.get_lines() or ax.collections or ax.patches):
            continue
        for axis, sup, shared in (("x", fig.get_supxlabel(), ax.get_shared_x_axes()),
                                  ("y", fig.get_supylabel(), ax.get_shared_y_axes())):
            own = ax.get_xlabel() if axis == "x" else ax.get_ylabel()
            siblings = [a.get_xlabel() if axis == "x" else a.get_ylabel()
                        for a in shared.get_siblings(ax)]
            if not any(_has_unit(lab) for lab in [own, sup, *siblings] if lab):
                problems.append(f"{axis} axis without a unit in {ax.get_title()!r} "
                                f"(label {own!r})")
    return problems


def page_problems(fig, dpi) -> list[str]:
    """A figure larger than an A4 page at ``dpi`` (2480 x 3508 px at 300 dpi, portrait)."""
    from powertrain.plotting.pages import A4_PX
    w, h = fig.get_figwidth() * dpi, fig.get_figheight() * dpi
    limit = (A4_PX[0] * dpi / 300, A4_PX[1] * dpi / 300)
    return [f"{w:.0f} x {h:.0f} px at {dpi:g} dpi: larger than A4 ({limit[0]:.0f} x "
            f"{limit[1]:.0f} px)"] if w > limit[0] + 0.5 or h > limit[1] + 0.5 else []
