#!/usr/bin/env python
"""Make the SYNTHETIC example measured run-up ``examples/measured-runup.csv``.

Nothing here was measured on a vehicle. The "measurement" is a simulation of a model that
differs from the default one in the ways the thesis blames for its own gaps (Kovarik 2016,
sec. 4.5), plus measurement noise, so that ``powertrain compare`` has something realistic to
find:

1. **Flexible chassis at the mount bases.** Every mount network stands on a base node
   (:func:`powertrain.models.extensions.with_base_compliance`) of mass ``BASE[mount][0]``,
   stiffness ``BASE[mount][1]`` and damping ``BASE[mount][2]`` to ground, the same in x, y, z.
2. **Amplitude-dependent mount stiffness** (softening, Payne-like): at each speed every
   spring of a mount direction's network (not the base) is scaled by

   .. math:: s(a) = s_\\infty + (1 - s_\\infty)/(1 + a/a_0)

   where :math:`a` is that mount direction's engine-side displacement amplitude (peak of
   the order synthesis, :math:`\\sqrt2` × RMS sum of orders 0.5..8, along the mount's local
   axis) in the baseline run (flexible bases, nominal stiffness) at the same speed.
3. **Measurement noise**, seeded: every order level times :math:`10^{\\epsilon/20}`,
   :math:`\\epsilon \\sim N(0, \\sigma_{dB})`, then an additive noise floor in power,
   :math:`v = \\sqrt{(g v_0)^2 + f^2\\rho}` with :math:`\\rho \\sim \\mathrm{Exp}(1)` (the
   power of a complex Gaussian noise of RMS ``FLOOR``); the synthesis is the RMS sum of the
   noisy orders 0.5..8, as an order analyser would compute it.
4. **Dense speed grid**: every ``RPM_STEP`` rpm from ``RPM_START`` to ``RPM_STOP``, solved with
   the harmonic solver (exact steady state of the linear model at each speed).

Written: the quantities ``QUANTITIES`` of the nine channels in the long CSV format
(``mount,direction,quantity,rpm,velocity_rms_mm_per_s``), with a ``#`` header saying it is
synthetic and listing these parameters.

Usage: ``python scripts/make_example_measurement.py [--out examples/measured-runup.csv]``
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from powertrain.analysis.orders import order_label
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.models.extensions import with_base_compliance
from powertrain.outputs import atomic_write
from powertrain.workflows.runup import run_runup

# ----------------------------------------------------------------------------- parameters
SEED = 20160901
RPM_START, RPM_STOP, RPM_STEP = 1000.0, 6000.0, 50.0
#: mount -> (base mass [kg], base stiffness [N/m], base damping [N*s/m]): a soft subframe,
#: attachment stiffness only 2-6x the mounts' dynamic stiffness; the base on its spring
#: sqrt(c/m)/(2 pi) = 28 Hz (engine mounts) and 27 Hz (gearbox), damping ratio ~0.05.
BASE = {"left": (25.0, 8.0e5, 450.0), "right": (25.0, 8.0e5, 450.0),
        "gearbox": (20.0, 6.0e5, 350.0)}
#: stiffness factor at large amplitude and reference amplitude [m] of s(a)
S_INF = 0.6
A0 = 0.05e-3
#: multiplicative level noise [dB, standard deviation] and RMS noise floor [m/s]
NOISE_DB = 0.7
FLOOR = 1.0e-6
#: (order 1 is left out: the simulated inline-4 has none, so the measured order 1 would be
#: pure noise floor)
QUANTITIES = ("synthesis", "order_2", "order_4", "order_6")
OUT = Path(__file__).resolve().parents[1] / "examples" / "measured-runup.csv"


def stiffness_factor(amplitude):
    """s(a) = S_INF + (1 - S_INF) / (1 + a / A0); amplitude [m] -> factor [1]."""
    return S_INF + (1.0 - S_INF) / (1.0 + np.asarray(amplitude, float) / A0)


def flexible_engine(engine, factors=None):
    """The engine with compliant bases; ``factors[(mount, axis)]`` scales that network's
    springs (before the base is added)."""
    mounts = []
    for m in engine.mounts:
        mb, cb, db = BASE[m.name]
        dirs = {}
        for axis, model in m.directions.items():
            s = 1.0 if factors is None else float(factors[(m.name, axis)])
            dirs[axis] = with_base_compliance(model.scaled(stiffness=s), mb, cb, db)
        mounts.append(dataclasses.replace(m, directions=dirs))
    return engine.replace(mounts=mounts, name=engine.name + " + compliant bases")


def local_displacement_amplitude(engine, result):
    """(n_rpm, mount, axis) -> engine-side peak displacement amplitude along the mount's
    local axis: sqrt(2) x RMS sum over orders [m]."""
    out = {}
    for m in engine.mounts:
        idx = [result.channel_index(m.name, a) for a in "xyz"]
        d = result.displacement[:, idx, :]                      # (n_rpm, 3, n_orders)
        local = np.einsum("ji,rjo->rio", np.asarray(m.rotation, float), d)   # R^T d
        rms = np.sqrt(np.sum(np.abs(local) ** 2 / 2.0, axis=-1))            # (n_rpm, 3)
        for ai, a in enumerate("xyz"):
            out[(m.name, a)] = np.sqrt(2.0) * rms[:, ai]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(OUT))
    args = ap.parse_args(argv)
    engine = read_engine(DEFAULT_ENGINE_PATH)
    n = int(round((RPM_STOP - RPM_START) / RPM_STEP)) + 1
    rpm = RPM_START + RPM_STEP * np.arange(n)
    base = run_runup(flexible_engine(engine), rpm, solver="harmonic")
    amp = local_displacement_amplitude(engine, base)
    vel = np.empty_like(base.velocity)
    factors_used = []
    for i, r in enumerate(rpm):
        factors = {k: stiffness_factor(v[i]) for k, v in amp.items()}
        factors_used.extend(factors.values())
        vel[i] = run_runup(flexible_engine(engine, factors), [r], solver="harmonic").velocity[0]
    # how different is this model from the default one, before any noise?
    ref = run_runup(engine, rpm, solver="harmonic")
    o24 = [ref.order_index(2.0), ref.order_index(4.0)]
    model_db = 20 * np.log10(np.abs(vel[..., o24]) / np.abs(ref.velocity[..., o24]))
    model_gap = (f"noise-free model difference from the default model, orders 2 and 4: "
                 f"RMS {np.sqrt(np.mean(model_db ** 2)):.2f} dB, "
                 f"max {np.max(np.abs(model_db)):.2f} dB")
    rng = np.random.default_rng(SEED)
    rms = np.abs(vel) / np.sqrt(2.0)                              # (n_rpm, 9, n_orders)
    gain = 10.0 ** (rng.normal(0.0, NOISE_DB, rms.shape) / 20.0)
    noise_power = FLOOR ** 2 * rng.exponential(1.0, rms.shape)
    meas = np.sqrt((gain * rms) ** 2 + noise_power)
    synth = np.sqrt(np.sum(meas ** 2, axis=-1))
    labels = [order_label(o) for o in base.orders]
    lines = [
        "# SYNTHETIC measured run-up: made by scripts/make_example_measurement.py, NOT measured.",
        f"# model: {engine.name} (engines/{Path(DEFAULT_ENGINE_PATH).name})"
        " with compliant chassis bases and amplitude-dependent mount stiffness",
        "# bases (mass kg, stiffness N/m, damping N*s/m): "
        + "; ".join(f"{k} {v[0]:g}, {v[1]:g}, {v[2]:g}" for k, v in BASE.items()),
        f"# stiffness factor s(a) = {S_INF:g} + {1 - S_INF:g}/(1 + a/{A0 * 1e3:g} mm), "
        f"a = baseline engine-side peak displacement per mount axis; applied factors "
        f"{min(factors_used):.3f}..{max(factors_used):.3f}",
        f"# noise: {NOISE_DB:g} dB level scatter (1 sigma), noise floor {FLOOR * 1e3:g} mm/s RMS "
        f"per order, seed {SEED}; harmonic solver every {RPM_STEP:g} rpm "
        f"{RPM_START:g}..{RPM_STOP:g}",
        f"# {model_gap}",
        "mount,direction,quantity,rpm,velocity_rms_mm_per_s",
    ]
    for c, (mount, direction) in enumerate(base.channels):
        for q in QUANTITIES:
            col = synth[:, c] if q == "synthesis" else meas[:, c, labels.index(q)]
            for r, v in zip(rpm, col):
                lines.append(f"{mount},{direction},{q},{r:g},{v * 1e3:.5g}")
    with atomic_write(args.out) as fh:
        fh.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}: {len(lines) - 7} rows; stiffness factors "
          f"{min(factors_used):.3f}..{max(factors_used):.3f}; {model_gap}")


if __name__ == "__main__":
    main()
