"""Figures on pages: a grid's rows split to fit A4 pages, written to ``NAME.png``,
``NAME_p2.png`` …, each page's title noting the others."""

from __future__ import annotations

import os

from powertrain.plotting.style import MAX_HEIGHT_IN, close_figure

#: Row heights of a grid [in]: the smallest keeping a title and two log ticks apart at 8 pt,
#: and the roomy one.
MIN_ROW_IN, ROOMY_ROW_IN = 0.62, 1.3
#: Size of an A4 page at :data:`~powertrain.plotting.style.DPI` [px]: no saved figure is larger.
A4_PX = (2480, 3508)


def page_rows(rows, frame_in, roomy=ROOMY_ROW_IN):
    """``rows`` of a grid split into pages that each fit :data:`MAX_HEIGHT_IN`, and the row height.

    Parameters
    ----------
    rows : list
        The grid's rows, in order.
    frame_in : float
        Height of a page outside its rows [in].
    roomy : float
        Row height when there is room [in].

    Returns
    -------
    pages : list of lists
        Consecutive rows per page, as even as can be.
    row_in : float
        Height of a row [in]: ``roomy``, or less (down to :data:`MIN_ROW_IN`) to fit.
    """
    room = MAX_HEIGHT_IN - frame_in
    per_page = max(1, int(room // MIN_ROW_IN))
    n_pages = -(-len(rows) // per_page)
    size = -(-len(rows) // max(n_pages, 1))
    pages = [rows[i:i + size] for i in range(0, len(rows), size)] or [rows]
    return pages, float(min(roomy, max(MIN_ROW_IN, room / max(size, 1))))


def page_path(path, k: int):
    """File of page ``k`` (from 0) of a figure written to ``path``: ``path``, ``NAME_p2.png`` …"""
    if k == 0 or path is None:
        return path
    base, ext = os.path.splitext(os.fspath(path))
    return f"{base}_p{k + 1}{ext}"


def draw_pages(rows, frame_in, ax, path, draw):
    """A grid's ``rows`` drawn on the pages :func:`page_rows` needs with ``frame_in`` (one
    into ``ax`` or unwritten) by ``draw(rows, row height [in], file, title note)``; the
    first page returned, ``pages`` listing the files written to ``path``, the rest closed."""
    pages, height = page_rows(rows, frame_in)
    if ax is not None or not path:
        pages = [rows]
    paths = [page_path(path, k) for k in range(len(pages))]
    figures = [draw(chunk, height, paths[k], page_note(k, pages, path)) for k, chunk in enumerate(pages)]
    for fig in figures[1:]:
        close_figure(fig)
    if len(figures) > 1:
        figures[0].pages = [p for p in paths if p]
    return figures[0]


def page_note(k: int, pages, path) -> str:
    """Title note of page ``k`` of ``pages`` written to ``path`` (empty for one page)."""
    if len(pages) < 2:
        return ""
    names = [os.path.basename(os.fspath(page_path(path, j))) for j in range(len(pages))]
    rest = ", ".join(n for j, n in enumerate(names) if j != k)
    return f" — page {k + 1} of {len(pages)} (also {rest})" if path else f" — part {k + 1} of {len(pages)}"
