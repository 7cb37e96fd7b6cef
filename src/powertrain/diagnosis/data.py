r"""Step 0 of the diagnosis: measured data on a speed grid, the noise floor, the speed split.

The model is the harmonic steady state at every measured speed in the engine's range, with
the noise floor :math:`f` (RMS per order) added in power, :math:`s' = \sqrt{s^2 + f^2}`
(synthesis: :math:`\sqrt{s^2 + 16 f^2}`). A point below the censoring level :math:`\kappa f`
(:mod:`powertrain.analysis.noise_floor`, :math:`\kappa = 3`) is *censored*: its residual is
:math:`\max(0, 20\log_{10}(s'/\kappa f))`, so noise is never scored as a gap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.noise_floor import above_floor, at_floor, censoring_level
from powertrain.diagnosis.noise_model import mad_sigma, second_differences
from powertrain.iotools.measured import quantity_sort_key
from powertrain.solvers.body_coupling import ModalBody, body_channels

#: Default RMS noise floor of the measured order curves [m/s].
DEFAULT_NOISE_FLOOR = 1.0e-6
#: Training speeds used for fitting (evenly chosen among the training blocks).
N_FIT_RPM = 24
#: Held-out speeds scored (evenly chosen among the held-out blocks).
N_TEST_RPM = 36
#: Blocks of the speed split and those held out (0-based).
N_BLOCKS = 12
HELDOUT_BLOCKS = (1, 4, 7, 10)
#: Speed folds of the cross-fit (every block held out once).
N_FOLDS = 3
#: Smallest data set that can be split: speeds in total.
MIN_RPM = 12
#: Dynamic range of measured order levels [dB]: a point more than this below the strongest
#: order at its speed is numerical error (a lab's order tracking resolves 60-80 dB) and is
#: left out like an absent point (levels below 3x the floor stay censored).
DYNAMIC_RANGE_DB = 90.0


@dataclass
class GapData:
    """Measured levels on a speed grid, arranged for fast comparison.

    Attributes
    ----------
    rpm : ndarray (n_r,)
        Speeds [rpm].
    channels : list of (mount, direction)
    quantities : list of str
        Orders (``order_2``...) then ``synthesis`` if measured.
    harmonic : ndarray (n_q,) int
        Index into the 16 orders 0.5..8 (−1 for the synthesis).
    level : ndarray (n_r, n_ch, n_q)
        Measured RMS velocity [m/s]; NaN where absent.
    floor : float
        Noise floor [m/s RMS].
    """

    rpm: np.ndarray
    channels: list
    quantities: list
    harmonic: np.ndarray
    level: np.ndarray
    floor: float

    @property
    def order_mask(self):
        return self.harmonic >= 0

    @property
    def censored(self):
        """Measured points at the floor (bool, like ``level``; absent points False)."""
        return at_floor(self.level, self.floor) & np.isfinite(self.level)

    @property
    def usable(self):
        """Measured points above the floor (bool, like ``level``)."""
        return above_floor(self.level, self.floor)

    @property
    def order_hz(self):
        """Frequency [Hz] (n_r, n_q): order × rpm / 60 (0 for the synthesis)."""
        return self.rpm[:, None] * ((self.harmonic + 1) / 2.0)[None, :] / 60.0

    def band_hz(self) -> tuple | None:
        """``(lowest, highest)`` order frequency [Hz] measured above the floor (or None)."""
        ok = self.usable & self.order_mask[None, None, :]
        f = np.broadcast_to(self.order_hz[:, None, :], ok.shape)[ok]
        return (float(f.min()), float(f.max())) if f.size else None

    #: Engine-side channels (the first ones); None: all.
    n_engine_side: int | None = None
    #: Measured order phase φ [deg] like ``level`` (None: no phase): the order-k component
    #: is √2·RMS·cos(kθ + φ), θ from cylinder-1 firing TDC.
    phase: np.ndarray | None = None

    @property
    def has_phase(self) -> bool:
        """Some order phase is measured."""
        return self.phase is not None and bool(np.isfinite(self.phase).any())

    @property
    def has_half_order_phase(self) -> bool:
        """Some half-order phase is measured (a cycle reference was used)."""
        if not self.has_phase:
            return False
        half = (self.harmonic >= 0) & (self.harmonic % 2 == 0)
        return bool(np.isfinite(self.phase[:, :, half]).any())

    @property
    def n_active(self) -> int:
        """Number of engine-side channels."""
        return len(self.channels) if self.n_engine_side is None else self.n_engine_side

    def active_only(self) -> GapData:
        """The same data on the engine-side channels only."""
        n = self.n_active
        return GapData(self.rpm, self.channels[:n], self.quantities, self.harmonic,
                       self.level[:, :n], self.floor, phase=None if self.phase is None else self.phase[:, :n])

    def orders_only(self) -> GapData:
        """The same data without the synthesis."""
        om = self.order_mask
        return GapData(self.rpm, self.channels, [q for q, o in zip(self.quantities, om) if o],
                       self.harmonic[om], self.level[:, :, om], self.floor, self.n_engine_side,
                       None if self.phase is None else self.phase[:, :, om])


def model_channels(engine) -> list:
    """Channels the fast model predicts for ``engine``: mounts' engine sides, and with a modal
    body their body sides (``NAME/passive``) and the body points."""
    active = [(m.name, a) for m in engine.mounts for a in ("x", "y", "z")]
    body = ModalBody.of(engine)
    if body is None:
        return active
    return active + body_channels([m.name for m in engine.mounts], body)


def _half_order_quantities(measured):
    quantities = []
    for q in sorted({q for _, _, q in measured.curves}, key=quantity_sort_key):
        if q == "synthesis":
            continue
        o = float(q.split("_", 1)[1])
        if abs(2 * o - round(2 * o)) < 1e-9 and 0.5 <= o <= 8.0:
            quantities.append(q)
    if any(q == "synthesis" for _, _, q in measured.curves):
        quantities.append("synthesis")
    return quantities


def gap_data(measured, engine, noise_floor=DEFAULT_NOISE_FLOOR) -> GapData:
    """Arrange a :class:`MeasuredRunup` on the union of its speeds inside the engine range.

    Parameters
    ----------
    measured : MeasuredRunup
    engine : Engine
    noise_floor : float
        RMS noise floor [m/s].
    """
    lo, hi = engine.speed_range_rpm()
    rpm = np.unique(np.concatenate([r for r, _ in measured.curves.values()]))
    rpm = rpm[(rpm >= lo - 1e-9) & (rpm <= hi + 1e-9)]
    channels = [(m.name, a) for m in engine.mounts for a in ("x", "y", "z")]
    measured_channels = {(m, d) for m, d, _ in measured.curves}
    channels += [c for c in model_channels(engine)[len(channels):] if c in measured_channels]
    quantities = _half_order_quantities(measured)
    harmonic = np.array([-1 if q == "synthesis" else int(round(2 * float(q[6:]))) - 1 for q in quantities])
    level = np.full((rpm.size, len(channels), len(quantities)), np.nan)
    phases = getattr(measured, "phases", None) or {}
    phase = np.full(level.shape, np.nan) if phases else None
    for (m, d, q), (r, v) in measured.curves.items():
        if (m, d) not in channels or q not in quantities:
            continue
        c, k = channels.index((m, d)), quantities.index(q)
        idx = np.searchsorted(rpm, r)
        ok = (idx < rpm.size) & (rpm[np.minimum(idx, rpm.size - 1)] == r)
        level[idx[ok], c, k] = v[ok]
        if (m, d, q) in phases and q != "synthesis":
            phase[idx[ok], c, k] = np.asarray(phases[(m, d, q)], float)[ok]
    _below_dynamic_range(level, phase, harmonic >= 0, float(noise_floor))
    return GapData(rpm, channels, quantities, harmonic, level, float(noise_floor),
                   3 * len(engine.mounts), phase)


def _below_dynamic_range(level, phase, orders, floor):
    """NaN (in place) where an order is :data:`DYNAMIC_RANGE_DB` below its speed's strongest."""
    lv = level[:, :, orders]
    with np.errstate(invalid="ignore"):
        top = np.max(np.where(np.isfinite(lv), lv, -np.inf), axis=(1, 2), keepdims=True)
        cut = (lv < top * 10 ** (-DYNAMIC_RANGE_DB / 20)) & above_floor(lv, floor)
    for a in [level] + ([] if phase is None else [phase]):
        sub = a[:, :, orders]
        sub[cut] = np.nan
        a[:, :, orders] = sub


