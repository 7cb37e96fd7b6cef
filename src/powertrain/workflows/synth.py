r"""``powertrain synth``: a SYNTHETIC measured run-up with hidden effects and noise.

A case: an engine with zero to two hidden *truth* effects of random parameters
(:func:`draw_truth`), simulated noise-free (:mod:`powertrain.workflows.synth_effects`) and
measured (:mod:`powertrain.workflows.measurement`), redrawn until the effect is visible
(:func:`worth_diagnosing`). docs/guide/synth.md. The diagnosis is never imported here.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.outputs import atomic_write, write_csv
from powertrain.plotting.style import figure_legend, finish, log_axis, series_style, subplots, target_and_path
from powertrain.results.base import Result
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows.arguments import integer
from powertrain.workflows.arguments import names as listed
from powertrain.workflows.measurement import FLOOR, SyntheticCase, draw_case, gaps_db
from powertrain.workflows.synth_effects import truth_velocity

TRUTH_EFFECTS = {
    "body_modes": "base_compliance",
    "mount_temperature": "mount_stiffness",
    "amplitude_power": "amplitude_stiffness",
    "balancer_error": "balancer_error",
    "cylinder_combustion": "cylinder_imbalance",
    "sensor_triads": "sensor_error",
    "powertrain_bending": None,
    "torsional_driveline": None,
}
#: Other names accepted for a truth effect: alias -> truth effect.
TRUTH_ALIASES = {"balancer_shafts": "balancer_error"}
#: Speed grid of a synth case [rpm].
RPM = np.arange(1000.0, 6000.1, 50.0)
#: Smallest noise-free gap of a hidden effect [dB RMS over the written order points].
MIN_EFFECT_DB = 0.5
#: ... or this largest noise-free gap [dB].
MIN_EFFECT_MAX_DB = 4.0
#: Draws of a hidden effect before the last one is kept whatever its size.
REDRAWS = 40


def truth_effect_name(name: str) -> str:
    """The truth effect's name, aliases (:data:`TRUTH_ALIASES`) resolved."""
    return TRUTH_ALIASES.get(name, name)


def draw_truth(name, rng, n_net=9):
    """Random parameters of a truth effect for ``n_net`` mount networks (three per mount)."""
    u = rng.uniform
    n_m = n_net // 3
    if name == "body_modes":
        K = 3
        shapes = rng.normal(size=(n_net, K))
        shapes /= np.max(np.abs(shapes), axis=0)
        return {"freq": np.sort(u(20, 80, K)), "zeta": u(0.03, 0.08, K),
                "mass": np.exp(u(np.log(1.5), np.log(10), K)), "shapes": shapes}
    if name == "mount_temperature":
        s_m = np.exp(rng.choice([-1, 1], n_m) * u(np.log(1.3), np.log(2.2), n_m))
        sp = np.repeat(s_m, 3) * np.exp(rng.normal(0, 0.05, 3 * n_m))
        return {"mount_factor": s_m, "spring": sp, "damper": sp ** 0.7}
    if name == "amplitude_power":
        return {"beta": u(0.08, 0.25, 2)}
    if name == "balancer_error":
        return {"gain": u(0.75, 1.25, 2), "lag": u(-0.35, 0.35), "lag_shaft": u(-0.05, 0.05, 2)}
    if name == "cylinder_combustion":
        return {"imep_dev": u(-0.12, 0.12, 4), "start_shift_deg": u(-2, 2, 4)}
    if name == "sensor_triads":
        g = np.clip(rng.normal(0, 2.5, 3 * n_m), -5, 5)
        T = np.zeros((3 * n_m, 3 * n_m))
        for m in range(n_m):
            blk = u(0.01, 0.03, (3, 3)) * rng.choice([-1, 1], (3, 3))
            np.fill_diagonal(blk, 1.0)
            T[3 * m:3 * m + 3, 3 * m:3 * m + 3] = blk
        T = (10 ** (g / 20))[:, None] * T
        return {"gain_db": g, "matrix": T}
    if name == "powertrain_bending":
        return {"freq": u(50, 140), "kappa": u(0.15, 0.5), "zeta": u(0.03, 0.08)}
    if name == "torsional_driveline":
        return {"freq": u(40, 120), "kappa": u(0.2, 0.6), "zeta": u(0.05, 0.1)}
    raise KeyError(name)


def worth_diagnosing(base, velocity) -> bool:
    """Redraw rule: the noise-free gap reaches :data:`MIN_EFFECT_DB` RMS or
    :data:`MIN_EFFECT_MAX_DB` somewhere."""
    g = gaps_db(base, velocity)
    return bool(g.size) and bool(np.sqrt(np.mean(g ** 2)) >= MIN_EFFECT_DB or np.max(g) >= MIN_EFFECT_MAX_DB)


