r"""Order phase in the diagnosis: complex residuals with a level-dependent noise model and the
run's crank-angle offset as a nuisance parameter.

Where a point carries its order phase :math:`\varphi` (order-k component
:math:`\sqrt2\,\mathrm{RMS}\cos(k\theta + \varphi)`, θ from cylinder-1 firing TDC) above the
censoring level, the phase gap :math:`\Delta = \mathrm{wrap}(\arg\hat v - k\delta - \varphi)`
is scored besides the level gap, as a residual with a level gap's 1σ:

.. math:: \sigma_\varphi = \sqrt{(\sigma\ln 10/20)^2 + (f/L)^2},\qquad
          r_\varphi = \frac{\sigma}{\sigma_\varphi}\,\Delta \quad[\mathrm{dB}].

The crank offset δ (prior :data:`CRANK_OFFSET_SD_DEG`) shifts order k's phase by −kδ; it is
profiled out per run on the training speeds and reused on the held-out ones.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.analysis.noise_floor import above_floor

#: 1σ of a lab's crank-angle (TDC) offset [deg crank].
CRANK_OFFSET_SD_DEG = 1.0


def wrap(x):
    """Angle ``x`` wrapped to [−π, π) [rad]."""
    return np.mod(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


def phase_weights(level, phase_deg, floor, sigma_db):
    """Weights σ/σ_φ [dB/rad] of the phase gaps at RMS ``level`` and ``floor`` [m/s] for scatter
    ``sigma_db``; NaN where ``phase_deg`` is missing or the level is censored."""
    sigma_r = sigma_db * math.log(10.0) / 20.0
    with np.errstate(divide="ignore", invalid="ignore"):
        s_phi = np.sqrt(sigma_r ** 2 + (floor / level) ** 2)
        w = sigma_db / s_phi
    ok = above_floor(level, floor) & np.isfinite(phase_deg)
    return np.where(ok, w, np.nan)


class OffsetProfile:
    r"""A run's crank-angle offset δ [rad] minimising
    :math:`\sum w^2\,\mathrm{wrap}(d - k\delta)^2 + (\sigma\delta/\sigma_\delta)^2` by two
    re-wrapped weighted least-squares steps; ``order`` k and ``w`` of the scored points."""

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
        """δ [rad] of each row of ``d`` (n_b, n_points)."""
        if d.shape[1] == 0:
            return np.zeros(d.shape[0])
        k = self.order
        delta = np.sum(self.w2k * wrap(d), axis=1) / self.denominator
        r = wrap(d - k * delta[:, None]) + k * delta[:, None]
        return np.sum(self.w2k * r, axis=1) / self.denominator


def crank_offset(d, order, w, sigma_db) -> float:
    """Profiled crank-angle offset δ [rad] (:class:`OffsetProfile`) of model minus measured
    phases ``d`` [rad] at orders ``order``, weights ``w``, scatter ``sigma_db``."""
    return OffsetProfile(order, w, sigma_db)(d)


def phase_gaps(velocity, phase_deg, w, order, delta):
    """Phase residuals [dB] like ``w`` of complex ``velocity`` against ``phase_deg`` at
    orders ``order`` and crank offset ``delta`` [rad]."""
    d = wrap(np.angle(velocity) - order * delta - np.deg2rad(phase_deg))
    return w * d


def rows_with_phase(g, d, profile, w, sigma_db) -> list:
    """Each row of level gaps ``g`` (n_b, n) followed by its phase gaps (``d`` (n_b, n_p)
    model minus measured phases [rad], weights ``w``) and offset prior (``profile``)."""
    delta = profile.rows(d)
    gp = w * wrap(d - profile.order * delta[:, None])
    return [np.concatenate([gi, gpi, [offset_prior(float(di), sigma_db)]])
            for gi, gpi, di in zip(g, gp, delta)]


def offset_prior(delta, sigma_db) -> float:
    """The crank offset ``delta``'s prior residual [dB]."""
    return sigma_db * delta / math.radians(CRANK_OFFSET_SD_DEG)