def order_levels(velocity, floor):
    """Model RMS levels [m/s] of complex peak velocities, ``floor`` [m/s] added in power."""
    return np.sqrt((np.abs(velocity) / np.sqrt(2.0)) ** 2 + floor ** 2)


def model_levels(velocity, data: GapData):
    """Model RMS levels (n_r, n_ch, n_q) with the noise floor added in power [m/s]."""
    out = np.empty(velocity.shape[:2] + (data.harmonic.size,))
    order = data.harmonic >= 0
    out[..., order] = order_levels(velocity[..., data.harmonic[order]], data.floor)
    if not order.all():                                        # the synthesis
        rms = np.abs(velocity) / np.sqrt(2.0)
        out[..., ~order] = np.sqrt(np.sum(rms ** 2, axis=-1) + 16 * data.floor ** 2)[..., None]
    return out


class ScoredLevels:
    """:func:`residuals_db` of :func:`order_levels` at fixed points, the measured side formed
    once; ``meas`` (1-D, finite) the measured RMS levels [m/s], ``floor`` [m/s]."""

    def __init__(self, meas, floor):
        self.censored, self.ref_db = censored_reference_db(meas, floor)
        self.floor2 = float(floor) ** 2

    def __call__(self, velocity):
        """Gaps [dB] of the complex peak order velocities ``velocity`` (1-D, the points')."""
        g = 10.0 * np.log10(0.5 * (velocity.real ** 2 + velocity.imag ** 2) + self.floor2)
        g -= self.ref_db
        return np.where(self.censored, np.maximum(g, 0.0), g)


