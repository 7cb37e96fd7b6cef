"""Time of the damped modes (``powertrain modes``, warm) against one eigensolve of the same model.

Both start from the same assembled model (:meth:`powertrain.models.engine.Engine.assemble`:
rigid body, the mount networks' internal degrees of freedom, body modes of a modal chassis).
Peer: every eigenvalue and eigenvector of its first-order form
``[[0, I], [-K, -C]] x = s [[I, 0], [0, M]] x`` (``scipy.linalg.eig``), which leaves the
rigid-body modes still to be picked out. Ours: the modes as ``powertrain modes`` reports them
(:func:`powertrain.solvers.modes.rigid_body_modes`: the static modes, the eigenvalues of the
same model, each static mode's damped root picked, energies, pairing, torque-roll angles).
Also printed: the whole library call (:func:`powertrain.workflows.modes.modes`, the assembly
included) and ``--static``.

Every time is the best of ``REPEATS`` calls, ours and the peer's interleaved, so that a load
from other processes falls on both alike.

Usage: python scripts/bench_modes.py [ENGINE_FILE]   (default engines/default-torque-rod.toml)
Prints the warm times and, last, the ratio peer / ours.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.solvers.modes import rigid_body_modes
from powertrain.workflows.modes import modes as engine_modes

REPEATS = 30


def best_times(functions, repeats=REPEATS):
    """The best wall time [s] of each function, the functions called in turn."""
    times = [[] for _ in functions]
    for _ in range(repeats):
        for fn, out in zip(functions, times):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
    return [min(t) for t in times]


def main(argv):
    path = argv[1] if len(argv) > 1 else Path(DEFAULT_ENGINE_PATH).parent / "default-torque-rod.toml"
    engine = read_engine(path)
    system = engine.assemble()
    n = system.n_dof
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-system.K, -system.C]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), system.M]])
    inertia = engine.body.inertia
    engine_modes(engine)                                   # warm up
    ours, whole, whole_static, peer = best_times([
        lambda: rigid_body_modes(system, inertia),
        lambda: engine_modes(engine),
        lambda: engine_modes(engine, static=True),
        lambda: sla.eig(A, B)])
    print(f"engine: {engine.name} ({len(engine.mounts)} mounts, {n} degrees of freedom)")
    print(f"modes --static, whole call (assembly included): {whole_static * 1e3:.2f} ms")
    print(f"modes, whole call (assembly included): {whole * 1e3:.2f} ms "
          f"(ratio peer/whole call: {peer / whole:.2f})")
    print(f"modes on the assembled model: {ours * 1e3:.2f} ms")
    print(f"peer (full state-space eig, scipy.linalg.eig): {peer * 1e3:.2f} ms")
    print(f"ratio peer/ours: {peer / ours:.2f}")


if __name__ == "__main__":
    main(sys.argv)
