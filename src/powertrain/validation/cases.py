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

**Case maker** (:func:`draw_case`, also for ``powertrain synth``,
:mod:`powertrain.validation.synth`): draw the hidden effects, simulate the noise-free truth,
measure it, and record its noise-free gap against the baseline.

**Measurement** (:func:`measure`): 100-rpm grid 1000–6000 rpm (``synth``: 50 rpm); each
order's complex amplitude [RMS] times :math:`10^{\epsilon/20}`,
:math:`\epsilon\sim N(0,\sigma)` (log-normal scatter, σ uniform 0.5–1.0 dB per case),
plus complex Gaussian noise of RMS :data:`FLOOR`; the written orders :data:`WRITTEN_ORDERS`
and the synthesis (RMS sum of all 16 noisy orders).

**Detectability** (:func:`gap_stats`, from the noise-free truth against the noise-free
baseline, both on the truth path; never shown to the diagnosis): over the written order
points of all speeds (:func:`gaps_db`: floor added in power; points where both are at the
floor, :func:`powertrain.analysis.noise_floor.censoring_level`, left out)
the gap RMS reaches :data:`DETECT_RMS_DB` or the 95th percentile of ``|gap|`` reaches
:data:`DETECT_LOCAL_DB`. For a pair each member is also classified alone; the *expected*
answer is the library matches of the members detectable alone (all members if none is).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.noise_floor import censoring_level
from powertrain.validation import truth as tr
from powertrain.validation.kinds import IN_LIBRARY, KINDS

#: RMS noise floor of every order [m/s] (also handed to the diagnosis).
FLOOR = 1.0e-6
#: Orders written to the measured file.
WRITTEN_ORDERS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
#: Speed grid of the measurement [rpm].
RPM = np.arange(1000.0, 6000.1, 100.0)
#: A case is detectable when its noise-free gap RMS reaches this [dB] (twice the 0.5 dB by
#: which a model may miss and still count as agreeing) ...
DETECT_RMS_DB = 1.0
#: ... or 5 % of its points are off by at least this [dB] (3 × the largest scatter, 1σ).
DETECT_LOCAL_DB = 3.0
#: Scatter range [dB, 1σ].
SIGMA_DB = (0.5, 1.0)
#: 1σ of a lab's crank-angle error at cylinder-1 firing TDC [deg crank] (phase cases).
TDC_SD_DEG = 1.0

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
    traces (:class:`~powertrain.models.engine.MeasuredPressure`)."""
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


def written_levels(velocity, floor=FLOOR):
    """RMS levels of the written orders with the floor added in power (n_r, n_ch, n_w)."""
    idx = [int(round(2 * o)) - 1 for o in WRITTEN_ORDERS]
    return np.sqrt((np.abs(velocity[..., idx]) / np.sqrt(2)) ** 2 + floor ** 2)


def gaps_db(reference, velocity) -> np.ndarray:
    """``|gap|`` [dB] of ``velocity`` against ``reference`` at the written order points that
    are not both at the floor (the one noise-floor rule,
    :func:`powertrain.analysis.noise_floor.censoring_level`), flattened."""
    a, b = written_levels(reference), written_levels(velocity)
    keep = np.maximum(a, b) >= censoring_level(FLOOR)
    return np.abs(20 * np.log10(b / a))[keep]


def gap_stats(reference, velocity):
    """(RMS, 95th percentile of |gap|) [dB] of ``velocity`` against ``reference``
    (:func:`gaps_db`)."""
    g = gaps_db(reference, velocity)
    if g.size == 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(g ** 2))), float(np.percentile(g, 95))


def is_detectable(stats) -> bool:
    """Detectability rule on :func:`gap_stats` (module docstring)."""
    return bool(stats[0] >= DETECT_RMS_DB or stats[1] >= DETECT_LOCAL_DB)


def measure(velocity, sigma_db, rng, source="", channels=None, rpm=RPM, phase=None):
    """Noisy measured run-up (:class:`~powertrain.iotools.measured.MeasuredRunup`) of the
    noise-free ``velocity`` (n_r, n_ch, 16) at the speeds ``rpm``.

    ``phase``: None (levels only), ``"all"`` (every written order's phase, as with a cycle
    reference) or ``"whole"`` (whole orders only: no cycle reference). Phases carry a
    scatter of σ·ln10/20 rad (the phase twin of the level scatter), the noise's phase (so
    their scatter grows as the level nears the floor) and the lab's TDC error
    δ ~ N(0, :data:`TDC_SD_DEG`) crank (order k: −kδ); a phase is given only where the
    measured level is above the floor's RMS (below it the order is noise, its phase
    undefined; up to the censoring level it is written but mostly noise, and the diagnosis
    does not score it, :mod:`powertrain.diagnosis.phase`). Drawn after the levels, which
    stay as without phase."""
    from powertrain.analysis.orders import order_label
    from powertrain.iotools.measured import MeasuredRunup
    amp = velocity / np.sqrt(2) * 10 ** (rng.normal(0, sigma_db, velocity.shape) / 20)
    noise = FLOOR * (rng.normal(size=amp.shape) + 1j * rng.normal(size=amp.shape)) / np.sqrt(2)
    lev = np.abs(amp + noise)
    syn = np.sqrt(np.sum(lev ** 2, axis=-1))
    phi = None if phase is None else np.where(lev > FLOOR,
                                              _measured_phase(amp + noise, sigma_db, rng),
                                              np.nan)
    curves, phases = {}, {}
    for c, (m, d) in enumerate(channels):
        for o in WRITTEN_ORDERS:
            h = int(round(2 * o)) - 1
            curves[(m, d, order_label(o))] = (rpm.copy(), lev[:, c, h].copy())
            if phi is not None and (phase == "all" or h % 2 == 1):
                phases[(m, d, order_label(o))] = phi[:, c, h].copy()
        curves[(m, d, "synthesis")] = (rpm.copy(), syn[:, c].copy())
    return MeasuredRunup(curves, source=source, comments=[f"SYNTHETIC: {source}"],
                         phases=phases)


def _measured_phase(complex_rms, sigma_db, rng):
    """Measured phase [deg] of every order (n_r, n_ch, 16): the scatter's phase twin and the
    run's TDC error added (:func:`measure`)."""
    scatter = rng.normal(0, sigma_db * np.log(10) / 20, complex_rms.shape)
    delta = np.deg2rad(rng.normal(0, TDC_SD_DEG))
    k = 0.5 * np.arange(1, complex_rms.shape[-1] + 1)
    return np.rad2deg(np.angle(complex_rms * np.exp(1j * (scatter - k * delta))))


