r"""Order phase in the diagnosis: complex residuals with a level-dependent noise model and the
run's crank-angle offset as a nuisance parameter.

Where a measured point carries its order phase :math:`\varphi` (the order-k component is
:math:`\sqrt2\,\mathrm{RMS}\cos(k\theta + \varphi)`, θ from cylinder-1 firing TDC) and its
level :math:`L` is above the censoring level, the fit scores the phase gap
:math:`\Delta = \mathrm{wrap}(\arg\hat v - k\delta - \varphi)` besides the level gap in dB.
The level gap of a complex log-normal scatter of σ dB has a phase twin of
:math:`\sigma_r = \sigma\ln 10/20` rad; the complex noise floor :math:`f` adds
:math:`f/L` rad, so that

.. math:: \sigma_\varphi = \sqrt{\sigma_r^2 + (f/L)^2},\qquad
          r_\varphi = \frac{\sigma}{\sigma_\varphi}\,\Delta \quad[\mathrm{dB}],

a residual with the same 1σ as a level gap: near the floor the phase weighs little, far
above it a phase gap of 1 rad weighs as 8.7 dB. Magnitudes alone where no phase is given.

A lab knows its TDC to about :data:`CRANK_OFFSET_SD_DEG` crank: an error δ shifts order k's
phase by −kδ. δ is profiled out per run (weighted least squares over the run's phase
residuals, with the prior :math:`\sigma\,\delta/\sigma_\delta` as one more residual); the
held-out speeds use the training speeds' δ.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.analysis.noise_floor import above_floor

#: 1σ of a lab's crank-angle (TDC) offset [deg crank].
CRANK_OFFSET_SD_DEG = 1.0


def wrap(x):
    """Angle wrapped to [−π, π) [rad]."""
    return np.mod(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


def phase_weights(level, phase_deg, floor, sigma_db):
    r"""Weights :math:`\sigma/\sigma_\varphi` [dB/rad] of the phase gaps (module docstring);
    NaN where no phase is given or the level is not above the censoring level."""
    sigma_r = sigma_db * math.log(10.0) / 20.0
    with np.errstate(divide="ignore", invalid="ignore"):
        s_phi = np.sqrt(sigma_r ** 2 + (floor / level) ** 2)
        w = sigma_db / s_phi
    ok = above_floor(level, floor) & np.isfinite(phase_deg)
    return np.where(ok, w, np.nan)


class OffsetProfile:
    r"""The crank-angle offset δ [rad] of one run profiled from its phase gaps: minimises
    :math:`\sum w^2\,\mathrm{wrap}(d - k\delta)^2 + (\sigma\delta/\sigma_\delta)^2` by two
    re-wrapped weighted least-squares steps, for the orders ``order`` k and weights ``w`` of
    the scored phase points (1-D; their sums are formed once: a fit profiles δ at every
    evaluation)."""

    def __init__(self, order, w, sigma_db):
        k, w2 = order, w ** 2
        ridge = (sigma_db / math.radians(CRANK_OFFSET_SD_DEG)) ** 2
        self.order, self.w2k = k, w2 * k
        self.denominator = np.sum(w2 * k * k) + ridge

    def __call__(self, d) -> float:
        """δ [rad] for the model minus measured phases ``d`` [rad] at the scored points."""
        if d.size == 0:
            return 0.0
        k = self.order
        delta = float(np.sum(self.w2k * wrap(d)) / self.denominator)
        r = wrap(d - k * delta) + k * delta
        return float(np.sum(self.w2k * r) / self.denominator)

    def rows(self, d) -> np.ndarray:
        """δ [rad] of each row of ``d`` (n_b, n_points), as calling this on each row."""
        if d.shape[1] == 0:
            return np.zeros(d.shape[0])
        k = self.order
        delta = np.sum(self.w2k * wrap(d), axis=1) / self.denominator
        r = wrap(d - k * delta[:, None]) + k * delta[:, None]
        return np.sum(self.w2k * r, axis=1) / self.denominator


def crank_offset(d, order, w, sigma_db) -> float:
    """Profiled crank-angle offset δ [rad] of one run (:class:`OffsetProfile`; ``d`` model
    minus measured phase [rad], ``order`` k and ``w`` the weights at the scored phase
    points, 1-D)."""
    return OffsetProfile(order, w, sigma_db)(d)


def phase_gaps(velocity, phase_deg, w, order, delta):
    """Phase residuals [dB] (like ``w``; NaN where no phase counts) of the model's complex
    velocities ``velocity`` (same cells) at the crank offset ``delta`` [rad]."""
    d = wrap(np.angle(velocity) - order * delta - np.deg2rad(phase_deg))
    return w * d


def rows_with_phase(g, d, profile, w, sigma_db) -> list:
    """Each row of the level gaps ``g`` (n_b, n) followed by its phase gaps and its crank
    offset's prior: ``d`` (n_b, n_p) the model minus measured phases [rad] at the scored
    phase points, ``w`` their weights, ``profile`` the run's :class:`OffsetProfile` (the
    offset profiled per row, as one row at a time)."""
    delta = profile.rows(d)
    gp = w * wrap(d - profile.order * delta[:, None])
    return [np.concatenate([gi, gpi, [offset_prior(float(di), sigma_db)]])
            for gi, gpi, di in zip(g, gp, delta)]


def offset_prior(delta, sigma_db) -> float:
    """The crank offset's prior residual [dB]."""
    return sigma_db * delta / math.radians(CRANK_OFFSET_SD_DEG)
