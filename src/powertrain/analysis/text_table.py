"""Fixed-width text tables for terminal reports (used by the CLI and by result objects)."""

from __future__ import annotations


def format_table(header: list[str], rows: list[list], floatfmt: str = "{:.4g}") -> str:
    """Fixed-width text table."""
    cells = [[floatfmt.format(v) if isinstance(v, float) else str(v) for v in row] for row in rows]
    widths = [max(len(h), *(len(r[i]) for r in cells)) if cells else len(h) for i, h in enumerate(header)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths)), "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)
