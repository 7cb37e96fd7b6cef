"""Plan cases of the blind benchmark: one car, one hidden truth, several load cases.

:func:`make_plan_case` draws the hidden effects once (:data:`~benchmarks.kinds.KINDS`)
on the default single-zone engine and simulates them on the truth path
(:mod:`benchmarks.truth`) at every load of the plan (the combustion model's IMEP
scale, :meth:`~powertrain.models.engine.Engine.at_load`; the amplitude-dependent elastomer
then works at each run's own amplitudes); every run is measured on its own (its own scatter
draw, noise and TDC error, :func:`powertrain.workflows.measurement.measure`). The case is
detectable when one of its runs is (:func:`benchmarks.cases.is_detectable`).

``sides="both"`` draws the same plan on the modal-body engine with both sides of every mount
measured (:mod:`benchmarks.passive`: the body side as further channels).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from benchmarks import cases as cs
from benchmarks.kinds import KINDS

#: Loads of the two-run plan (full load, part load).
LOADS = (1.0, 0.4)
#: Measured sides of a plan: engine side alone, or both sides of every mount.
SIDES = ("engine", "both")


def plan_engine(sides="engine"):
    """The engine a plan of ``sides`` is drawn on and diagnosed with (full load)."""
    if sides == "both":
        from benchmarks.passive import passive_engines
        return passive_engines()["body_sz"]
    return cs.engines()["sz"]


def _truth_path(sides):
    """``(simulate(engine, truth), channels(engine))`` of the truth path for ``sides``."""
    if sides == "both":
        from benchmarks import passive
        return passive.truth_velocity, passive.channels
    return cs.truth_velocity, lambda e: [(mt.name, a) for mt in e.mounts for a in "xyz"]


@functools.cache
def baseline_at(load, sides="engine"):
    """Noise-free baseline of the plan engine at ``load`` on the truth path."""
    simulate, _ = _truth_path(sides)
    return simulate(plan_engine(sides).at_load(load), [])


@dataclass
class PlanCase:
    """One car's runs (:class:`~benchmarks.cases.Case` per load) and its truth."""

    index: int
    names: list
    seed: int
    loads: tuple
    runs: list
    truth: list
    sides: str = "engine"

    @property
    def engine(self):
        """The engine the diagnosis gets (full load; each run at its own load)."""
        return plan_engine(self.sides)

    @property
    def category(self) -> str:
        return self.runs[0].category

    @property
    def detectable(self) -> bool:
        return any(r.detectable for r in self.runs)

    @property
    def truth_set(self) -> list:
        return self.runs[0].truth_set

    def plan(self):
        """The :class:`~powertrain.iotools.plan.Plan` the diagnosis gets."""
        from powertrain.iotools.plan import Plan, PlanRun
        return Plan([PlanRun(r.measured, load) for r, load in zip(self.runs, self.loads)],
                    source=f"plan case {self.index} (seed {self.seed})")


def make_plan_case(index, names, seed, loads=LOADS, phase=None, params=None,
                   sides="engine") -> PlanCase:
    """Draw the hidden effects ``names`` once (``params``: ``{name: parameters}`` fixed
    instead of drawn) and measure them at every load, on the ``sides`` of :data:`SIDES`."""
    if sides not in SIDES:
        raise ValueError(f"sides must be one of {SIDES}, not {sides!r}")
    engine = plan_engine(sides)
    simulate, channels = _truth_path(sides)
    rng = np.random.default_rng(seed)
    truth = [(n, {**KINDS[n].draw(rng, engine), **(params or {}).get(n, {})}) for n in names]
    runs = []
    for k, load in enumerate(loads):
        e = engine.at_load(load)
        run_seed = int(np.random.SeedSequence([seed, k]).generate_state(1)[0])
        runs.append(cs.draw_case(index, names, "sz" if sides == "engine" else "body_sz",
                                 run_seed, e, baseline_at(load, sides),
                                 lambda eng, _t: simulate(eng, truth), channels(e),
                                 f"plan case load {load:g}", phase=phase,
                                 params={n: p for n, p in truth}))
    return PlanCase(index, list(names), seed, tuple(loads), runs, truth, sides)
