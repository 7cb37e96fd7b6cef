"""HTML pieces shared by the results' ``_repr_html_`` (Jupyter) and ``powertrain report``:
tables, embedded figures and the style sheet.

Self-contained: figures are PNG data URIs, the style sheet is inline, nothing is fetched, no
script runs. The style is scoped to ``.pt-report`` (a notebook is not restyled); its print
rules (A4, no figure or table row cut by a page break) apply when printed to PDF.
"""

from __future__ import annotations

import base64
import html
import io
import math
import re

from powertrain.plotting.style import MAX_HEIGHT_IN, close_figure

#: Resolution of the embedded figures [dpi]: sharp, and a dozen figures stay a few MB.
EMBED_DPI = 150
#: CSS pixels per inch (fixed by CSS).
CSS_PX_PER_IN = 96
_VALUE = r"[+\-−]?(\d|\.\d)[\d.,]*(e[+\-]?\d+)?"
#: A cell that reads as a number (or ``a / b``, two numbers), right-aligned in tables.
_NUMBER = re.compile(rf"^{_VALUE}(\s*/\s*{_VALUE})?\s*(%|dB|Hz|rpm|°)?$")

#: The style sheet (scoped to ``.pt-report``); ``@page`` sets A4 for print to PDF.
STYLE = """
@page { size: A4; margin: 12mm; }
.pt-report { font-family: system-ui, -apple-system, "Segoe UI", "DejaVu Sans", sans-serif;
  font-size: 14px; line-height: 1.4; color: #111; max-width: 60em; margin: 0 auto;
  padding: 0 1em; }
.pt-report h1 { font-size: 1.6em; margin: 0.6em 0 0.2em; }
.pt-report h2 { font-size: 1.3em; border-bottom: 2px solid #0072B2; margin: 1.4em 0 0.5em;
  break-after: avoid; }
.pt-report h3 { font-size: 1.08em; margin: 1.1em 0 0.4em; break-after: avoid; }
.pt-report .meta { color: #444; }
.pt-report .verdict { font-weight: 600; border-left: 4px solid #D55E00; padding: 0.3em 0.7em;
  background: #fdf3ec; }
.pt-report .synthetic { color: #fff; background: #D55E00; font-weight: 700;
  padding: 0 0.35em; border-radius: 3px; font-size: 0.85em; }
.pt-report table { border-collapse: collapse; margin: 0.4em 0 0.9em; font-size: 0.88em; }
.pt-report caption { text-align: left; color: #333; padding-bottom: 0.2em; }
.pt-report th, .pt-report td { border-bottom: 1px solid #ccc; padding: 0.15em 0.55em;
  text-align: left; vertical-align: top; }
.pt-report th { background: #eef4f9; }
.pt-report td.num { text-align: right; font-variant-numeric: tabular-nums;
  white-space: nowrap; }
.pt-report .hash, .pt-report code, .pt-report pre { font-family: "DejaVu Sans Mono",
  Consolas, monospace; font-size: 0.86em; }
.pt-report .hash { font-size: 0.72em; color: #444; word-break: break-all; }
.pt-report pre { background: #f5f5f5; padding: 0.5em 0.7em; white-space: pre-wrap;
  overflow-wrap: anywhere; }
.pt-report figure { margin: 0.8em 0 1.2em; break-inside: avoid; page-break-inside: avoid; }
.pt-report figure img { display: block; max-width: 100%; height: auto; }
.pt-report figcaption { font-size: 0.88em; color: #333; margin-top: 0.3em; }
.pt-report tr, .pt-report pre { break-inside: avoid; page-break-inside: avoid; }
.pt-report thead { display: table-header-group; }
@media print {
  .pt-report { font-size: 10pt; max-width: none; padding: 0; }
  .pt-report section.step { break-before: page; }
}
"""


def esc(value) -> str:
    """``value`` as HTML text (``&``, ``<``, ``>`` and quotes escaped)."""
    return html.escape(str(value), quote=True)


def number(value, fmt: str = ".2f") -> str:
    """``value`` formatted with ``fmt``; ``-`` where None or not finite, no minus sign on a
    value that rounds to zero."""
    if value is None:
        return "-"
    try:
        x = float(value)
    except (TypeError, ValueError):
        return str(value)
    if not math.isfinite(x):
        return "-"
    text = format(x, fmt)
    if _is_zero(text) and text.startswith("-"):
        return ("+" if fmt.startswith("+") else "") + text[1:]
    return text


def _is_zero(text: str) -> bool:
    return not any(ch in "123456789" for ch in text.split("e")[0])


def table(header, rows, caption: str = "") -> str:
    """An HTML table of escaped cells (``rows``: lists of cells), numbers right-aligned."""
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = "".join(f'<td class="num">{esc(c)}</td>' if _NUMBER.match(str(c).strip())
                        else f"<td>{esc(c)}</td>" for c in row)
        body.append(f"<tr>{cells}</tr>")
    cap = f"<caption>{esc(caption)}</caption>" if caption else ""
    return (f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody>"
            "</table>")


def paragraph(text: str, cls: str = "") -> str:
    """``<p>`` of escaped text (with a class when given)."""
    attr = f' class="{cls}"' if cls else ""
    return f"<p{attr}>{esc(text)}</p>"


def synthetic_mark(synthetic: bool) -> str:
    """The SYNTHETIC badge for synthetic data, else nothing."""
    return ' <span class="synthetic">SYNTHETIC</span>' if synthetic else ""


def figure_html(fig, caption: str, dpi: int = EMBED_DPI) -> str:
    """A matplotlib figure as ``<figure>``, PNG embedded, with its caption (figure closed);
    at its drawn size, scaled down to fit an A4 page
    (:data:`~powertrain.plotting.style.MAX_HEIGHT_IN`)."""
    w_in, h_in = (float(v) for v in fig.get_size_inches())
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=dpi)
    finally:
        close_figure(fig)
    scale = min(1.0, MAX_HEIGHT_IN / h_in) if h_in > 0 else 1.0
    width = round(w_in * CSS_PX_PER_IN * scale)
    height = round(h_in * CSS_PX_PER_IN * scale)
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    return (f'<figure><img src="data:image/png;base64,{data}" width="{width}" '
            f'height="{height}" alt="{esc(caption)}"><figcaption>{esc(caption)}'
            "</figcaption></figure>")


def fragment(inner: str) -> str:
    """``inner`` in a ``.pt-report`` block with the style sheet (what ``_repr_html_``
    returns)."""
    return styled(f'<div class="pt-report">{inner}</div>')


def styled(block: str) -> str:
    """A ``.pt-report`` block preceded by the style sheet."""
    return f"<style>{STYLE}</style>{block}"
