r"""A transient manoeuvre: the crank speed and the engine load over time.

The crank speed is a table of time and speed, linear between the rows, so the crank's
angular acceleration :math:`\alpha` is constant on each interval and the crank angle is
exact (a quadratic in time per interval):

.. math:: \theta(t) = \Theta_i + \omega_i (t - t_i) + \tfrac12\alpha_i (t - t_i)^2,
   \qquad \alpha_i = \frac{\omega_{i+1} - \omega_i}{t_{i+1} - t_i}.

The load is a second table, linear between its rows: the IMEP scale of the engine's
combustion model or the mean torque into the driveline (:class:`Manoeuvre`; the file reader
is :mod:`powertrain.iotools.manoeuvre_file`, the guide ``docs/guide/transient.md``). SI.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: Load kinds a manoeuvre's load table may hold.
LOAD_KINDS = ("imep_scale", "mean_torque")


@dataclass(frozen=True, eq=False)
class Starter:
    """A starter (or integrated starter-generator) that drives the crank.

    Attributes
    ----------
    ratio : float
        Ring gear over pinion (or belt) ratio [-].
    reaction_point : ndarray (3,)
        Where it reacts on the block, engine axes [m].
    until : float
        Time it disengages [s].
    """

    ratio: float
    reaction_point: np.ndarray
    until: float


@dataclass(frozen=True, eq=False)
class Manoeuvre:
    """Crank speed and load tables of a transient (module docstring).

    Attributes
    ----------
    name : str
    time, speed : ndarray (n,)
        Speed table: times [s] from 0, strictly increasing; crank speed [rad/s].
    load_time, load : ndarray (m,)
        Load table: times [s] covering the speed table's; IMEP scale [-] or mean
        torque [N·m] (``load_kind``).
    load_kind : str
        ``"imep_scale"`` or ``"mean_torque"``.
    gear_ratio : float
        Overall ratio of the driveline torque's reaction [-]; 0 = neutral.
    crank_inertia : float
        Crank train and flywheel about the crank axis [kg·m²].
    starter : Starter or None
    reversal : bool
        The crank may turn backwards (speed < 0).
    file : str
        The file it was read from.
    notes : str
    """

    name: str
    time: np.ndarray
    speed: np.ndarray
    load_time: np.ndarray
    load: np.ndarray
    load_kind: str = "imep_scale"
    gear_ratio: float = 0.0
    crank_inertia: float = 0.0
    starter: Starter | None = None
    reversal: bool = False
    file: str = ""
    notes: str = ""

    @property
    def duration(self) -> float:
        """Length of the manoeuvre [s]."""
        return float(self.time[-1])

    @property
    def max_speed(self) -> float:
        """Largest crank speed magnitude [rad/s]."""
        return float(np.max(np.abs(self.speed)))

    def crank_motion(self, t):
        """Crank angle [rad], speed [rad/s] and angular acceleration [rad/s²] at the times
        ``t`` [s] (arrays of the shape of ``t``; constant beyond the table's ends)."""
        t = np.clip(np.asarray(t, float), self.time[0], self.time[-1])
        dt = np.diff(self.time)
        accel = np.diff(self.speed) / dt
        start = np.concatenate([[0.0], np.cumsum(self.speed[:-1] * dt + 0.5 * accel * dt ** 2)])
        i = np.clip(np.searchsorted(self.time, t, side="right") - 1, 0, dt.size - 1)
        tau = t - self.time[i]
        omega = self.speed[i] + accel[i] * tau
        theta = start[i] + self.speed[i] * tau + 0.5 * accel[i] * tau ** 2
        return theta, omega, accel[i]

    def load_at(self, t) -> np.ndarray:
        """The load table at the times ``t`` [s], linear between its rows."""
        return np.interp(np.asarray(t, float), self.load_time, self.load)

    def with_speed(self, time, speed) -> Manoeuvre:
        """A copy driven by another speed table (e.g. a recorded one)."""
        return replace(self, time=np.asarray(time, float), speed=np.asarray(speed, float))
