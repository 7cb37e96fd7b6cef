#!/usr/bin/env python
"""CPU time of transient manoeuvres (issue 38), in one process, warm (the Numba kernels
compiled and cached before timing), ``time.process_time``, best of ``--repeat``:

* the 3 s start of ``examples/start.toml`` (0 -> cranking -> flare to 1150 rpm -> idle) on
  the default engine, linear mounts;
* the same start with a static curve, the power amplitude law and Berg's friction on every
  mount direction (each direction's curve the z-nonlinear mount's shape scaled to its own
  static stiffness, reference deflection 0; amplitude law and friction as
  scripts/bench_nonlinear_runup.py);
* against ``solve_ivp``: the independent check of tests/test_transient.py (6-DOF body,
  Kelvin-Voigt mounts, one direction with static curve, amplitude law and friction;
  tests/transient_oracle.py), over a 0.3 s flare from rest: Radau at rtol 1e-8 (the
  reference); each of :data:`METHODS` at rtol 1e-2, 1e-3, ... until its error is at most
  ours, the fastest of them counting; ours at 1 deg, error of each against the rtol 1e-8 run
  (deflection and force of that direction, relative to their peaks). Both are timed from
  the engine and the manoeuvre (the peer's time includes computing the manoeuvre's load),
  best of ``--repeat``.

Last line: ``linear_s=... nonlinear_s=... newmark_s=... solve_ivp_s=... ratio=...
solve_ivp_method=... solve_ivp_rtol=...``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_nonlinear_runup import BERG, POWER

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.manoeuvre_file import read_manoeuvre
from powertrain.models.manoeuvre import Manoeuvre
from powertrain.models.mount import MountModel
from powertrain.physics.mount_laws import StaticCurve
from powertrain.solvers.transient import STRETCH, simulate_transient
from powertrain.solvers.transient_load import transient_load

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from transient_oracle import Oracle, integrate, write_case  # noqa: E402

#: The z-nonlinear mount's curve shape [mm, N] and its tangent at 0 [N/mm].
SHAPE_MM = (-12.0, -9.0, -7.0, -5.0, -3.0, 0.0, 3.0, 6.0, 9.0)
SHAPE_N = (-2743.42, -1419.01, -851.41, -586.52, -359.48, 0.0, 312.18, 662.2, 1419.01)


def fully_nonlinear(engine):
    """Every mount direction with a static curve, the power law and Berg's friction."""
    tangent0 = float(StaticCurve(tuple(x * 1e-3 for x in SHAPE_MM), SHAPE_N).tangent_at(0.0))

    def model(mod):
        k0 = mod.static_stiffness()
        curve = StaticCurve(tuple(x * 1e-3 for x in SHAPE_MM),
                            tuple(f * k0 / tangent0 for f in SHAPE_N), 0.0)
        return MountModel(mod.topology, dict(mod.params), name=mod.name, port_law=BERG,
                          amplitude_law=POWER, static_curve=curve)
    mounts = [dataclasses.replace(m, directions={a: model(mod) for a, mod in
                                                 m.directions.items()})
              for m in engine.mounts]
    return dataclasses.replace(engine, mounts=mounts)


def best_cpu(run, repeat):
    run()
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        run()
        best = min(best, time.process_time() - t0)
    return best


def peer_case(folder, seconds=0.3):
    engine = read_engine(write_case(folder, Path(DEFAULT_ENGINE_PATH).read_text()))
    system = engine.assemble()
    w = 1200.0 * np.pi / 30.0
    m = Manoeuvre("flare", np.array([0.0, seconds]), np.array([0.0, w]),
                  np.array([0.0, seconds]), np.zeros(2), crank_inertia=0.3)
    return engine, system, m


def errors(u, f, u_ref, f_ref):
    return max(np.max(np.abs(u - u_ref)) / np.max(np.abs(u_ref)),
               np.max(np.abs(f - f_ref)) / np.max(np.abs(f_ref)))


#: solve_ivp's methods tried (stiff and explicit: the 6-DOF case is not stiff) and its
#: tolerances, loosest first.
METHODS = ("Radau", "BDF", "LSODA", "RK45")
RTOLS = 10.0 ** -np.arange(2, 8)


def against_solve_ivp(repeat):
    """(ours [s], error, best solve_ivp [s] at an error <= ours, its method and rtol).

    Both are timed from the engine and the manoeuvre to the histories, so the peer's time
    includes the manoeuvre's load (which ours computes too); both best of ``repeat``."""
    with tempfile.TemporaryDirectory() as tmp:
        engine, system, m = peer_case(Path(tmp))
        net = system.network_names.index("left.z")
        ch = [f"{a}.{b}" for a, b in system.channels].index("left.z")
        ours_s = best_cpu(lambda: simulate_transient(engine, m, system=system), repeat)
        run = simulate_transient(engine, m, system=system)
        every = max(1, round(STRETCH / (run.load.t[1] - run.load.t[0])))

        def peer(method, rtol):
            load = transient_load(engine, m, run.load.t)
            return integrate(StretchODE(engine, system, load.t, load.F, net), every, rtol,
                             method)
        u_ref, f_ref = peer("Radau", 1e-8)
        err = errors(run.deflection[:, net], run.force[:, ch], u_ref, f_ref)
        print(f"ours (Newmark 1 deg) on the 6-DOF case: {ours_s:.4f} s, error {err:.2e} "
              "against Radau rtol 1e-8")
        best = (float("inf"), "none", float("nan"))
        for method in METHODS:
            for rtol in RTOLS:
                u, f = peer(method, rtol)
                e = errors(u, f, u_ref, f_ref)
                if e <= err:
                    seconds = best_cpu(lambda: peer(method, rtol), repeat)  # noqa: B023
                    print(f"solve_ivp {method} rtol {rtol:.0e}: {seconds:.3f} s, error {e:.2e}")
                    best = min(best, (seconds, method, rtol))
                    break
            else:
                print(f"solve_ivp {method}: error above ours down to rtol {RTOLS[-1]:.0e}")
        return ours_s, err, *best


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    engine = read_engine(DEFAULT_ENGINE_PATH)
    start = read_manoeuvre(ROOT / "examples" / "start.toml")
    linear = best_cpu(lambda: simulate_transient(engine, start), args.repeat)
    nonlinear_engine = fully_nonlinear(engine)
    run = simulate_transient(nonlinear_engine, start)
    nonlinear = best_cpu(lambda: simulate_transient(nonlinear_engine, start), args.repeat)
    print(f"3 s start ({run.load.t.size - 1} steps): linear {linear:.3f} s; static curve, "
          f"amplitude law and friction on every mount {nonlinear:.3f} s ({run.method})")
    ours_s, err, peer_s, method, rtol = against_solve_ivp(args.repeat)
    print(f"linear_s={linear:.4f} nonlinear_s={nonlinear:.4f} newmark_s={ours_s:.4f} "
          f"solve_ivp_s={peer_s:.3f} ratio={peer_s / ours_s:.0f} "
          f"solve_ivp_method={method} solve_ivp_rtol={rtol:.0e}")


if __name__ == "__main__":
    main()
