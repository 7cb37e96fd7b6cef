r"""The load on the powertrain over a transient manoeuvre, at every time step.

At crank angle :math:`\theta`, speed :math:`\omega` and acceleration :math:`\alpha`
(:meth:`~powertrain.models.manoeuvre.Manoeuvre.crank_motion`) the block load is the run-up's
excitation at any speed (:meth:`Engine.load_table`) plus the moving masses' tangential
accelerations (:meth:`Engine.motion_patterns`):

.. math:: \mathbf f(t) = \tilde{\mathbf G}(\theta, |\omega|, s)
   + \omega^2\,\mathbf I(\theta) + \alpha\,\tilde{\mathbf A}(\theta)
   - \big(J\alpha + i\,T_d\big)\,\mathbf n .

:math:`\tilde{\mathbf G}`, :math:`\tilde{\mathbf A}` have the cycle mean of their roll moment
about the crank sense :math:`\mathbf n` removed; the mean roll reaction is the last term:
the crank train and flywheel (:math:`J`) accelerating push the housing back with
:math:`-J\alpha\,\mathbf n`, the driveline torque :math:`T_d` reacts through the gear ratio
:math:`i` (0 in neutral). The starter acts inside the powertrain (no net load); its torque
:math:`T_s = J\alpha + T_d - T_e` is reported.

The gas load is tabulated over crank angle (0.5°), speed (25 rpm, clamped to the combustion
model's range) and load level :math:`\lambda`, read trilinearly, and fades out linearly
below :data:`FADE_RPM`. The IMEP scale :math:`s` is 0 without burn (:meth:`Engine.motored`),
1 at full load; :math:`s_0(\omega) = W(0)/W(1)` is the indicated work of the zero-torque
fired cycle over the full-load one. From :math:`s_0` up :math:`\lambda = (s - s_0)/(1 -
s_0)` (fraction of full-load brake torque, steps of :data:`LEVEL_STEP`); below,
:math:`\lambda = s/s_0 - 1` mixes the motored cycle (:math:`\lambda = -1`) and the
zero-torque one. A mean torque :math:`T_d` is the level :math:`T_d / T_{full}(\omega)`, or
when negative :math:`T_d / |T_{motored}(\omega)|`. :math:`T_e` is the model's mean brake
torque at :math:`(\omega, \lambda)`; in the IMEP form :math:`T_d = T_e - J\alpha` in gear.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from powertrain.errors import PowertrainWarning
from powertrain.kernels import kernel_input
from powertrain.kernels.load_table import table_load
from powertrain.units import UNITS

#: Crank-angle samples of the load table over the cycle, and its speed step [rpm].
N_THETA = 1440
RPM_STEP = 25.0
#: Load levels of the table of a mean-torque manoeuvre, and the step of an IMEP table's.
TORQUE_SCALES = np.linspace(0.0, 1.0, 11)
LEVEL_STEP = 0.1
#: Below this speed [rpm] the gas load fades out linearly to none at rest (a crank at rest
#: holds its cylinders' gas torque inside the engine).
FADE_RPM = 50.0
RPM = UNITS["rpm"][1]


@dataclass(frozen=True)
class TransientLoad:
    """The manoeuvre at every time step: times [s], crank angle [rad], speed [rad/s],
    acceleration [rad/s²], IMEP scale [-], engine mean brake torque, driveline torque and
    starter torque [N·m], and the generalized load ``F`` (n_t, 6) [N, N·m] about the CG."""

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    scale: np.ndarray
    engine_torque: np.ndarray
    driveline_torque: np.ndarray
    starter_torque: np.ndarray
    F: np.ndarray


def transient_load(engine, manoeuvre, t) -> TransientLoad:
    """The load of ``manoeuvre`` on ``engine`` at the times ``t`` [s] (module docstring).

    Parameters
    ----------
    engine : Engine
    manoeuvre : Manoeuvre
    t : ndarray (n_t,)
        Times [s].
    """
    theta, omega, alpha = manoeuvre.crank_motion(t)
    n = np.array([float(engine.crank.rotation_sign), 0.0, 0.0])
    table = _GasTable(engine, manoeuvre)
    spin = np.abs(omega)
    if manoeuvre.load_kind == "mean_torque":
        driveline = manoeuvre.load_at(t)
        level = table.level_of_torque(spin, driveline)
        engine_torque = table.torque(spin, level)
        _warn_beyond(driveline, engine_torque, t)
    else:
        level = table.level_of_scale(spin, manoeuvre.load_at(t))
        engine_torque = table.torque(spin, level)
        driveline = (engine_torque - manoeuvre.crank_inertia * alpha
                     if manoeuvre.gear_ratio > 0 else np.zeros_like(t))
    scale = table.scale_of_level(spin, level)
    J = manoeuvre.crank_inertia
    F = table.load(theta, omega, alpha, level)
    F[:, 3] -= J * alpha * n[0]                     # n: the crank axis, the engine's x
    F[:, 3] += driveline_moment(engine, manoeuvre, driveline)
    starter = np.zeros_like(t)
    if manoeuvre.starter is not None:
        on = t < manoeuvre.starter.until
        starter[on] = (J * alpha + driveline - engine_torque)[on]
    return TransientLoad(np.asarray(t, float), theta, omega, alpha, scale, engine_torque,
                         driveline, starter, F)


def _warn_beyond(driveline, engine_torque, t):
    """Warn where a mean torque is beyond the engine's full load or motored drag."""
    off = np.abs(driveline - engine_torque) > 1e-6 * np.maximum(np.abs(driveline), 1.0)
    if off.any():
        i = int(np.argmax(np.abs(driveline - engine_torque)))
        warnings.warn(f"mean torque {driveline[i]:.4g} N*m at {t[i]:.4g} s is beyond what the "
                      f"engine gives there ({engine_torque[i]:.4g} N*m, its full load or its "
                      f"motored drag), during {np.mean(off):.0%} of the manoeuvre: the gas load "
                      "is that of the engine's limit, the driveline reaction the table's",
                      TorqueLimitWarning, stacklevel=3)


