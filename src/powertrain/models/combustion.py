"""Combustion models of an engine: the single-zone pressure model and measured traces.

Each gives every cylinder's pressure over a cycle at a speed (``cycle_pressures``) and its
speed range (``speed_range``), over :mod:`powertrain.physics.combustion` (SI).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from powertrain.errors import InputError
from powertrain.models.crank_train import CrankTrain
from powertrain.models.memo import Memo
from powertrain.physics import combustion as comb

#: rad/s per rpm.
RPM = 2.0 * np.pi / 60.0


@dataclass(frozen=True, eq=False)
class FullLoadCurve:
    """Full-load brake torque and friction mean effective pressure against speed.

    Attributes
    ----------
    speed : ndarray
        Engine speed [rad/s], increasing.
    torque : ndarray
        Full-load brake torque [N·m].
    fmep : ndarray
        Friction mean effective pressure [Pa].
    """

    speed: np.ndarray
    torque: np.ndarray
    fmep: np.ndarray

    def imep(self, omega: float, displacement: float, load: float = 1.0) -> float:
        r"""Net IMEP :math:`4\pi T_b/V_D + \mathrm{FMEP}` [Pa] at ``omega`` [rad/s] for ``load``
        × full-load torque."""
        tb = load * np.interp(omega, self.speed, self.torque)
        return float(4.0 * np.pi * tb / displacement + self.fmep_at(omega))

    def fmep_at(self, omega: float) -> float:
        """FMEP [Pa] at ``omega`` [rad/s], interpolated linearly in the curve."""
        return float(np.interp(omega, self.speed, self.fmep))


@dataclass(frozen=True, eq=False)
class SingleZoneCombustion:
    """Parameters of the single-zone pressure model (SI; see :mod:`powertrain.physics.combustion`)."""

    full_load: FullLoadCurve
    imep_factors: np.ndarray
    ambient_pressure: float
    start: float
    duration: float
    wiebe_a: float
    wiebe_m: float
    n_compression: float
    n_expansion: float
    exhaust_valve_opening: float
    blowdown_end: float
    valve_overlap: float
    exhaust_pressure_ratio: float
    intake_pressure_min: float
    intake_pressure_max: float
    indicated_efficiency: float
    volumetric_efficiency: float
    air_fuel_ratio: float
    heating_value: float
    intake_temperature: float
    grid_points: int = 5760
    model: str = "single-zone"
    _memo: Memo = field(default_factory=Memo, init=False, repr=False, compare=False)
    speed_key = "combustion.full_load.speed"

    def with_cylinder_factors(self, factors) -> SingleZoneCombustion:
        """Cylinder i's combustion times ``factors[i]``: its IMEP target."""
        return dataclasses.replace(self, imep_factors=np.asarray(self.imep_factors, float)
                                   * np.asarray(factors, float))

    def cycle_pressures(self, crank: CrankTrain, omega: float, load: float = 1.0):
        """Pressure of every cylinder on the cycle grid.

        Returns
        -------
        theta : ndarray, shape (N,)
            Grid of cylinder cycle angles on ``[-π, 3π)`` [rad].
        pressure : ndarray, shape (n_cyl, N)
            Absolute pressure [Pa].
        info : dict
            ``imep_target`` [Pa] per cylinder, ``heat`` [J] per cylinder, ``p_intake``,
            ``p_exhaust`` [Pa].
        """
        theta, V, dV, (b_in, b_ex, p1) = self.cycle_basis(crank)
        vd = crank.swept_volume
        imep = self.full_load.imep(omega, crank.displacement, load)
        p_in = comb.boost_pressure(
            imep, vd, V[0], indicated_efficiency=self.indicated_efficiency,
            air_fuel_ratio=self.air_fuel_ratio, heating_value=self.heating_value,
            intake_temperature=self.intake_temperature,
            volumetric_efficiency=self.volumetric_efficiency)
        p_in = float(np.clip(p_in, self.intake_pressure_min, self.intake_pressure_max))
        p_ex = max(self.ambient_pressure, self.exhaust_pressure_ratio * p_in)
        p0 = p_in * b_in + p_ex * b_ex
        dtheta = 4.0 * np.pi / theta.size
        targets = imep * np.asarray(self.imep_factors, dtype=float)
        heats = np.array([comb.calibrate_heat(p0, p1, dV, dtheta, vd, t) for t in targets])
        pressure = p0[None, :] + heats[:, None] * p1[None, :]
        return theta, pressure, {"imep_target": targets, "heat": heats, "p_intake": p_in,
                                 "p_exhaust": p_ex}

    def motored_pressures(self, crank: CrankTrain, omega: float, intake_pressure=None):
        """:meth:`cycle_pressures` without burn, from ``intake_pressure`` [Pa] (default ambient)."""
        theta, _, _, (b_in, b_ex, _) = self.cycle_basis(crank)
        p_in = self.ambient_pressure if intake_pressure is None else float(intake_pressure)
        p_ex = max(self.ambient_pressure, self.exhaust_pressure_ratio * p_in)
        n_cyl = len(self.imep_factors)
        pressure = np.tile(p_in * b_in + p_ex * b_ex, (n_cyl, 1))
        return theta, pressure, {"imep_target": np.full(n_cyl, np.nan),
                                 "heat": np.zeros(n_cyl), "p_intake": p_in,
                                 "p_exhaust": p_ex}

    def cycle_basis(self, crank: CrankTrain):
        """Speed-independent cycle grid ``theta`` [rad], ``V`` [m³], ``dV/dtheta`` [m³/rad] and
        :func:`~powertrain.physics.combustion.pressure_basis` of ``crank`` (memoised, read-only)."""
        kept = self._memo.get("cycle basis")
        if kept is not None and kept[0] is crank:
            return kept[1]
        n = self.grid_points
        theta = -np.pi + 4.0 * np.pi * np.arange(n) / n
        V, dV = crank.volume(theta)
        basis = comb.pressure_basis(theta, V, self.n_compression, self.n_expansion,
                                    self.start, self.duration, self.wiebe_a, self.wiebe_m,
                                    self.exhaust_valve_opening, self.blowdown_end,
                                    self.valve_overlap)
        for a in (theta, V, dV, *basis):
            a.setflags(write=False)
        self._memo["cycle basis"] = (crank, (theta, V, dV, basis))
        return theta, V, dV, basis

    def friction_mean_effective_pressure(self, omega: float) -> float:
        """FMEP [Pa] at ``omega`` [rad/s]: the full-load curve's."""
        return self.full_load.fmep_at(omega)

    def speed_range(self):
        """(min, max) speed of the full-load curve [rad/s]."""
        return float(self.full_load.speed[0]), float(self.full_load.speed[-1])