def censored_reference_db(meas, floor):
    """``(censored, reference [dB])`` of ``meas``: the censoring level where below it."""
    cl = censoring_level(floor)
    censored = meas < cl
    with np.errstate(divide="ignore", invalid="ignore"):
        return censored, 20.0 * np.log10(np.where(censored, cl, meas))


def residuals_db(sim, meas, floor):
    """Gap [dB] of ``sim`` over ``meas`` with censoring; NaN where nothing was measured."""
    cens, ref_db = censored_reference_db(meas, floor)
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = 20.0 * np.log10(sim) - ref_db
    gap = np.where(cens, np.maximum(0.0, gap), gap)
    return np.where(np.isfinite(meas), gap, np.nan)


def noise_sigma_db(data: GapData) -> float:
    r"""Measurement scatter [dB, 1σ] from second differences of the dB levels along speed,
    :math:`\hat\sigma = 1.4826\,\mathrm{MAD}/\sqrt6` (an upper bound on a coarse grid)."""
    lv = data.level[:, :, data.order_mask]
    ok = above_floor(lv, data.floor)
    with np.errstate(divide="ignore", invalid="ignore"):
        L = np.where(ok, 20 * np.log10(lv), np.nan)
    d2 = second_differences(L)
    return mad_sigma(d2) if d2.size >= 10 else float("nan")


def split_rpm(rpm, fold=0):
    """Training and held-out indices of ``rpm`` (12 blocks, 2, 5, 8, 11 held out); ``fold`` k
    holds out the blocks k places further on."""
    n = rpm.size
    block = np.minimum((np.arange(n) * N_BLOCKS) // n, N_BLOCKS - 1)
    test = np.isin(block, [(b + fold) % N_BLOCKS for b in HELDOUT_BLOCKS])
    return np.flatnonzero(~test), np.flatnonzero(test)


def even(idx, n_max):
    """At most ``n_max`` of ``idx``, evenly spread."""
    if idx.size <= n_max:
        return idx
    return idx[np.unique(np.round(np.linspace(0, idx.size - 1, n_max)).astype(int))]


def speed_groups(test_idx, size=4):
    """Runs of adjacent held-out speeds, cut into groups of about ``size`` speeds."""
    runs = np.split(np.arange(test_idx.size), np.flatnonzero(np.diff(test_idx) != 1) + 1)
    groups = []
    for r in runs:
        k = max(1, int(round(r.size / size)))
        groups += [g for g in np.array_split(r, k) if g.size >= 2]
    return groups
