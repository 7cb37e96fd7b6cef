#!/usr/bin/env python
"""CPU time of the continuous sweep (``runup --sweep``) of the default engine, linear and with
Berg's friction on every mount (issue 20, item 8: 1000 -> 6000 rpm at 50 rpm/s, 100 s
simulated: <= 2 CPU-seconds warm linear, <= 4 with friction), in one process.

Both run :func:`powertrain.solvers.speed_ramp.simulate_sweep` as the command does (load
table, integration, decimation to 8192 Hz), warm (the Numba kernels compiled and cached by
a short sweep first), timed by ``time.process_time``. The linear model is integrated in
modal form (one fused kernel: load interpolation, recurrence, outputs); with friction in
physical coordinates, engine cycle by engine cycle, Newton per step in the kernel. The
parts of the linear sweep (the load table, which evaluates the engine model at 201 speeds x
1440 angles, the kernel, the decimation) are printed too.

Last line: ``linear_cpu_s=... friction_cpu_s=... ratio=...`` (friction over linear).
"""

from __future__ import annotations

import argparse
import collections
import time

from bench_nonlinear_runup import BERG, with_laws

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.solvers import speed_ramp


def timed_parts():
    """Wrap the linear sweep's parts to sum their CPU time."""
    parts = collections.Counter()

    def wrap(owner, name):
        inner = getattr(owner, name)

        def timed(*args, **kwargs):
            t0 = time.process_time()
            out = inner(*args, **kwargs)
            parts[name] += time.process_time() - t0
            return out
        setattr(owner, name, timed)

    wrap(speed_ramp, "_load_table")
    wrap(speed_ramp._Decimator, "push")
    return parts


def cpu_sweep(engine, rpm_from, rpm_to, rate):
    """CPU seconds of one sweep."""
    t0 = time.process_time()
    speed_ramp.simulate_sweep(engine, rpm_from, rpm_to, rate)
    return time.process_time() - t0


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--from", dest="rpm_from", type=float, default=1000.0)
    p.add_argument("--to", dest="rpm_to", type=float, default=6000.0)
    p.add_argument("--rate", type=float, default=50.0)
    args = p.parse_args()
    engine = read_engine(DEFAULT_ENGINE_PATH)
    span = (args.rpm_from, args.rpm_to, args.rate)
    rough = with_laws(engine, port_law=BERG)
    for model in (engine, rough):               # warm: the kernels compiled and cached
        speed_ramp.simulate_sweep(model, args.rpm_from, args.rpm_from + 100.0, 100.0)
    parts = timed_parts()
    linear = cpu_sweep(engine, *span)
    table, decimation = parts["_load_table"], parts["push"]
    print(f"linear sweep {args.rpm_from:g}->{args.rpm_to:g} rpm at {args.rate:g} rpm/s: "
          f"{linear:.2f} CPU-s (target 2): load table {table:.2f} s, decimation "
          f"{decimation:.2f} s, integration and the rest {linear - table - decimation:.2f} s")
    friction = cpu_sweep(rough, *span)
    print(f"with Berg's friction on every mount: {friction:.2f} CPU-s (target 4)")
    print(f"linear_cpu_s={linear:.3f} friction_cpu_s={friction:.3f} "
          f"ratio={friction / linear:.2f}")


if __name__ == "__main__":
    main()
