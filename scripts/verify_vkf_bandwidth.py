"""Vold-Kalman default bandwidth against swept single-DOF resonances (issue 18, item 5).

Order 2 sweeps 1000 -> 6000 rpm at 100 and 500 rpm/s through a resonance at 50 or 150 Hz with
damping 0.005 ... 0.05 (:func:`benchmarks.signals.swept_resonance`, the exact response on the
sample grid). For each case the peak of the tracked order 2 is compared with the peak of the
fine-grid envelope of the response, for the default bandwidth (only order 2 tracked, so the
order-spacing rule does not bind) and for the former fixed 0.5 Hz; COT for reference.

Usage: python scripts/verify_vkf_bandwidth.py
Prints one line per case and, last, the worst default-bandwidth peak error.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks import signals
from powertrain.workflows.tracking import track_recording

FS = 4096.0
#: Limit on the default bandwidth's peak error [dB] (tests/tolerances.py VKF_RESONANCE_DB).
LIMIT_DB = 0.5


def peak_db(tracked, envelope, fn):
    """Tracked peak re the fine-grid envelope's [dB], as text; 'dropped' when the resonance
    speed lies in the record ends the tracker does not report."""
    if not tracked.rpm[0] < fn * 60.0 / 2.0 < tracked.rpm[-1]:
        return "dropped (in the ends not reported)", None
    err = float(20 * np.log10(np.abs(tracked.amplitude[:, 0, 0]).max() / envelope.max()))
    return f"{err:+.2f} dB", err


def main():
    worst = 0.0
    for rate in (100.0, 500.0):
        for fn in (50.0, 150.0):
            for zeta in (0.005, 0.01, 0.02, 0.05):
                rec, env = signals.swept_resonance(FS, 5000.0 / rate, 1000.0, 6000.0, 2.0,
                                                   fn, zeta)
                vkf = track_recording(rec, [2.0], rpm_step=5.0, method="vkf")
                old = track_recording(rec, [2.0], rpm_step=5.0, method="vkf",
                                      bandwidth_hz=0.5)
                cot = track_recording(rec, [2.0], rpm_step=5.0)
                lo, hi = vkf.settings["bandwidth_hz_range"]
                text, err = peak_db(vkf, env, fn)
                worst = min(worst, -np.inf if err is None else err)
                print(f"{rate:3.0f} rpm/s, {fn:3.0f} Hz, damping {zeta:<5g}: peak vs fine grid "
                      f"VKF default ({lo:.2g}..{hi:.2g} Hz) {text}, VKF 0.5 Hz "
                      f"{peak_db(old, env, fn)[0]}, COT {peak_db(cot, env, fn)[0]}")
    ok = abs(worst) <= LIMIT_DB
    print(f"verify_vkf_bandwidth: worst default-bandwidth peak {worst:+.2f} dB "
          f"(limit {LIMIT_DB} dB): {'ok' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
