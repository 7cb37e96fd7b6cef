"""Regenerate every figure under docs/ from the commands the guides show.

- ``docs/compare-example.png``: ``powertrain compare examples/measured-runup.csv --plot …``
  (README step 2, docs/guide/compare.md, docs/reference/figures.md).
- ``docs/sweep-rates.png``: ``scripts/sweep_vs_stepped.py --plot …`` (docs/guide/track.md);
  minutes of CPU, skipped with ``--quick``.

Each figure is written by the command line itself (so it carries its provenance line and
passes the checks of tests/test_figures.py: text >= 8 pt at the 16 cm print width, no legend
over data, colour-blind-safe palette). Prints each file written and its size in pixels.

Usage: python scripts/make_doc_figures.py [--quick] [--out docs]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(args, cwd):
    print("$ " + " ".join(str(a) for a in args), flush=True)
    subprocess.run([str(a) for a in args], cwd=cwd, check=True)


def _shown(path: Path) -> str:
    """The path relative to the checkout (so the provenance line names no home folder)."""
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs"), help="folder of the figures")
    ap.add_argument("--quick", action="store_true", help="skip the slow sweep figure")
    args = ap.parse_args(argv)
    out = Path(args.out).resolve()
    cli = [sys.executable, "-m", "powertrain.cli"]
    written = [out / "compare-example.png"]
    _run(cli + ["compare", "examples/measured-runup.csv", "--plot", _shown(written[0]),
                "--quiet"], ROOT)
    if not args.quick:
        written.append(out / "sweep-rates.png")
        _run([sys.executable, "scripts/sweep_vs_stepped.py", "--plot", _shown(written[1])], ROOT)
    from PIL import Image
    for path in written:
        with Image.open(path) as im:
            print(f"wrote {_shown(path)}: {im.width} x {im.height} px")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
