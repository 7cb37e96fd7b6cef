#!/usr/bin/env python
r"""Reproduce Tables 3, 4 and 5 of Kovarik (2016) with both of our solution methods.

The thesis verified its triple mass oscillator (parallel connection, eq. 20-39) by putting a
100 kg engine mass on it, loading the mass with a 100 N harmonic force and computing the
engine-mass displacement x1 (Table 3), the force transmitted to ground F_T (Table 4) and the
cross-point stiffness K_CP = F_T/x1 (Table 5) at 5-40 Hz in four tools (Analytical, MSC
Nastran SOL 108 with the deck of Appendix A, AVL Excite, MSC Adams) [1]_. This script solves
the same set-up, ``mounts/thesis-appendix-a.toml`` (the Appendix A deck), with

* the frequency method: the condensed network, :math:`\hat X_1 = F/(K_{IP} - \omega^2 m_e)`,
  :math:`F_T = K_{CP}\hat X_1` (eq. 25-39 in general form), and
* the time method: Newmark average-acceleration integration from the periodic steady state,
  processed by FFT (as the thesis did in AVL Excite),

through :func:`powertrain.workflows.stiffness.stiffness_table`, and prints both next to
the printed MSC Nastran column.

Tolerances (named in ``tests/tolerances.py``, shared with ``tests/test_thesis_tables.py``):

* Tables 3 and 4: :math:`|\text{ours} - \text{Nastran}| \le 1` unit of the last printed
  digit, real and imaginary part separately, for both methods. Solving the Appendix A deck
  exactly reproduces the Nastran columns to their printed digits (worst about 0.6 unit), so
  the only admissible difference is the printed rounding.
* Table 5: :math:`|K_\text{ours} - K_\text{Nastran}|/|K_\text{Nastran}| \le 0.5\,\%`
  (complex). Table 5's Nastran column is *not* consistent with the thesis's own Tables 3-4:
  F_T/x1 of the exact solution (which matches Tables 3-4 to the digit) differs from it by up
  to 2.1 N/mm in the imaginary part at 40 Hz (0.4 % of |K|), and dividing the printed Table 3
  and 4 values gives yet other numbers. The script prints the spread of the thesis's four
  columns about the Nastran one: 0.5 % is the size of the thesis's own tool-to-tool
  disagreement (up to 0.6 %), so it is the sharpest check Table 5 supports.
* Time vs frequency method: relative difference < 1e-3 on x1, F_T and K_CP (the Newmark
  frequency warping with 1024 steps per period is (2 pi/1024)^2/12 = 3e-6 relative).

Deviations are printed in units of the last printed digit (Tables 3-4) and relative
(Table 5). The last line is a machine-readable summary; the exit status is 0 if every
criterion holds, 1 otherwise.

References
----------
.. [1] B. Kovarik, *Modeling of the Nonlinear Frequency Dependent Engine Mount Dynamic
   Stiffness*, Master's thesis, University of Zagreb, 2016, sec. 3.2, Tables 3-5, Appendix A.

Examples
--------
::

    python scripts/verify_thesis_tables.py
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

from powertrain.iotools.mount_file import read_mount
from powertrain.workflows.stiffness import stiffness_table

ROOT = Path(__file__).resolve().parents[1]
MOUNT_FILE = ROOT / "mounts" / "thesis-appendix-a.toml"
ENGINE_MASS_KG = 100.0
FORCE_N = 100.0


def _load_module(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


thesis_tables = _load_module("thesis_tables", ROOT / "tests" / "data" / "thesis_tables.py")
tolerances = _load_module("tolerances", ROOT / "tests" / "tolerances.py")


def solve(method: str):
    """x1 [mm], F_T [N], K_CP [N/mm] of the Appendix A set-up by ``method``."""
    model = read_mount(MOUNT_FILE)
    f = np.array(thesis_tables.FREQUENCIES_HZ)
    t = stiffness_table(model, f, method=method, engine_mass=ENGINE_MASS_KG, force=FORCE_N)
    return {"table3": t.x1 * 1e3, "table4": t.ft, "table5": t.kcp / 1e3}


def digit_deviation(ours, table):
    """|ours - Nastran| in units of the last printed digit: (real, imaginary) arrays."""
    ref = table["nastran"]
    return (np.abs(ours.real - ref.real) / table["nastran_digit_real"],
            np.abs(ours.imag - ref.imag) / table["nastran_digit_imag"])


def relative_deviation(ours, ref):
    """|ours - ref| / |ref| (complex)."""
    return np.abs(ours - ref) / np.abs(ref)


def thesis_spread(table):
    """Largest |K_source - K_Nastran| / |K_Nastran| over the thesis's other three columns."""
    ref = table["nastran"]
    return np.max([relative_deviation(table[s], ref)
                   for s in thesis_tables.SOURCES if s != "nastran"], axis=0)


