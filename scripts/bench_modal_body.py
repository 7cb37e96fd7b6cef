"""Run-up time with a modal body of 20 modes against the rigid-body run-up (issue 13: within 2x).

The 20 body modes are made up for the timing (frequencies 25-400 Hz, damping 2-5 %, modal
masses 5-60 kg, random shapes at the mount attachment points and one body point; seeded);
the engine is engines/default.toml. Both run-ups use the default Newmark solver (modal
stepper), 1000-6000 rpm in 500 rpm steps; the best of three runs of each is taken.

Usage: python scripts/bench_modal_body.py
Prints both times and, last, the ratio modal-body / rigid.
"""

from __future__ import annotations

import time

import numpy as np

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.models.chassis import BodyMode, Chassis
from powertrain.workflows.runup import run_runup

N_MODES = 20


def made_up_body(mount_names, n_modes=N_MODES, seed=13):
    rng = np.random.default_rng(seed)
    names = list(mount_names) + ["seat_rail"]
    modes = tuple(BodyMode(frequency=f, damping_ratio=rng.uniform(0.02, 0.05),
                           modal_mass=rng.uniform(5.0, 60.0),
                           shapes={n: rng.normal(size=3) for n in names})
                  for f in np.geomspace(25.0, 400.0, n_modes))
    return Chassis(model="modal", modes=modes, points=("seat_rail",))


def best_of(fn, n=3):
    best = np.inf
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    rigid = read_engine(DEFAULT_ENGINE_PATH)
    modal = rigid.replace(chassis=made_up_body(rigid.mount_names))
    run_runup(rigid)
    run_runup(modal)                                    # warm up (Numba, caches)
    t_rigid = best_of(lambda: run_runup(rigid))
    t_modal = best_of(lambda: run_runup(modal))
    print(f"rigid body: {t_rigid:.3f} s ({rigid.assemble().n_dof} degrees of freedom)")
    print(f"modal body, {N_MODES} modes: {t_modal:.3f} s ({modal.assemble().n_dof} degrees "
          "of freedom, body side and body point included)")
    print(f"ratio modal/rigid: {t_modal / t_rigid:.2f}")


if __name__ == "__main__":
    main()
