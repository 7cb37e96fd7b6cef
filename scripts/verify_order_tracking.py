"""Verify order tracking against signals with known order content (issue 12, item 7).

Every check runs the command line (``powertrain track``, in-process) on CSV, HDF5, UFF58
and MDF4 copies of the same synthetic signals (written here with the package's writers,
i.e. pyuff and asammdf) and reads the tracked CSV back:

1. analytic linear sweep 1000->6000 rpm in 20 s, orders 0.5..8 with known amplitudes and
   phases: tracked RMS within 0.1 dB (every grid speed; the tracker keeps a whole block
   inside the record, so the run-up ends are excluded);
2. the published order-tracking example of a commercial signal-processing toolbox (600 Hz,
   5 s, 600->2400 rpm, orders 1, 1/2, sqrt2, 2, amplitudes 1, 1/2, sqrt2, 2): recovered
   amplitudes within 0.1 dB;
3. tacho (4 pulses/rev) of the same sweep gives the rpm channel's curves within 0.05 dB;
4. order 2 crossing a fixed 100 Hz tone of half its amplitude at 500 rpm/s: Vold-Kalman
   keeps the order within 0.5 dB where COT smears (> 1 dB);
5. acceleration in, ``--as velocity`` out equals the velocity channel of the same signal
   within 0.05 dB.

Usage: python scripts/verify_order_tracking.py [--formats csv,hdf5,uff,mdf]
Prints one line per check and, last, the summary.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
from click.testing import CliRunner

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks import signals
from powertrain.cli import main as cli
from powertrain.iotools.measured import read_measured

WRITERS = {"csv": ("csv", "powertrain.iotools.raw_csv", "write_raw_csv"),
           "hdf5": ("h5", "powertrain.iotools.raw_hdf5", "write_raw_hdf5"),
           "uff": ("uff", "powertrain.iotools.raw_uff", "write_raw_uff"),
           "mdf": ("mf4", "powertrain.iotools.raw_mdf", "write_raw_mdf")}
ANALYTIC_TOL_DB = 0.1
TOOLBOX_TOL_DB = 0.1
TACHO_TOL_DB = 0.05
VKF_TOL_DB = 0.5
COT_SMEAR_DB = 1.0
AS_VELOCITY_TOL_DB = 0.05


def write_copy(rec, fmt, folder, name):
    import importlib
    ext, module, func = WRITERS[fmt]
    path = Path(folder) / f"{name}.{ext}"
    getattr(importlib.import_module(module), func)(path, rec)
    return path


def track(path, *args):
    """Run ``powertrain track`` in-process; return (printed text, curves of the CSV)."""
    out = Path(str(path) + f".{abs(hash(args))}.csv")
    res = CliRunner().invoke(cli, ["track", str(path), "--csv", str(out), *args])
    if res.exit_code != 0:
        raise SystemExit(f"track {path} {' '.join(args)} failed: {res.output}")
    return res.output, read_measured(out) if "velocity" in " ".join(args) \
        else _read_any(out)


def _read_any(path):
    """Curves of a tracked CSV in its own quantity (no conversion): {(mount, dir, q): ...}."""
    curves = {}
    lines = [ln for ln in Path(path).read_text().splitlines() if ln and not ln.startswith("#")]
    factor = 1e-3 if lines[0].endswith("_mm_per_s") else 1.0
    for ln in lines[1:]:
        m, d, q, r, v = ln.split(",")
        rr, vv = curves.setdefault((m, d, q), ([], []))
        rr.append(float(r))
        vv.append(float(v) * factor)
    return {k: (np.array(r), np.array(v)) for k, (r, v) in curves.items()}


def curves_of(tracked):
    return tracked.curves if hasattr(tracked, "curves") else tracked


def db(a, b):
    return 20 * np.log10(np.asarray(a) / np.asarray(b))


def check_analytic(path):
    text, tr = track(path, "--quantity", "velocity", "--as", "velocity")
    worst = 0.0
    for o, a in zip(signals.ANALYTIC_ORDERS, signals.ANALYTIC_VELOCITY):
        _, lev = curves_of(tr)[("right", "z", f"order_{o:g}")]
        worst = max(worst, float(np.max(np.abs(db(lev, a / np.sqrt(2))))))
    return worst, text


def check_toolbox(path):
    spec = ",".join(f"{o:.17g}" for o in signals.TOOLBOX_ORDERS)
    text, tr = track(path, "--orders", spec)
    worst = 0.0
    for o, a in zip(signals.TOOLBOX_ORDERS, signals.TOOLBOX_AMPLITUDES):
        key = [k for k in curves_of(tr) if k[2] != "synthesis"
               and abs(float(k[2][6:]) - o) < 1e-4][0]
        _, lev = curves_of(tr)[key]
        worst = max(worst, float(np.max(np.abs(db(lev * np.sqrt(2), a)))))
    return worst, text


def check_tacho(path):
    _, by_rpm = track(path, "--quantity", "velocity")
    _, by_tacho = track(path, "--quantity", "velocity", "--tacho", "tacho",
                        "--pulses-per-rev", "4")
    worst = 0.0
    for key, (r1, v1) in curves_of(by_rpm).items():
        r2, v2 = curves_of(by_tacho)[key]
        common, i1, i2 = np.intersect1d(r1, r2, return_indices=True)
        worst = max(worst, float(np.max(np.abs(db(v2[i2], v1[i1])))))
    return worst


def check_as_velocity(path):
    _, acc = track(path, "--quantity", "acceleration", "--as", "velocity")
    _, vel = track(path, "--quantity", "velocity")
    worst = 0.0
    for (_, d, q), (_, v1) in curves_of(acc).items():
        r2, v2 = curves_of(vel)[("right", d, q)]
        worst = max(worst, float(np.max(np.abs(db(v1, v2)))))
    return worst


def check_crossing(path):
    _, cot = track(path, "--orders", "2", "--rpm-step", "25")
    _, vkf = track(path, "--orders", "2", "--rpm-step", "25", "--method", "vkf",
                   "--bandwidth", "0.5")
    e_cot = float(np.max(np.abs(db(curves_of(cot)[("left", "z", "order_2")][1] * np.sqrt(2), 1))))
    e_vkf = float(np.max(np.abs(db(curves_of(vkf)[("left", "z", "order_2")][1] * np.sqrt(2), 1))))
    return e_vkf, e_cot


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--formats", default="csv,hdf5,uff,mdf")
    args = ap.parse_args(argv)
    formats = [f.strip() for f in args.formats.split(",") if f.strip()]
    sources = {"analytic": signals.analytic_sweep(), "toolbox": signals.toolbox_example(),
               "crossing": signals.crossing()}
    fails, worst = [], {}
    with tempfile.TemporaryDirectory() as folder:
        for fmt in formats:
            paths = {k: write_copy(rec, fmt, folder, f"{k}-{fmt}") for k, rec in sources.items()}
            e_an, _ = check_analytic(paths["analytic"])
            e_tb, text = check_toolbox(paths["toolbox"])
            e_ta = check_tacho(paths["analytic"])
            e_av = check_as_velocity(paths["analytic"])
            e_vkf, e_cot = check_crossing(paths["crossing"])
            if fmt == formats[0]:
                print(f"powertrain track toolbox-example.{fmt} --orders 1,0.5,sqrt2,2:")
                print("\n".join("    " + ln for ln in text.splitlines()))
            rows = [("analytic sweep, 16 orders", e_an, e_an <= ANALYTIC_TOL_DB,
                     f"<= {ANALYTIC_TOL_DB} dB"),
                    ("toolbox example amplitudes", e_tb, e_tb <= TOOLBOX_TOL_DB,
                     f"<= {TOOLBOX_TOL_DB} dB"),
                    ("tacho vs rpm channel", e_ta, e_ta <= TACHO_TOL_DB, f"<= {TACHO_TOL_DB} dB"),
                    ("VKF through a tone crossing", e_vkf, e_vkf <= VKF_TOL_DB,
                     f"<= {VKF_TOL_DB} dB"),
                    ("COT through the crossing smears", e_cot, e_cot > COT_SMEAR_DB,
                     f"> {COT_SMEAR_DB} dB"),
                    ("acceleration --as velocity = velocity", e_av, e_av <= AS_VELOCITY_TOL_DB,
                     f"<= {AS_VELOCITY_TOL_DB} dB")]
            for name, err, ok, limit in rows:
                print(f"[{fmt:4}] {name:40s} max |error| {err:.4f} dB  ({limit}) "
                      f"{'ok' if ok else 'FAIL'}")
                worst[name] = max(worst.get(name, 0.0), err) if "smears" not in name \
                    else min(worst.get(name, np.inf), err)
                if not ok:
                    fails.append(f"{fmt}: {name}")
    n = 6 * len(formats)
    print(f"verify_order_tracking: {n - len(fails)}/{n} checks passed on "
          f"{', '.join(formats)}; analytic {worst['analytic sweep, 16 orders']:.4f} dB, "
          f"toolbox {worst['toolbox example amplitudes']:.4f} dB, tacho-vs-rpm "
          f"{worst['tacho vs rpm channel']:.4f} dB, VKF crossing "
          f"{worst['VKF through a tone crossing']:.3f} dB (COT "
          f"{worst['COT through the crossing smears']:.2f} dB), as-velocity "
          f"{worst['acceleration --as velocity = velocity']:.4f} dB")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