@dataclass(frozen=True, eq=False)
class MeasuredPressure:
    """Measured cylinder-pressure traces (see :mod:`powertrain.iotools.pressure_csv`).

    Attributes
    ----------
    file : str
    speed : ndarray
        Measured speeds [rad/s], increasing.
    pressure : ndarray, shape (n_speed, n_cyl, N)
        Absolute pressure [Pa] on the common grid ``theta``.
    theta : ndarray, shape (N,)
        Cylinder cycle angles on ``[-π, 3π)`` [rad].
    """

    file: str
    speed: np.ndarray
    pressure: np.ndarray
    theta: np.ndarray
    model: str = "measured"
    speed_key = "combustion.traces"

    def cycle_pressures(self, crank: CrankTrain, omega: float, load: float = 1.0):
        """Pressure of every cylinder on the grid, linear in speed; ``load`` must be 1."""
        if load != 1.0:
            raise InputError("measured pressure traces cannot be scaled to another load",
                             file=self.file, key="load")
        lo, hi = self.speed_range()
        if not lo - 1e-9 <= omega <= hi + 1e-9:
            raise InputError(f"speed {omega / RPM:.6g} rpm outside the measured traces "
                             f"({lo / RPM:.6g}..{hi / RPM:.6g} rpm)", file=self.file,
                             key="speed")
        if len(self.speed) == 1:
            p = self.pressure[0]
        else:
            j = int(np.clip(np.searchsorted(self.speed, omega) - 1, 0, len(self.speed) - 2))
            w = (omega - self.speed[j]) / (self.speed[j + 1] - self.speed[j])
            p = (1 - w) * self.pressure[j] + w * self.pressure[j + 1]
        dtheta = self.theta[1] - self.theta[0]
        _, dV = crank.volume(self.theta)
        imep = comb.indicated_work(np.atleast_2d(p), dV, dtheta) / crank.swept_volume
        return self.theta, p, {"imep_target": imep, "heat": np.full(len(p), np.nan),
                               "p_intake": float("nan"), "p_exhaust": float("nan")}

    def friction_mean_effective_pressure(self, omega: float) -> float:
        """0: measured traces give no FMEP."""
        return 0.0

    def speed_range(self):
        return float(self.speed[0]), float(self.speed[-1])


class _OnBase:
    """A combustion model run another way, with its base model's kind, speed key and range."""

    @property
    def model(self):
        return self.base.model

    @property
    def speed_key(self):
        return self.base.speed_key

    def speed_range(self):
        return self.base.speed_range()


@dataclass(frozen=True, eq=False)
class LoadedCombustion(_OnBase):
    """A combustion model run at ``load`` times its nominal load (IMEP scale)."""

    base: object
    load: float

    @property
    def with_cylinder_factors(self):
        """The base's ``with_cylinder_factors`` at this load (None when the base has none)."""
        scale = getattr(self.base, "with_cylinder_factors", None)
        if scale is None:
            return None
        return lambda factors: LoadedCombustion(scale(factors), self.load)

    @property
    def motored_pressures(self):
        """The base's cycle without burn (None where it has none)."""
        return getattr(self.base, "motored_pressures", None)

    def cycle_pressures(self, crank: CrankTrain, omega: float, load: float = 1.0):
        return self.base.cycle_pressures(crank, omega, self.load * load)


@dataclass(frozen=True, eq=False)
class MotoredCombustion(_OnBase):
    """A combustion model's cycle without burn from ``intake_pressure`` [Pa] (None: default)."""

    base: object
    intake_pressure: float | None = None

    def cycle_pressures(self, crank: CrankTrain, omega: float, load: float = 1.0):
        motored = getattr(self.base, "motored_pressures", None)
        if motored is None:
            raise InputError("measured pressure traces have no cycle without burn (an IMEP "
                             "scale below the fired one of zero torque, or a negative "
                             "mean torque)", file=getattr(self.base, "file", None),
                             key="load")
        return motored(crank, omega, self.intake_pressure)

    def friction_mean_effective_pressure(self, omega: float) -> float:
        return self.base.friction_mean_effective_pressure(omega)