def make_case(engine, truth_names, seed, *, rpm=None, hm=None, noise_db=None, params=None) -> SyntheticCase:
    """One synthetic measurement (:class:`~powertrain.workflows.measurement.SyntheticCase`)
    with the named truth effects.

    Parameters
    ----------
    engine : Engine
        Baseline model.
    truth_names : sequence of str
        Names or aliases of truth effects (empty: effect-free).
    seed : int
        Seed of every draw (effects, scatter, noise).
    rpm : array_like, optional
        Speeds [rpm] (default :data:`RPM`).
    hm : HarmonicModel, optional
        Cached model of ``engine`` at ``rpm``.
    noise_db : float, optional
        Measurement scatter [dB, 1σ] (default uniform 0.5–1.0).
    params : dict, optional
        ``{truth name: parameters}`` fixed instead of drawn.
    """
    truth_names = [truth_effect_name(n) for n in truth_names]
    params = {truth_effect_name(k): v for k, v in (params or {}).items()} or None
    rpm = RPM if rpm is None else np.asarray(rpm, float)
    hm = HarmonicModel(engine, rpm) if hm is None else hm
    base = hm.velocity(hm.solve(hm.two_ports()[0]))
    return draw_case(list(truth_names), seed, engine, base, lambda eng, truth: truth_velocity(eng, hm, truth),
                     lambda name, rng, eng: draw_truth(name, rng, 3 * len(eng.mounts)), hm.channels,
                     f"synthetic case 0 (seed {seed})", rpm=rpm, noise_db=noise_db, params=params,
                     redraws=REDRAWS, worth=worth_diagnosing)


@dataclasses.dataclass(frozen=True)
class SynthCase(Result):
    """A synthetic measured run-up of :func:`synth`; ``case`` is the
    :class:`~powertrain.workflows.measurement.SyntheticCase`."""

    case: object
    seed: int

    @property
    def measured(self):
        """The measured order curves (:class:`~powertrain.iotools.measured.MeasuredRunup`)."""
        return self.case.measured

    def to_text(self) -> str:
        """Hidden effects, noise and the noise-free effect's size (one line)."""
        c = self.case
        return (f"{len(c.names) or 'no'} hidden effect(s), noise {c.noise_db:.2f} dB, "
                f"noise-free effect {c.effect_rms_db:.2f} dB RMS")

    def to_csv(self, path=None) -> str:
        """The measured CSV (the hidden effect not written), written to ``path`` if given."""
        text = self.case.csv_text()
        if path is not None:
            write_csv(path, text)
        return text

    def truth(self) -> dict:
        """The hidden effects and their parameters (keep them away from the diagnosis)."""
        def plain(x):
            return x.tolist() if isinstance(x, np.ndarray) else float(x)
        c = self.case
        return {"seed": self.seed, "noise_db": c.noise_db, "effect_rms_db": c.effect_rms_db,
                "truth": [{"effect": n, "library_match": TRUTH_EFFECTS[n],
                           "parameters": {k: plain(v) for k, v in p.items()}} for n, p in c.truth]}

    def writers(self) -> dict:
        """``.csv`` (:meth:`to_csv`), ``.png``."""
        return {".csv": self.to_csv, **super().writers()}

    def to_truth_json(self, path=None) -> str:
        """:meth:`truth` as JSON, written to ``path`` if given."""
        text = json.dumps(self.truth(), indent=1)
        if path is not None:
            with atomic_write(path) as fh:
                fh.write(text)
        return text

    def plot(self, ax=None, *, path=None, mount=None, direction="z", provenance=None):
        """The measured order curves [mm/s RMS] of one channel (default the first mount) and
        the noise floor; returns the figure."""
        ax, path = target_and_path(ax, path)
        curves = self.measured.curves
        mount = mount or next(iter(curves))[0]
        fig, axes, own = subplots(ax)
        a = axes[0, 0]
        drawn = [(q, rpm, v) for (m, d, q), (rpm, v) in curves.items()
                 if (m, d) == (mount, direction) and q != "synthesis"]
        for k, (q, rpm, v) in enumerate(drawn):
            a.plot(rpm, np.asarray(v) * 1e3, lw=1.0, label=q.replace("_", " "), **series_style(k))
        a.axhline(FLOOR * 1e3, color="0.4", lw=0.8, ls=(0, (1, 2)), label="noise floor")
        log_axis(a, "y")
        a.set_xlabel("engine speed [rpm]")
        a.set_ylabel(f"{mount} {direction} velocity [mm/s RMS]")
        if own:
            figure_legend(fig, axes)
        else:
            a.legend(fontsize=7, ncol=3)
        return finish(fig, own, path, provenance,
                      title=f"synthetic measured run-up (seed {self.seed}): {self.to_text()}")


def synth(effects=(), seed=0, *, engine=None, rpm=None, noise_db=None) -> SynthCase:
    """A synthetic measured run-up of ``engine`` with hidden ``effects`` and noise.

    Parameters
    ----------
    effects : str or sequence of str
        Truth effects (:data:`TRUTH_EFFECTS`, :data:`TRUTH_ALIASES`), or as ``--effect``
        writes them (``"a,b"``, ``"none"``).
    seed : int
        0..2^63-1.
    engine : Engine, str or path, optional
        Baseline engine or its file (default: the shipped ``engines/default.toml``).
    rpm, noise_db
        As for :func:`make_case`.
    """
    given = listed(effects, "--effect")
    names = [truth_effect_name(e) for e in ([] if given == ["none"] else given)]
    for e in names:
        if e not in TRUTH_EFFECTS:
            raise InputError(f"unknown truth effect {e!r} (known: {', '.join(TRUTH_EFFECTS)})",
                             key="--effect")
    engine = engine_or_default(engine)
    seed = integer(seed, "--seed")
    if not 0 <= seed < 2 ** 63:
        raise InputError(f"must be an integer 0..2^63-1, got {seed}", key="--seed")
    return SynthCase(make_case(engine, names, seed, rpm=rpm, noise_db=noise_db), seed)
