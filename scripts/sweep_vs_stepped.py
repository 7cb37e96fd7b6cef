"""Continuous run-up (simulated sweep, tracked) against the stepped harmonic run-up.

1. Simulates a linear sweep of the default engine (``powertrain.solvers.speed_ramp``: Newmark in
   time, speed-dependent load), tracks its mount-point accelerations like measured data
   (computed order tracking, 50 rpm grid, speed and phase from its tacho as ``runup
   --sweep`` tracks it, converted to velocity order by order) and
   compares orders 2, 4 and the synthesis of the nine channels with the stepped harmonic
   run-up at the same speeds (an independent path: frequency-domain steady state per
   order). Slow sweeps must agree: median |gap| <= 0.2 dB (issue 12, done-when).
2. Shows how resonance peaks shift and smear at faster sweeps (``--plot``, default
   docs/sweep-rates.png). The default engine's rigid-body modes (6-11 Hz) lie below order 2
   at 1000 rpm, so its order curves have no resonance peak in the run-up range; the plot
   uses the default engine with every mount stiffness scaled by ``--plot-stiffness`` (20:
   modes 26-51 Hz, order 2 crosses them at 800-1550 rpm) -- a what-if variant, labelled so
   -- and the channel and order with the most pronounced peak of its stepped run-up.

Usage: python scripts/sweep_vs_stepped.py [--rate 25] [--from 1000] [--to 6000]
       [--fast 200,800] [--plot docs/sweep-rates.png]
Prints the gaps and peak positions and, last, the median gaps of the slow sweep.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.solvers.speed_ramp import simulate_sweep
from powertrain.workflows.runup import SWEEP_TRACKING, run_runup
from powertrain.workflows.tracking import track_recording

LIMIT_DB = 0.2
QUANTITIES = ("order_2", "order_4", "synthesis")


def tracked_sweep(engine, rpm_from, rpm_to, rate):
    t0 = time.perf_counter()
    rec = simulate_sweep(engine, rpm_from, rpm_to, rate)
    t1 = time.perf_counter()
    tr = track_recording(rec, **SWEEP_TRACKING).as_velocity()
    return tr, t1 - t0, time.perf_counter() - t1


def gaps(tracked, stepped):
    """|20 log10(sweep/stepped)| [dB] per quantity over channels and speeds."""
    out = {}
    for q in QUANTITIES:
        d = [20 * np.log10(tracked.curve(f"{m}.{d}", q) / stepped.curve(m, d, q))
             for m, d in stepped.channels]
        out[q] = np.abs(np.concatenate(d))
    return out


def most_resonant(stepped, flank=200.0):
    """(channel, order) whose stepped curve has the highest peak over its flanks (curves
    above 10 % of the strongest one only)."""
    best, key = 0.0, None
    rpm = stepped.rpm
    top = stepped.order_rms("velocity").max()
    for m, d in stepped.channels:
        for o in stepped.orders:
            y = stepped.curve(m, d, f"order_{o:g}")
            if y.max() < 0.1 * top:
                continue
            for i in np.flatnonzero((rpm > rpm[0] + flank) & (rpm < rpm[-1] - flank)):
                lo, hi = np.interp([rpm[i] - flank, rpm[i] + flank], rpm, y)
                if y[i] >= y[max(i - 1, 0)] and y[i] >= y[min(i + 1, y.size - 1)]:
                    prom = y[i] / np.sqrt(lo * hi)
                    if prom > best:
                        best, key = prom, (f"{m}.{d}", f"order_{o:g}")
    return key


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rate", type=float, default=25.0, help="slow sweep rate [rpm/s]")
    ap.add_argument("--from", dest="rpm_from", type=float, default=1000.0)
    ap.add_argument("--to", dest="rpm_to", type=float, default=6000.0)
    ap.add_argument("--fast", default="200,1000", help="faster rates to plot [rpm/s]")
    ap.add_argument("--plot", default="docs/sweep-rates.png")
    ap.add_argument("--plot-stiffness", type=float, default=20.0,
                    help="mount stiffness factor of the plotted variant")
    ap.add_argument("--plot-from", type=float, default=1000.0)
    ap.add_argument("--plot-to", type=float, default=2200.0)
    args = ap.parse_args(argv)
    engine = read_engine(DEFAULT_ENGINE_PATH)
    slow, t_sim, t_track = tracked_sweep(engine, args.rpm_from, args.rpm_to, args.rate)
    stepped = run_runup(engine, slow.rpm, solver="harmonic")
    g = gaps(slow, stepped)
    print(f"sweep {args.rpm_from:g}->{args.rpm_to:g} rpm at {args.rate:g} rpm/s: simulated in "
          f"{t_sim:.1f} s, tracked in {t_track:.2f} s, {slow.rpm.size} speeds "
          f"{slow.rpm[0]:g}..{slow.rpm[-1]:g} rpm x 9 channels")
    for q in QUANTITIES:
        print(f"  {q:10s} |gap| to stepped harmonic: median {np.median(g[q]):.4f} dB, "
              f"95th percentile {np.percentile(g[q], 95):.4f} dB, max {g[q].max():.4f} dB")
    from powertrain.workflows.operations import apply_operations
    from powertrain.workflows.variants import parse_operations
    stiff = apply_operations(engine, parse_operations(
        {"scale": [f"*.*.stiffness={args.plot_stiffness:g}"]}))
    base, _, _ = tracked_sweep(stiff, args.plot_from, args.plot_to, args.rate)
    ref_run = run_runup(stiff, base.rpm, solver="harmonic")
    label, q = most_resonant(ref_run)
    m, d = label.split(".")
    y_ref = ref_run.curve(m, d, q)
    modes = ", ".join(f"{f:.0f}" for f in ref_run.rigid_body_modes_hz)
    print(f"plot: default engine, mount stiffness x{args.plot_stiffness:g} (rigid-body modes "
          f"{modes} Hz); {label} {q}, stepped peak at {ref_run.rpm[np.argmax(y_ref)]:g} rpm")
    curves = [("stepped harmonic", ref_run.rpm, y_ref)]
    for rate in [args.rate] + [float(r) for r in args.fast.split(",") if r.strip()]:
        fast = base if rate == args.rate else tracked_sweep(stiff, args.plot_from,
                                                             args.plot_to, rate)[0]
        y = fast.curve(label, q)
        ref = np.interp(fast.rpm, ref_run.rpm, y_ref)
        print(f"  sweep {rate:g} rpm/s: peak at {fast.rpm[np.argmax(y)]:g} rpm, peak level "
              f"{20 * np.log10(y.max() / y_ref.max()):+.2f} dB vs stepped; median |gap| "
              f"{np.median(np.abs(20 * np.log10(y / ref))):.3f} dB")
        curves.append((f"sweep {rate:g} rpm/s", fast.rpm, y))
    if args.plot:
        from powertrain.plotting.orders import plot_sweep_rates
        plot_sweep_rates(curves, args.plot, title=f"{label} {q.replace('_', ' ')}, mount "
                         f"stiffness x{args.plot_stiffness:g}: stepped run-up vs continuous "
                         "sweeps (simulated, tracked)")
        print(f"wrote {args.plot}")
    ok = all(np.median(g[q]) <= LIMIT_DB for q in QUANTITIES)
    print(f"sweep {args.rate:g} rpm/s vs stepped harmonic, median |gap|: order 2 "
          f"{np.median(g['order_2']):.4f} dB, order 4 {np.median(g['order_4']):.4f} dB, "
          f"synthesis {np.median(g['synthesis']):.4f} dB (limit {LIMIT_DB} dB): "
          f"{'ok' if ok else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