def _print_digit_table(title, unit, table, ours_f, ours_t, decimals):
    fmt = f"{{:>10.{decimals}f}}"
    print(f"{title} [{unit}]  (dev = |ours - Nastran| in units of the last printed digit)")
    part = f"{'Nastran':>10}  {'frequency':>10}  {'dev':>6}  {'time':>10}  {'dev':>6}"
    print(f"{'':6}  {'real part':^46}  {'imaginary part':^46}")
    print(f"{'f[Hz]':>6}  {part}  {part}")
    df_re, df_im = digit_deviation(ours_f, table)
    dt_re, dt_im = digit_deviation(ours_t, table)
    for i, f in enumerate(table["frequency_hz"]):
        txt_re, txt_im = table["nastran_text"][i]
        cells = [f"{txt_re:>10}", fmt.format(ours_f[i].real), f"{df_re[i]:6.2f}",
                 fmt.format(ours_t[i].real), f"{dt_re[i]:6.2f}",
                 f"{txt_im:>10}", fmt.format(ours_f[i].imag), f"{df_im[i]:6.2f}",
                 fmt.format(ours_t[i].imag), f"{dt_im[i]:6.2f}"]
        print(f"{f:6.0f}  " + "  ".join(cells))
    worst = max(df_re.max(), df_im.max(), dt_re.max(), dt_im.max())
    print(f"max deviation: {worst:.2f} digit (tolerance "
          f"{tolerances.TABLE34_MAX_DEV_LAST_DIGIT:g})\n")
    return worst


def main() -> int:
    tabs = thesis_tables.load()
    freq = solve("frequency")
    time = solve("time")

    t3 = _print_digit_table("Table 3: engine mass displacement x1", "mm", tabs["table3"],
                            freq["table3"], time["table3"], 5)
    t4 = _print_digit_table("Table 4: transmitted force F_T", "N", tabs["table4"],
                            freq["table4"], time["table4"], 3)

    tab5 = tabs["table5"]
    rel_f = relative_deviation(freq["table5"], tab5["nastran"])
    rel_t = relative_deviation(time["table5"], tab5["nastran"])
    spread = thesis_spread(tab5)
    print("Table 5: cross-point stiffness K_CP [N/mm]  (rel = |K - K_Nastran| / |K_Nastran|;")
    print("         thesis spread = max over Analytical, Excite, Adams of the same)")
    print(f"{'f[Hz]':>6}  {'Nastran':>16}  {'frequency':>18}  {'rel':>7}  "
          f"{'time':>18}  {'rel':>7}  {'thesis spread':>13}")
    for i, f in enumerate(tab5["frequency_hz"]):
        re, im = tab5["nastran_text"][i]
        kf, kt = freq["table5"][i], time["table5"][i]
        print(f"{f:6.0f}  {re:>7} {im:>7}i  {kf.real:8.2f} {kf.imag:7.2f}i  {rel_f[i]:7.2%}  "
              f"{kt.real:8.2f} {kt.imag:7.2f}i  {rel_t[i]:7.2%}  {spread[i]:13.2%}")
    t5 = max(rel_f.max(), rel_t.max())
    print(f"max deviation: {t5:.2%} (tolerance {tolerances.TABLE5_MAX_REL_DEV:.1%}); "
          f"thesis tool-to-tool spread up to {spread.max():.2%}\n")

    tvf = max(relative_deviation(time[k], freq[k]).max() for k in freq)
    print(f"time vs frequency method, max relative difference on x1, F_T, K_CP: {tvf:.2e} "
          f"(tolerance {tolerances.TIME_VS_FREQUENCY_REL:g})")

    ok = (t3 <= tolerances.TABLE34_MAX_DEV_LAST_DIGIT
          and t4 <= tolerances.TABLE34_MAX_DEV_LAST_DIGIT
          and t5 <= tolerances.TABLE5_MAX_REL_DEV
          and tvf <= tolerances.TIME_VS_FREQUENCY_REL)
    print(f"table3_max_dev_digits={t3:.2f} table4_max_dev_digits={t4:.2f} "
          f"table5_max_rel_dev={t5:.4f} thesis_table5_spread={spread.max():.4f} "
          f"time_vs_frequency_max_rel={tvf:.1e} pass={ok}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
