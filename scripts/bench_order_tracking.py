"""Benchmark: order tracking of a 60 s, 16-channel, 25.6 kHz run-up (issue 12, item 8).

Ours: :func:`powertrain.workflows.tracking.track_recording` (speed from the rpm channel, computed
order tracking with the fused anti-alias/angle-resampling Numba kernel, exact-order Hann
spectra per block; Numba threads on all cores).
Peer: a plain scipy implementation of the same analysis doing the same work -- like ours it
processes only the blocks it analyses (one block of B revolutions per grid speed, about a
quarter of the record), not the whole record: per block, an 8th-order Butterworth anti-alias
(``sosfiltfilt``, all channels at once) at 1.6x the highest tracked frequency (passband droop
< 0.01 dB) over the block's time span plus a margin for the filter's start-up transient,
angle from the integrated rpm, cubic-spline resampling of the block to a uniform angle grid
(``CubicSpline``), a Hann-windowed ``rfft`` and the bins of the orders (single-threaded, as
scipy runs it).

Both track orders 0.5..8 every 50 rpm on the same synthetic signal (orders with known
amplitudes plus broadband noise; SYNTHETIC) and their worst error against the known
amplitudes is printed, so the two do the same work to a comparable accuracy.

Ours runs twice: with Numba's threads on all cores, and with one thread (the peer is
single-threaded, so that pair compares the same work on the same resources).

Usage: python scripts/bench_order_tracking.py [--duration 60] [--channels 16]
Prints throughput (samples/s) of each and, last, the ratios.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks.signals import linear_sweep, order_sum
from powertrain.analysis.order_tracking import block_revolutions
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.workflows.tracking import track_recording

FS = 25600.0
ORDERS = np.arange(1, 17) * 0.5
RPM0, RPM1 = 1000.0, 6000.0
RPM_STEP = 50.0
#: Samples filtered beyond each end of a block, in periods of the anti-alias cut-off: the
#: zero-phase Butterworth's start-up transient has decayed there (the printed worst error of
#: the peer equals the whole-record version's).
FILTER_MARGIN_CYCLES = 40


def make_recording(duration, n_channels, seed=1):
    t, rpm, theta = linear_sweep(FS, duration, RPM0, RPM1)
    rng = np.random.default_rng(seed)
    amps = 1.0 + 0.1 * np.arange(ORDERS.size)
    clean = order_sum(theta, ORDERS, amps)
    block = clean[None, :] + 0.05 * rng.standard_normal((n_channels, t.size))
    chans = [RawChannel(f"m{c}.z", f"m{c}", "active", "z", "acceleration", block[c], "m/s^2")
             for c in range(n_channels)]
    return RawRecording(t, chans, rpm, None, "bench", ["SYNTHETIC"]), amps


def plain_scipy(rec, orders, rpm_step):
    """Plain scipy computed order tracking of the analysed blocks only (module docstring)."""
    from scipy.integrate import cumulative_trapezoid
    from scipy.interpolate import CubicSpline
    from scipy.signal import butter, sosfiltfilt
    t, rpm = rec.time, rec.rpm
    fs = rec.sample_rate
    B = block_revolutions(orders)
    fc = 1.6 * orders.max() * rpm.max() / 60.0
    S = int(2 ** np.ceil(np.log2(2.5 * fc * 60.0 / rpm.min())))
    sos = butter(8, fc, fs=fs, output="sos")
    margin = int(np.ceil(FILTER_MARGIN_CYCLES * fs / fc))
    angle = cumulative_trapezoid(rpm * 2 * np.pi / 60.0, t, initial=0.0)
    grid = RPM_STEP * np.arange(np.ceil(rpm.min() / rpm_step), np.floor(rpm.max() / rpm_step) + 1)
    N = B * S
    starts = np.interp(grid, rpm, angle) - N // 2 * (2 * np.pi / S)
    ok = (starts >= 0) & (starts + N * 2 * np.pi / S <= angle[-1])
    grid, starts = grid[ok], starts[ok]
    w = np.hanning(N + 1)[:-1]
    bins = np.round(orders * B).astype(int)
    X = np.array([ch.values for ch in rec.channels])
    out = np.empty((grid.size, len(rec.channels), orders.size))
    for i, start in enumerate(starts):
        t_u = np.interp(start + np.arange(N) * (2 * np.pi / S), angle, t)
        lo = max(0, int(t_u[0] * fs) - margin)
        hi = min(t.size, int(t_u[-1] * fs) + 2 + margin)
        xf = sosfiltfilt(sos, X[:, lo:hi], axis=1)
        xu = CubicSpline(t[lo:hi], xf, axis=1)(t_u)
        spec = np.fft.rfft(xu * w, axis=1)
        out[i] = np.abs(spec[:, bins]) * 2.0 / w.sum() / np.sqrt(2.0)
    return grid, out


def timed(func, *args, **kwargs):
    """(result, wall seconds, CPU seconds summed over threads) of one call."""
    t0, c0 = time.perf_counter(), time.process_time()
    result = func(*args, **kwargs)
    return result, time.perf_counter() - t0, time.process_time() - c0


def report(label, wall, cpu, n_samples, speeds, error):
    print(f"{label}: wall {wall:.2f} s = {n_samples / wall / 1e6:.1f} M samples/s; CPU "
          f"{cpu:.2f} s = {n_samples / cpu / 1e6:.0f} M samples per CPU-second; {speeds} "
          f"speeds, worst error {error:.3f} dB")


def main(argv=None):
    import numba
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--channels", type=int, default=16)
    args = ap.parse_args(argv)
    rec, amps = make_recording(args.duration, args.channels)
    n_samples = rec.time.size * len(rec.channels)
    small, _ = make_recording(2.0, 2)
    track_recording(small, ORDERS, rpm_step=500.0)                 # JIT warm-up (cached)
    ours, t_ours, c_ours = timed(track_recording, rec, ORDERS, rpm_step=RPM_STEP)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    _, t_one, c_one = timed(track_recording, rec, ORDERS, rpm_step=RPM_STEP)
    numba.set_num_threads(threads)
    (grid, peer), t_peer, c_peer = timed(plain_scipy, rec, ORDERS, RPM_STEP)
    ref = amps / np.sqrt(2.0)
    e_ours = np.max(np.abs(20 * np.log10(ours.order_rms() / ref)))
    e_peer = np.max(np.abs(20 * np.log10(peer / ref)))
    print(f"run-up {RPM0:g}->{RPM1:g} rpm, {args.duration:g} s, {len(rec.channels)} channels "
          f"at {FS:g} Hz = {n_samples / 1e6:.1f} M samples; orders 0.5..8, every "
          f"{RPM_STEP:g} rpm; {os.cpu_count()} cores (shared machine: other jobs running)")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores: wall-clock "
          "figures are inflated by other jobs when it exceeds the core count; CPU time is "
          "summed over threads")
    report(f"ours (powertrain, COT, Numba, {threads} threads)", t_ours, c_ours, n_samples,
           ours.rpm.size, e_ours)
    report("ours (1 Numba thread)", t_one, c_one, n_samples, ours.rpm.size, e_ours)
    report("plain scipy, analysed blocks only (sosfiltfilt + CubicSpline + rfft per block)",
           t_peer, c_peer, n_samples, grid.size, e_peer)
    print(f"single-thread ratio (plain scipy / ours with 1 thread, wall): {t_peer / t_one:.1f}x")
    print(f"CPU-time ratio (plain scipy / ours): {c_peer / c_ours:.1f}x")
    print(f"ratio (plain scipy wall time / ours): {t_peer / t_ours:.1f}x")


if __name__ == "__main__":
    main()
