"""Figures on pages: the rows of a grid split so that each page fits an A4 page
(:data:`~powertrain.plotting.style.MAX_HEIGHT_IN`), the page files ``NAME.png``,
``NAME_p2.png`` …, and the title note of each page."""

from __future__ import annotations

import os

from powertrain.plotting.style import MAX_HEIGHT_IN, close_figure

#: Row heights of a grid of panels [in]: the smallest that keeps a one-line panel title and
#: two log ticks at 8 pt apart, and the roomy one; a grid whose rows at the smallest height
#: exceed :data:`MAX_HEIGHT_IN` is drawn on several pages (:func:`page_rows`).
MIN_ROW_IN, ROOMY_ROW_IN = 0.62, 1.3
#: Size of an A4 page at :data:`~powertrain.plotting.style.DPI` [px], portrait: no saved figure is larger.
A4_PX = (2480, 3508)


def page_rows(rows, frame_in, roomy=ROOMY_ROW_IN):
    """``rows`` of a grid split into pages that each fit :data:`MAX_HEIGHT_IN`, and the row
    height.

    Parameters
    ----------
    rows : list
        The grid's rows, in order.
    frame_in : float
        Height of a page outside its rows [in] (title, legend, x labels, provenance line).
    roomy : float
        Row height when there is room [in].

    Returns
    -------
    pages : list of lists
        Consecutive rows per page, as even as can be (one page when all fit at
        :data:`MIN_ROW_IN`).
    row_in : float
        Height of a row [in]: ``roomy``, or less (not below :data:`MIN_ROW_IN`) to fit.
    """
    room = MAX_HEIGHT_IN - frame_in
    per_page = max(1, int(room // MIN_ROW_IN))
    n_pages = -(-len(rows) // per_page)
    size = -(-len(rows) // max(n_pages, 1))
    pages = [rows[i:i + size] for i in range(0, len(rows), size)] or [rows]
    return pages, float(min(roomy, max(MIN_ROW_IN, room / max(size, 1))))


def page_path(path, k: int):
    """File of page ``k`` (from 0) of a figure written to ``path``: ``path`` itself, then
    ``NAME_p2.png``, ``NAME_p3.png`` … beside it."""
    if k == 0 or path is None:
        return path
    base, ext = os.path.splitext(os.fspath(path))
    return f"{base}_p{k + 1}{ext}"


def draw_pages(rows, frame_in, ax, path, draw):
    """A grid's ``rows`` drawn on as many pages as :func:`page_rows` needs (one page when
    drawn into ``ax`` or not written): ``draw(rows, row height [in], file, title note)``
    makes a page's figure. Returns the first page (what a plot function returns; the others,
    written, are released), its ``pages`` attribute listing every file written when there
    are several."""
    pages, height = page_rows(rows, frame_in)
    if ax is not None or not path:
        pages = [rows]
    paths = [page_path(path, k) for k in range(len(pages))]
    figures = [draw(chunk, height, paths[k], page_note(k, pages, path))
               for k, chunk in enumerate(pages)]
    for fig in figures[1:]:
        close_figure(fig)
    if len(figures) > 1:
        figures[0].pages = [p for p in paths if p]
    return figures[0]


def page_note(k: int, pages, path) -> str:
    """Title note of page ``k`` of a figure drawn on several pages (empty for one page)."""
    if len(pages) < 2:
        return ""
    names = [os.path.basename(os.fspath(page_path(path, j))) for j in range(len(pages))]
    rest = ", ".join(n for j, n in enumerate(names) if j != k)
    return f" — page {k + 1} of {len(pages)} (also {rest})" if path else \
        f" — part {k + 1} of {len(pages)}"
