"""Text layout check of a rendered figure: no two text elements overlap, none leaves the
figure.

The figure is drawn once with matplotlib's Agg renderer while every :class:`~matplotlib.text.Text`
draw call is recorded, so exactly the text that appears in the PNG is checked — titles, axis
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
    """(Text, Bbox in display pixels) of every text drawn when ``fig`` is rendered."""
    with recording_texts() as drawn:
        fig.canvas.draw()
    return drawn


def text_problems(fig, tol=TOLERANCE_PX) -> list[str]:
    """Descriptions of overlapping texts and texts outside the figure (empty list: fine)."""
    return check_boxes(drawn_texts(fig), fig.bbox.width, fig.bbox.height, tol)


def check_boxes(drawn, width, height, tol=TOLERANCE_PX) -> list[str]:
    """Problems among recorded (Text, Bbox [px]) in a ``width`` x ``height`` px figure."""
    problems = []
    for text, bb in drawn:
        if bb.x0 < -tol or bb.y0 < -tol or bb.x1 > width + tol or bb.y1 > height + tol:
            problems.append(f"outside the figure: {text.get_text()!r} at "
                            f"({bb.x0:.0f}, {bb.y0:.0f})-({bb.x1:.0f}, {bb.y1:.0f}) px, "
                            f"figure {width:.0f}x{height:.0f} px")
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
