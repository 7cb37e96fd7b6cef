#!/usr/bin/env python
"""Time-domain run-up with Berg's friction on every mount against the linear one (issue 20,
item 8: <= 3x), in one process.

Both are the whole default run-up (1000..6000 rpm, 500 rpm steps, six cycles, 1 deg) as
``powertrain runup`` runs it, warm (the Numba kernels compiled and cached before timing),
CPU time (``time.process_time``), best of ``--repeat``:

* linear: the default engine, Newmark (auto: the modal recurrence; the dense kernel's time is
  printed too);
* friction: every mount direction with Berg's element (40 N, x2 = 0.05 mm) in parallel,
  Newmark (auto: the modal recurrence with the port laws, Newton per step in the kernel,
  outputs over the processed window only), each speed started from the harmonic fixed point
  with the friction on its steady loop; with the power amplitude law too (printed: its
  networks change scale cycle by cycle, so that run is dense).

Last line: ``linear_s=... friction_s=... ratio=...``.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
import warnings

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.models.mount import MountModel
from powertrain.physics.mount_laws import BergFriction, PowerLaw
from powertrain.workflows.runup import run_runup

BERG = BergFriction(max_force=40.0, half_displacement=5e-5)
POWER = PowerLaw(reference=1e-4, exponent=0.15, limits=(0.2, 5.0))


def with_laws(engine, **laws):
    """The engine with every mount direction carrying ``laws``."""
    mounts = [dataclasses.replace(m, directions={
        a: MountModel(mod.topology, dict(mod.params), name=mod.name, **laws)
        for a, mod in m.directions.items()}) for m in engine.mounts]
    return dataclasses.replace(engine, mounts=mounts)


def cpu_seconds(engine, repeat, **kwargs):
    """Best CPU time of the whole run-up over ``repeat`` runs (after a warm-up)."""
    run_runup(engine, [3000.0], **kwargs)
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        run_runup(engine, **kwargs)
        best = min(best, time.process_time() - t0)
    return best


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    warnings.simplefilter("ignore")          # periodicity warnings: printed by the tests
    engine = read_engine(DEFAULT_ENGINE_PATH)
    linear = cpu_seconds(engine, args.repeat)
    dense = cpu_seconds(engine, args.repeat, stepper="dense")
    friction = cpu_seconds(with_laws(engine, port_law=BERG), args.repeat)
    both = cpu_seconds(with_laws(engine, port_law=BERG, amplitude_law=POWER), args.repeat)
    print(f"linear run-up (modal): {linear:.3f} s; dense kernel: {dense:.3f} s")
    print(f"friction on every mount: {friction:.3f} s; with the power amplitude law too: "
          f"{both:.3f} s ({both / linear:.2f}x)")
    print(f"linear_s={linear:.4f} friction_s={friction:.4f} ratio={friction / linear:.2f}")


if __name__ == "__main__":
    main()