class TorqueLimitWarning(PowertrainWarning):
    """A manoeuvre's mean torque beyond the engine's full load or motored drag."""


def driveline_reaction(engine, manoeuvre, driveline):
    r"""The reaction (..., 6) [N, N·m] about the CG, :math:`-i\,T_d\,\mathbf n`, of the
    driveline torque ``driveline`` (...) [N·m] of ``manoeuvre`` on ``engine``."""
    out = np.zeros(np.shape(driveline) + (6,))
    out[..., 3] = driveline_moment(engine, manoeuvre, driveline)
    return out


def driveline_moment(engine, manoeuvre, driveline):
    """The moment (...) [N·m] about the engine's x axis of :func:`driveline_reaction`
    (same arguments)."""
    return -manoeuvre.gear_ratio * np.asarray(driveline, float) * float(engine.crank.rotation_sign)


class _GasTable:
    """Gas load and mean brake torque per load level and speed, and the motion patterns."""

    def __init__(self, engine, manoeuvre):
        lo, hi = engine.speed_range_rpm()
        top = min(hi, max(lo, manoeuvre.max_speed / RPM))
        self.speeds = np.arange(lo, top + RPM_STEP, RPM_STEP).clip(lo, top)
        self.zero = None if _full_only(manoeuvre) else np.array(
            [np.sum(engine.indicated_work(n, 0.0)) / np.sum(engine.indicated_work(n, 1.0))
             for n in self.speeds])
        self.scales = _levels(manoeuvre, self.zero)
        theta = np.arange(N_THETA) * (4 * np.pi / N_THETA)
        self.n = np.array([float(engine.crank.rotation_sign), 0.0, 0.0])
        inertia, acceleration = engine.motion_patterns(theta)
        motored = (engine.motored(manoeuvre.motored_intake_pressure)   # after: its patterns
                   if self.scales[0] < 0 else None)
        fired = self.scales >= 0
        gas = np.empty((self.scales.size, self.speeds.size, N_THETA + 1, 6))
        gas[fired, :, :-1] = engine.load_tables(self.speeds, theta, self.scales[fired])
        if motored is not None:
            gas[~fired, :, :-1] = motored.load_table(self.speeds, theta)
        gas[:, :, :-1] -= ((self.speeds * RPM) ** 2)[:, None, None] * inertia
        self.table = self._no_mean_roll(gas)
        self.table[:, :, -1] = self.table[:, :, 0]               # the periodic wrap
        self.inertia = np.r_[inertia, inertia[:1]]
        self.acceleration = self._no_mean_roll(np.r_[acceleration, acceleration[:1]])
        self.torques = np.array([[motored.mean_brake_torque(n) if s < 0 else
                                  engine.mean_brake_torque(n, s) for n in self.speeds]
                                 for s in self.scales])
        self.full = np.array([engine.mean_brake_torque(n, 1.0) for n in self.speeds])

    def level_of_scale(self, spin, scale):
        """Load level of the IMEP ``scale`` at the speeds ``spin`` [rad/s]."""
        if self.zero is None:
            return np.asarray(scale, float)
        s0 = self._by_speed(self.zero, spin)
        return np.where(scale >= s0, (scale - s0) / (1.0 - s0), scale / s0 - 1.0)

    def scale_of_level(self, spin, level):
        """IMEP scale [-] of the load ``level`` at the speeds ``spin`` [rad/s]."""
        if self.zero is None:
            return np.asarray(level, float)
        s0 = self._by_speed(self.zero, spin)
        return np.where(level >= 0, s0 + level * (1.0 - s0), (1.0 + level) * s0)

    def level_of_torque(self, spin, torque):
        """Load level of the mean brake ``torque`` [N·m] at ``spin`` [rad/s], within the table."""
        full = np.maximum(self._by_speed(self.full, spin), 1e-9)
        level = np.where(torque >= 0, torque / full, 0.0)
        if self.scales[0] < 0:
            drag = np.minimum(self._by_speed(self.torques[0], spin), -1e-9)
            level = np.where(torque < 0, torque / -drag, level)
        return np.clip(level, self.scales[0], self.scales[-1])

    def _by_speed(self, values, spin):
        v0, v1, fv = self._speed_index(spin)
        return values[v0] * (1 - fv) + values[v1] * fv

    def _no_mean_roll(self, load):
        """``load`` (..., n_theta + 1, 6) with the cycle mean of its roll moment removed, in place."""
        s = self.n[0]
        load[..., 3] -= np.mean(load[..., :-1, 3] * s, axis=-1)[..., None] * s
        return load

    def _speed_index(self, spin):
        v = np.clip((spin / RPM - self.speeds[0]) / RPM_STEP, 0.0, self.speeds.size - 1.0)
        i = np.minimum(v.astype(np.int64), max(self.speeds.size - 2, 0))
        return i, np.minimum(i + 1, self.speeds.size - 1), v - i

    def _scale_index(self, scale):
        s = self.scales
        if s.size == 1:
            return np.zeros(scale.size, np.int64), np.zeros(scale.size, np.int64), np.zeros(scale.size)
        j = np.clip(np.searchsorted(s, scale, side="right") - 1, 0, s.size - 2)
        w = np.clip((scale - s[j]) / (s[j + 1] - s[j]), 0.0, 1.0)
        return j, j + 1, w

    def load(self, theta, omega, alpha, level):
        """Load (n_t, 6) at crank angles ``theta`` [rad], speeds ``omega`` [rad/s],
        accelerations ``alpha`` [rad/s²] and load ``level``."""
        spin = np.abs(omega)
        s0, _, fs = self._scale_index(level)
        v0, _, fv = self._speed_index(spin)
        out = np.empty((np.size(theta), 6))
        table_load(*(kernel_input(a) for a in (
            self.table, self.inertia, self.acceleration, np.column_stack([s0, fs]),
            np.column_stack([v0, fv]), np.mod(theta, 4 * np.pi) * (N_THETA / (4 * np.pi)),
            np.clip(spin / (FADE_RPM * RPM), 0.0, 1.0), omega ** 2, alpha)), out)
        return out

    def torque(self, spin, scale):
        """Mean brake torque [N·m] at the speeds ``spin`` [rad/s] and levels ``scale``, bilinear."""
        s0, s1, fs = self._scale_index(scale)
        v0, v1, fv = self._speed_index(spin)
        T = self.torques
        return ((T[s0, v0] * (1 - fv) + T[s0, v1] * fv) * (1 - fs)
                + (T[s1, v0] * (1 - fv) + T[s1, v1] * fv) * fs)


def _full_only(manoeuvre):
    """An IMEP manoeuvre at the model's own load throughout."""
    return manoeuvre.load_kind == "imep_scale" and bool(np.all(manoeuvre.load == 1.0))


def _levels(manoeuvre, zero):
    """Load levels of the gas table: -1 (no burn) where needed, then steps of :data:`LEVEL_STEP`."""
    if zero is None:
        return np.array([1.0])
    if manoeuvre.load_kind == "mean_torque":
        return np.r_[[-1.0] if np.any(manoeuvre.load < 0) else [], TORQUE_SCALES]
    s_max = float(np.max(manoeuvre.load))
    top = np.ceil(max(np.max((s_max - zero) / (1.0 - zero)), 0.0) / LEVEL_STEP - 1e-9) * LEVEL_STEP
    fired = np.arange(0.0, top + LEVEL_STEP / 2, LEVEL_STEP)
    low = [-1.0] if np.min(manoeuvre.load) < np.max(zero) else []
    return np.r_[low, fired if fired.size > 1 or low else [0.0, LEVEL_STEP]]
