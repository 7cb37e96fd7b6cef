r"""Cases of the truth generators: plan, engines, case maker, scatter and noise, detectability.

**Plan** (:func:`case_plan`), repeated every 25 cases: 14 single in-library effects
(``mount_temperature`` and ``weak_cylinder`` three times, the four other in-library kinds
twice, engines alternating), 3 pairs of different in-library kinds (random, random engine),
4 effect-free (two per engine), 4 out-of-library (``sensor_bracket`` and
``powertrain_bending`` twice each, alternating engines). The order within a lap is fixed and
mixed, so a short run still covers most kinds.

**Engines**: the default single-zone engine, or the same engine with **measured pressure
traces** (:func:`traces_engine`: its own single-zone traces tabulated every 250 rpm) — the
diagnosis gets the engine the case was made on, without the hidden effect.

**Case maker** (:func:`draw_case`): draw the hidden effects, simulate the noise-free truth,
measure it, and record its noise-free gap against the baseline, with the case maker and
measurement of ``powertrain synth`` (:func:`powertrain.workflows.measurement.draw_case`).

**Measurement** (:func:`powertrain.workflows.measurement.measure`): 100-rpm grid
1000–6000 rpm (``synth``: 50 rpm); each order's complex amplitude [RMS] times
:math:`10^{\epsilon/20}`, :math:`\epsilon\sim N(0,\sigma)` (log-normal scatter, σ uniform
0.5–1.0 dB per case), plus complex Gaussian noise of RMS
:data:`~powertrain.workflows.measurement.FLOOR`; the written orders and the synthesis (RMS
sum of all 16 noisy orders).

**Detectability** (:func:`~powertrain.workflows.measurement.gap_stats`, from the noise-free
truth against the noise-free baseline, both on the truth path; never shown to the
diagnosis): over the written order points of all speeds (floor added in power; points where
both are at the floor, :func:`powertrain.analysis.noise_floor.censoring_level`, left out)
the gap RMS reaches :data:`DETECT_RMS_DB` or the 95th percentile of ``|gap|`` reaches
:data:`DETECT_LOCAL_DB`. For a pair each member is also classified alone; the *expected*
answer is the library matches of the members detectable alone (all members if none is).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, fields

import numpy as np

from benchmarks import truth as tr
from benchmarks.kinds import IN_LIBRARY, KINDS
from powertrain.workflows import measurement
from powertrain.workflows.measurement import RPM, SyntheticCase

#: A case is detectable when its noise-free gap RMS reaches this [dB] (twice the 0.5 dB by
#: which a model may miss and still count as agreeing) ...
DETECT_RMS_DB = 1.0
#: ... or 5 % of its points are off by at least this [dB] (3 × the largest scatter, 1σ).
DETECT_LOCAL_DB = 3.0

_LAP = [("mount_temperature", "sz"), ("weak_cylinder", "traces"), ("none", "sz"),
        ("balancer_shafts", "sz"), ("sensor_bracket", "sz"), ("sensor_triads", "traces"),
        ("chassis_base", "sz"), ("pair", None), ("amplitude_elastomer", "traces"),
        ("weak_cylinder", "sz"), ("none", "traces"), ("powertrain_bending", "traces"),
        ("mount_temperature", "traces"), ("balancer_shafts", "traces"), ("pair", None),
        ("sensor_triads", "sz"), ("chassis_base", "traces"), ("none", "sz"),
        ("amplitude_elastomer", "sz"), ("sensor_bracket", "traces"), ("pair", None),
        ("powertrain_bending", "sz"), ("none", "traces"), ("weak_cylinder", "traces"),
        ("mount_temperature", "sz")]


def case_plan(n_cases, seed):
    """``[(names, engine kind, case seed)]`` for ``n_cases`` cases of benchmark ``seed``.

    Names are truth kinds (empty: effect-free); engine kind ``"sz"`` (single-zone) or
    ``"traces"``; the case seed is derived from (``seed``, index).
    """
    out = []
    for i in range(n_cases):
        case_seed = int(np.random.SeedSequence([seed, i]).generate_state(1)[0])
        rng = np.random.default_rng(case_seed)
        name, eng = _LAP[i % len(_LAP)]
        if name == "pair":
            names = sorted(rng.choice(IN_LIBRARY, 2, replace=False).tolist())
            eng = "sz" if rng.random() < 0.5 else "traces"
        else:
            names = [] if name == "none" else [name]
        out.append((names, eng, case_seed))
    return out


@functools.cache
def engines():
    """``{"sz": default engine, "traces": the same with measured pressure traces}``."""
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    e = read_engine(DEFAULT_ENGINE_PATH)
    return {"sz": e, "traces": traces_engine(e)}


def traces_engine(engine, step_rpm=250.0):
    """``engine`` with its single-zone pressures tabulated every ``step_rpm`` as measured
    traces (:class:`~powertrain.models.combustion.MeasuredPressure`)."""
    from powertrain.models.combustion import RPM as RAD_PER_RPM
    from powertrain.models.combustion import MeasuredPressure
    lo, hi = engine.speed_range_rpm()
    speeds = np.arange(lo, hi + 1e-9, step_rpm)
    p = []
    for n in speeds:
        theta, pc, _ = engine.combustion.cycle_pressures(engine.crank, n * RAD_PER_RPM)
        p.append(pc)
    comb = MeasuredPressure("synthetic traces (single-zone model of the default engine)",
                            speeds * RAD_PER_RPM, np.array(p), theta)
    return engine.replace(combustion=comb, name=engine.name + " [measured traces]")


@functools.cache
def baseline_velocity(engine_kind):
    """Noise-free baseline on the truth path (n_r, 9, 16) [m/s peak]."""
    e = engines()[engine_kind]
    return tr.simulate_truth(tr.TruthSpec(e, list(e.mounts)), RPM)


def truth_velocity(engine, truth):
    """Noise-free truth of ``[(kind name, params)]`` on ``engine``."""
    parts = {"engine": engine, "mounts": list(engine.mounts), "chassis": None,
             "bending": None, "amplitude_beta": None, "sensor": []}
    for name, params in truth:
        KINDS[name].apply(params, parts)
    return tr.simulate_truth(tr.TruthSpec(**parts), RPM)


def is_detectable(stats) -> bool:
    """Detectability rule on :func:`~powertrain.workflows.measurement.gap_stats` (module docstring)."""
    return bool(stats[0] >= DETECT_RMS_DB or stats[1] >= DETECT_LOCAL_DB)


@dataclass(frozen=True)
class Case(SyntheticCase):
    """One case: what the diagnosis sees (a
    :class:`~powertrain.workflows.measurement.SyntheticCase`) and what only the scorer knows.

    ``index`` is the case's place in its plan, ``engine_kind`` the engine it was made on;
    ``kinds`` the truth kinds the names refer to (:data:`~benchmarks.kinds.KINDS`).
    """

    index: int = 0
    engine_kind: str = ""
    kinds: dict = field(default_factory=lambda: KINDS)

    @property
    def category(self) -> str:
        """``"none"``, ``"in"`` (every hidden effect in the library) or ``"out"``."""
        if not self.names:
            return "none"
        return "in" if all(self.kinds[n].library for n in self.names) else "out"

    @property
    def detectable(self) -> bool:
        return bool(self.names) and is_detectable(self.stats)

    @property
    def truth_set(self) -> list:
        return sorted({self.kinds[n].library or "outside" for n in self.names})

    @property
    def expected_set(self) -> list:
        alone = [n for n in self.names if is_detectable(self.member_stats.get(n, self.stats))]
        return sorted({self.kinds[n].library or "outside" for n in (alone or self.names)})


def make_case(index, names, engine_kind, seed, phase=None) -> Case:
    """Draw, simulate and measure one case (``phase``:
    :func:`powertrain.workflows.measurement.measure`)."""
    engine = engines()[engine_kind]
    return draw_case(index, names, engine_kind, seed, engine, baseline_velocity(engine_kind),
                     truth_velocity, [(mt.name, a) for mt in engine.mounts for a in "xyz"],
                     "blind case", phase=phase)


def draw_case(index, names, engine_kind, seed, engine, base, simulate, channels, label, *,
              kinds=KINDS, rpm=RPM, noise_db=None, params=None, redraws=1,
              worth=None, phase=None) -> Case:
    """The case maker of the benchmark: draw the hidden effects ``names`` (:class:`TruthKind`
    of ``kinds``) on ``engine``, simulate them (``simulate(engine, truth)``, noise-free,
    ``base`` without them) and measure ``channels`` at ``rpm`` (source
    ``"{label} {index} (seed {seed})"``); pairs also get each member's gap alone
    (:func:`powertrain.workflows.measurement.draw_case`, whose other arguments these are).
    """
    case = measurement.draw_case(
        list(names), seed, engine, base, simulate, lambda n, rng, e: kinds[n].draw(rng, e),
        channels, f"{label} {index} (seed {seed})", rpm=rpm, noise_db=noise_db, params=params,
        redraws=redraws, worth=worth, phase=phase)
    return Case(**{f.name: getattr(case, f.name) for f in fields(SyntheticCase)},
                index=index, engine_kind=engine_kind, kinds=kinds)
