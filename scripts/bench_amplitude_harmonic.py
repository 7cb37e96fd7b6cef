#!/usr/bin/env python
"""Benchmark: harmonic run-up with an amplitude law on every mount vs the linear one.

Issue 20, item 8: the harmonic solver with the amplitude law costs <= 5x the linear one.
Runs, in one process, on the default engine (or ``--engine``) and the same speeds:

* the linear harmonic run-up (``powertrain runup --solver harmonic``);
* the same run-up with every mount direction given the power law
  ``clip((0.1 mm / A)^0.15, [0.2, 5])`` (the issue's example law): the equivalent-linear
  fixed point per speed (:mod:`powertrain.solvers.equivalent_linear`), warm-started across
  speeds.

Both warm (one untimed run each first), best of ``--repeat`` wall-clock runs of the whole
run-up (load sampling, assembly and solve alike); the solver-only ratio (the summed
per-speed solve times, ``RunupResult.solver_seconds``) is printed too. Prints the largest
change of the synthesis velocity the law makes (a check that the law acted), and last::

    linear_s=... amplitude_s=... solver_ratio=... ratio=...
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics.mount_laws import PowerLaw
from powertrain.workflows.arguments import default_rpm
from powertrain.workflows.runup import run_runup

#: The issue's example law: reference 0.1 mm, exponent 0.15, limits [0.2, 5].
LAW = PowerLaw(1e-4, 0.15, (0.2, 5.0))


def with_law(engine, law):
    """The engine with ``law`` on every direction of every mount."""
    mounts = [dataclasses.replace(m, directions={d: dataclasses.replace(model, amplitude_law=law)
                                                 for d, model in m.directions.items()})
              for m in engine.mounts]
    return engine.replace(mounts=mounts)


def best_time(engine, rpm, repeat):
    """(best wall-clock [s] of the whole harmonic run-up, its result)."""
    run_runup(engine, rpm, solver="harmonic")                       # warm
    best, result = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = run_runup(engine, rpm, solver="harmonic")
        best = min(best, time.perf_counter() - t0)
    return best, result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engine", default=str(DEFAULT_ENGINE_PATH))
    ap.add_argument("--repeat", type=int, default=3, help="timed runs each (best counts)")
    args = ap.parse_args()
    engine = read_engine(args.engine)
    rpm = default_rpm()
    t_lin, lin = best_time(engine, rpm, args.repeat)
    t_amp, amp = best_time(with_law(engine, LAW), rpm, args.repeat)
    v_lin, v_amp = lin.synthesis_rms("velocity"), amp.synthesis_rms("velocity")
    change = float(np.max(np.abs(v_amp / v_lin - 1)))
    print(f"speeds: {len(rpm)} ({rpm[0]:g}..{rpm[-1]:g} rpm), law {LAW} on every mount direction")
    print(f"largest change of a synthesis velocity by the law: {100 * change:.1f} %")
    solver_ratio = amp.solver_seconds / lin.solver_seconds
    print(f"linear_s={t_lin:.3f} amplitude_s={t_amp:.3f} solver_ratio={solver_ratio:.2f} "
          f"ratio={t_amp / t_lin:.2f}")


if __name__ == "__main__":
    main()
