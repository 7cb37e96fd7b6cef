#!/usr/bin/env python
"""Iterations of the equivalent-linear amplitude fixed point per speed.

Counts the solves of :func:`powertrain.solvers.equivalent_linear.amplitude_fixed_point`
(one per iteration) in the harmonic run-up at the default speeds (1000..6000 rpm, step 500)
of

* ``engines/default-nonlinear.toml`` as shipped, and
* the same engine with a steep power law on its y directions (reference 0.1 mm, exponent
  1.5, limits [0.001, 1000]), where plain damped iteration did not converge in 200
  iterations at 1000 rpm.

Prints one line per engine: the solves per speed and their total, or the error.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from powertrain.iotools.engine_file import read_engine
from powertrain.physics.mount_laws import PowerLaw
from powertrain.solvers import steppers
from powertrain.workflows.arguments import default_rpm
from powertrain.workflows.runup import run_runup

ENGINE = Path(__file__).resolve().parents[1] / "engines" / "default-nonlinear.toml"
STEEP = PowerLaw(1e-4, 1.5, (0.001, 1000.0))


def with_steep_y(engine):
    """``engine`` with :data:`STEEP` on every y direction that has an amplitude law."""
    mounts = [dataclasses.replace(m, directions={
        a: dataclasses.replace(mod, amplitude_law=STEEP)
        if a == "y" and mod.amplitude_law is not None else mod
        for a, mod in m.directions.items()}) for m in engine.mounts]
    return dataclasses.replace(engine, mounts=mounts)


def solves_per_speed(engine) -> str:
    """The fixed point's solves at each default speed of the harmonic run-up."""
    counts, original = [], steppers.amplitude_fixed_point

    def counting(solve, *args):
        calls = [0]

        def counted(amplitudes):
            calls[0] += 1
            return solve(amplitudes)
        try:
            return original(counted, *args)
        finally:
            counts.append(calls[0])

    steppers.amplitude_fixed_point = counting
    try:
        run_runup(engine, default_rpm(), solver="harmonic")
        return f"{' '.join(map(str, counts))} (total {sum(counts)})"
    except FloatingPointError as exc:
        return f"error: {exc}"
    finally:
        steppers.amplitude_fixed_point = original


def main():
    engine = read_engine(ENGINE)
    print(f"default-nonlinear:        {solves_per_speed(engine)}")
    print(f"steep y law (n = 1.5):    {solves_per_speed(with_steep_y(engine))}")


if __name__ == "__main__":
    main()