@dataclass
class Case:
    """One case: what the diagnosis sees and what only the scorer knows.

    ``noise_db`` is the measurement scatter [dB, 1σ]; ``stats`` the noise-free gap
    (:func:`gap_stats`) of the truth ``clean`` against the baseline, ``member_stats`` that of
    each member of a pair alone; ``kinds`` the truth kinds the names refer to
    (:data:`~powertrain.validation.kinds.KINDS`, or those of ``powertrain synth``).
    """

    index: int
    names: list
    engine_kind: str
    seed: int
    measured: object
    noise_db: float
    truth: list
    clean: np.ndarray
    stats: tuple
    member_stats: dict = field(default_factory=dict)
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
    def effect_rms_db(self) -> float:
        """Noise-free gap RMS of the truth against the baseline [dB]."""
        return self.stats[0]

    @property
    def truth_set(self) -> list:
        return sorted({self.kinds[n].library or "outside" for n in self.names})

    @property
    def expected_set(self) -> list:
        alone = [n for n in self.names if is_detectable(self.member_stats.get(n, self.stats))]
        return sorted({self.kinds[n].library or "outside" for n in (alone or self.names)})

    def csv_text(self) -> str:
        """The measured CSV (long format); with a body under the mounts (channels
        ``NAME/passive`` and body points) with the ``side`` column; with measured phase the
        ``phase_deg`` column (empty where none is given)."""
        from powertrain.analysis.channel import split_side
        names = {m for m, _, _ in self.measured.curves}
        bases = {split_side(m)[0] for m in names if split_side(m)[1] == "passive"}
        phases = getattr(self.measured, "phases", None) or {}
        header = ("mount,direction,quantity,rpm" + (",side" if bases else "")
                  + ",velocity_rms_mm_per_s" + (",phase_deg" if phases else ""))
        lines = [f"# SYNTHETIC measured run-up (powertrain synth, seed {self.seed}); the hidden "
                 "effect is not stated here", header]
        for (m, d, q), (r, v) in self.measured.curves.items():
            base, side = split_side(m)
            if bases and side == "active" and base not in bases:
                side = "passive"                     # a body point of interest
            col = f",{side}" if bases else ""
            phi = phases.get((m, d, q), np.full(len(r), np.nan))
            for ri, vi, pi in zip(r, v, phi):
                tail = "" if not phases else "," if not np.isfinite(pi) else f",{pi:.2f}"
                lines.append(f"{base},{d},{q},{ri:g}{col},{vi * 1e3:.6g}{tail}")
        return "\n".join(lines) + "\n"


def make_case(index, names, engine_kind, seed, phase=None) -> Case:
    """Draw, simulate and measure one case (``phase``: :func:`measure`)."""
    engine = engines()[engine_kind]
    return draw_case(index, names, engine_kind, seed, engine, baseline_velocity(engine_kind),
                     truth_velocity, [(mt.name, a) for mt in engine.mounts for a in "xyz"],
                     "blind case", phase=phase)


def draw_case(index, names, engine_kind, seed, engine, base, simulate, channels, label, *,
              kinds=KINDS, rpm=RPM, noise_db=None, params=None, redraws=1,
              worth=None, phase=None) -> Case:
    """The one case maker: draw the hidden effects ``names`` (:class:`TruthKind` of
    ``kinds``) on ``engine``, simulate them (``simulate(engine, truth)``, noise-free,
    ``base`` without them) and measure ``channels`` at ``rpm`` (source
    ``"{label} {index} (seed {seed})"``); pairs also get each member's gap alone.

    ``params`` (``{name: parameters}``) fixes parameters instead of drawing them; the draw
    is repeated up to ``redraws`` times until ``worth(base, clean)`` holds; ``noise_db``
    fixes the scatter (default uniform :data:`SIGMA_DB`); ``phase`` what phase is measured
    (:func:`measure`).
    """
    rng = np.random.default_rng(seed)
    truth, clean = [], base
    for _ in range(redraws if names else 0):
        truth = [(n, {**kinds[n].draw(rng, engine), **(params or {}).get(n, {})})
                 for n in names]
        clean = simulate(engine, truth)
        if worth is None or worth(base, clean):
            break
    sigma = float(rng.uniform(*SIGMA_DB)) if noise_db is None else float(noise_db)
    measured = measure(clean, sigma, rng, f"{label} {index} (seed {seed})", channels, rpm,
                       phase)
    members = {}
    if len(truth) > 1:
        members = {t[0]: gap_stats(base, simulate(engine, [t])) for t in truth}
    return Case(index, list(names), engine_kind, seed, measured, sigma, truth, clean,
                gap_stats(base, clean), members, kinds)
