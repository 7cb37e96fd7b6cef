r"""The synthetic measurement of ``powertrain synth``: scatter, noise floor, measured file.

:func:`measure`: each order's complex amplitude [RMS] times :math:`10^{\epsilon/20}`,
:math:`\epsilon\sim N(0,\sigma)`, plus complex Gaussian noise of RMS :data:`FLOOR`;
:func:`draw_case` draws, simulates and measures a :class:`SyntheticCase`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.channel import split_side
from powertrain.analysis.noise_floor import censoring_level
from powertrain.analysis.orders import order_label
from powertrain.iotools.measured import MeasuredRunup

#: RMS noise floor of every order [m/s] (also handed to the diagnosis).
FLOOR = 1.0e-6
#: Orders written to the measured file.
WRITTEN_ORDERS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
#: Default speed grid of a measurement [rpm].
RPM = np.arange(1000.0, 6000.1, 100.0)
#: Scatter range [dB, 1σ].
SIGMA_DB = (0.5, 1.0)
#: 1σ of a lab's crank-angle error at cylinder-1 firing TDC [deg crank] (measured phase).
TDC_SD_DEG = 1.0


def written_levels(velocity, floor=FLOOR):
    """RMS levels of the written orders with the floor added in power (n_r, n_ch, n_w).

    Parameters
    ----------
    velocity : ndarray
        Complex order amplitudes (n_r, n_ch, 16) [m/s peak], orders 0.5 ... 8.
    floor : float
        RMS noise floor [m/s].
    """
    idx = [int(round(2 * o)) - 1 for o in WRITTEN_ORDERS]
    return np.sqrt((np.abs(velocity[..., idx]) / np.sqrt(2)) ** 2 + floor ** 2)


def gaps_db(reference, velocity) -> np.ndarray:
    """Flat ``|gap|`` [dB] of ``velocity`` against ``reference`` (both (n_r, n_ch, 16) [m/s
    peak]) at the written order points not both at the floor."""
    a, b = written_levels(reference), written_levels(velocity)
    keep = np.maximum(a, b) >= censoring_level(FLOOR)
    return np.abs(20 * np.log10(b / a))[keep]


def gap_stats(reference, velocity):
    """(RMS, 95th percentile) of :func:`gaps_db` [dB]; ``(0, 0)`` with no point above floor."""
    g = gaps_db(reference, velocity)
    if g.size == 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(g ** 2))), float(np.percentile(g, 95))


def measure(velocity, sigma_db, rng, source="", channels=None, rpm=RPM, phase=None):
    """Noisy measured run-up (:class:`~powertrain.iotools.measured.MeasuredRunup`) of a
    noise-free one.

    Phases carry a scatter of σ·ln10/20 rad, the noise's phase and a TDC error
    δ ~ N(0, :data:`TDC_SD_DEG`) crank (order k: −kδ); given only above the floor.

    Parameters
    ----------
    velocity : ndarray
        Noise-free complex order amplitudes (n_r, n_ch, 16) [m/s peak].
    sigma_db : float
        Level scatter [dB, 1σ].
    rng : numpy.random.Generator
        Source of the scatter and noise.
    source : str
        Description of the run-up (comment ``SYNTHETIC: source``).
    channels : list of (str, str)
        ``(mount, direction)`` of each channel of ``velocity``.
    rpm : array_like
        Speeds [rpm] of the rows of ``velocity``.
    phase : {None, "all", "whole"}
        Levels only, every written order's phase, or whole orders' only.
    """
    amp = velocity / np.sqrt(2) * 10 ** (rng.normal(0, sigma_db, velocity.shape) / 20)
    noise = FLOOR * (rng.normal(size=amp.shape) + 1j * rng.normal(size=amp.shape)) / np.sqrt(2)
    lev = np.abs(amp + noise)
    syn = np.sqrt(np.sum(lev ** 2, axis=-1))
    phi = None if phase is None else np.where(lev > FLOOR, _measured_phase(amp + noise, sigma_db, rng),
                                              np.nan)
    curves, phases = {}, {}
    for c, (m, d) in enumerate(channels):
        for o in WRITTEN_ORDERS:
            h = int(round(2 * o)) - 1
            curves[(m, d, order_label(o))] = (rpm.copy(), lev[:, c, h].copy())
            if phi is not None and (phase == "all" or h % 2 == 1):
                phases[(m, d, order_label(o))] = phi[:, c, h].copy()
        curves[(m, d, "synthesis")] = (rpm.copy(), syn[:, c].copy())
    return MeasuredRunup(curves, source=source, comments=[f"SYNTHETIC: {source}"], phases=phases)


def _measured_phase(complex_rms, sigma_db, rng):
    """Measured phase [deg] of every order (n_r, n_ch, 16), scatter and TDC error added."""
    scatter = rng.normal(0, sigma_db * np.log(10) / 20, complex_rms.shape)
    delta = np.deg2rad(rng.normal(0, TDC_SD_DEG))
    k = 0.5 * np.arange(1, complex_rms.shape[-1] + 1)
    return np.rad2deg(np.angle(complex_rms * np.exp(1j * (scatter - k * delta))))


@dataclass(frozen=True)
class SyntheticCase:
    """A synthetic measured run-up and the hidden effects behind it.

    ``truth`` ``[(name, parameters)]``, ``clean`` the noise-free run-up (n_r, n_ch, 16) [m/s
    peak], ``noise_db`` the scatter [dB, 1σ], ``stats`` the noise-free gap
    (:func:`gap_stats`), ``member_stats`` each member of a pair's alone.
    """

    names: list
    seed: int
    measured: object
    noise_db: float
    truth: list
    clean: np.ndarray
    stats: tuple
    member_stats: dict = field(default_factory=dict)

    @property
    def effect_rms_db(self) -> float:
        """Noise-free gap RMS of the hidden effects against the baseline [dB]."""
        return self.stats[0]

    def csv_text(self) -> str:
        """The measured CSV (long format; ``side`` column with a body, ``phase_deg`` with
        phase)."""
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
                side = "passive"                     # a body point
            col = f",{side}" if bases else ""
            phi = phases.get((m, d, q), np.full(len(r), np.nan))
            for ri, vi, pi in zip(r, v, phi):
                tail = "" if not phases else "," if not np.isfinite(pi) else f",{pi:.2f}"
                lines.append(f"{base},{d},{q},{ri:g}{col},{vi * 1e3:.6g}{tail}")
        return "\n".join(lines) + "\n"


def draw_case(names, seed, engine, base, simulate, draw, channels, source, *, rpm=RPM,
              noise_db=None, params=None, redraws=1, worth=None, phase=None) -> SyntheticCase:
    """Draw the hidden effects ``names`` on ``engine``, simulate them noise-free and measure.

    Parameters
    ----------
    names : list of str
        Hidden effects (empty: effect-free).
    seed : int
        Seed of every draw (effects, scatter, noise).
    engine : Engine
        Baseline model.
    base : ndarray
        Noise-free run-up without the effects (n_r, n_ch, 16) [m/s peak].
    simulate, draw : callable
        ``simulate(engine, truth)``: noise-free run-up; ``draw(name, rng, engine)``: one
        effect's random parameters.
    channels, source, rpm, phase
        As for :func:`measure` (``rpm`` [rpm]).
    noise_db : float, optional
        Scatter [dB, 1σ] (default uniform :data:`SIGMA_DB`).
    params : dict, optional
        ``{name: parameters}`` fixed instead of drawn.
    redraws : int
        Draws until ``worth(base, clean)`` holds (else the last is kept).
    worth : callable, optional
        Redraw rule; None keeps the first draw.
    """
    rng = np.random.default_rng(seed)
    truth, clean = [], base
    for _ in range(redraws if names else 0):
        truth = [(n, {**draw(n, rng, engine), **(params or {}).get(n, {})}) for n in names]
        clean = simulate(engine, truth)
        if worth is None or worth(base, clean):
            break
    sigma = float(rng.uniform(*SIGMA_DB)) if noise_db is None else float(noise_db)
    measured = measure(clean, sigma, rng, source, channels, rpm, phase)
    members = {}
    if len(truth) > 1:
        members = {t[0]: gap_stats(base, simulate(engine, [t])) for t in truth}
    return SyntheticCase(list(names), seed, measured, sigma, truth, clean, gap_stats(base, clean), members)
