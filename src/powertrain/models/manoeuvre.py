r"""A transient manoeuvre: the crank speed and the engine load over time.

The crank speed is a table linear between rows, so :math:`\alpha_i` is constant per interval
and :math:`\theta(t) = \Theta_i + \omega_i (t - t_i) + \tfrac12\alpha_i (t - t_i)^2` exactly.
The load (IMEP scale or mean driveline torque) is a second table, linear between rows
(``docs/guide/transient.md``). SI.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from powertrain.errors import InputError

#: Load kinds a manoeuvre's load table may hold.
LOAD_KINDS = ("imep_scale", "mean_torque")
#: Longest manoeuvre [s]; longest interval between rows over which the value changes [s].
MAX_DURATION = 60.0
MAX_GAP = 5.0
#: Largest crank speed [rpm] and IMEP scale [-].
MAX_RPM = 12000.0
MAX_IMEP_SCALE = 2.0
#: Largest mean torque magnitude [N·m], gear ratio [-] and crank train inertia [kg·m²].
MAX_TORQUE = 5000.0
MAX_GEAR_RATIO = 50.0
MAX_CRANK_INERTIA = 20.0
#: Intake pressure of the cycle without burn [Pa], least and most.
MOTORED_INTAKE_PRESSURE = (0.05e5, 4e5)
#: A starter's ratio range [-] and its reaction point's largest distance from the origin [m].
STARTER_RATIO = (0.1, 100.0)
MAX_REACH = 3.0


@dataclass(frozen=True, eq=False)
class Starter:
    """A starter (or starter-generator) that drives the crank.

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
    file: str = ""

    def __post_init__(self):
        lo, hi = STARTER_RATIO
        _require(_finite(self.ratio) and lo <= self.ratio <= hi,
                 f"must be {lo:g}..{hi:g}, got {self.ratio!r}", self.file, "starter.ratio")
        point = np.asarray(self.reaction_point, float)
        _require(point.shape == (3,) and np.all(np.isfinite(point))
                 and np.linalg.norm(point) <= MAX_REACH,
                 f"a point on the block: at most {MAX_REACH:g} m from the engine origin",
                 self.file, "starter.reaction_point")
        _require(_finite(self.until) and self.until >= 0, "must be >= 0 s", self.file,
                 "starter.until")


@dataclass(frozen=True, eq=False)
class Manoeuvre:
    """Crank speed and load tables of a transient.

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
    file, notes : str
        The file it was read from; notes.
    motored_intake_pressure : float or None
        Intake pressure of the cycle without burn [Pa]; None: the model's ambient pressure.
    trigger_time : float
        Time [s] at which a recording's trigger channel rises (before the end).
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
    motored_intake_pressure: float | None = None
    trigger_time: float = 0.0

    def __post_init__(self):
        f = self.file or None
        _require(isinstance(self.name, str), "expected a string", f, "manoeuvre.name")
        _require(isinstance(self.reversal, (bool, np.bool_)), "expected true or false", f,
                 "manoeuvre.reversal")
        lo, hi = MOTORED_INTAKE_PRESSURE
        p = self.motored_intake_pressure
        _require(p is None or (_finite(p) and lo <= p <= hi), f"must be {lo / 1e5:g}.."
                 f"{hi / 1e5:g} bar", f, "load.motored_intake_pressure")
        t, w = _times(self.time, self.speed, f, "speed")
        _require(self.reversal or not np.any(w < 0), "negative speed but the manoeuvre "
                 "allows no reversal (set manoeuvre.reversal = true)", f, "speed.speed")
        _require(np.max(np.abs(w)) * 30.0 / np.pi <= MAX_RPM * (1 + 1e-12),
                 f"at most {MAX_RPM:g} rpm", f, "speed.speed")
        _require(self.load_kind in LOAD_KINDS, f"one of {', '.join(LOAD_KINDS)}", f, "load")
        tl, load = _times(self.load_time, self.load, f, "load", self.load_kind)
        _require(tl[-1] >= t[-1] - 1e-12, f"ends at {tl[-1]:g} s, before the speed table's "
                 f"{t[-1]:g} s (a gap)", f, "load.time")
        scale = self.load_kind == "imep_scale"
        _require(not scale or np.all(load >= 0), "must not be negative", f,
                 "load.imep_scale")
        bound = MAX_IMEP_SCALE if scale else MAX_TORQUE
        _require(np.max(np.abs(load)) <= bound, f"at most {bound:g} in magnitude", f,
                 f"load.{self.load_kind}")
        for key, value, top in (("gear_ratio", self.gear_ratio, MAX_GEAR_RATIO),
                                ("crank_inertia", self.crank_inertia, MAX_CRANK_INERTIA)):
            _require(_finite(value) and 0 <= value <= top, f"must be 0..{top:g}, got "
                     f"{value!r}", f, f"manoeuvre.{key}")
        _require(self.crank_inertia > 0 or np.ptp(w) == 0, "missing: the crank train's and "
                 "flywheel's inertia, whose reaction J*alpha acts where the speed changes",
                 f, "manoeuvre.crank_inertia")
        _require(_finite(self.trigger_time) and 0 <= self.trigger_time < t[-1],
                 f"must be 0 s or later and before the end ({t[-1]:g} s), got "
                 f"{self.trigger_time!r}", f, "manoeuvre.trigger_time")
        _require(self.starter is None or self.starter.until <= t[-1],
                 f"after the end of the manoeuvre ({t[-1]:g} s)", f, "starter.until")

    @property
    def duration(self) -> float:
        """Length of the manoeuvre [s]."""
        return float(self.time[-1])

    @property
    def max_speed(self) -> float:
        """Largest crank speed magnitude [rad/s]."""
        return float(np.max(np.abs(self.speed)))

    def crank_motion(self, t):
        """Crank angle [rad], speed [rad/s] and acceleration [rad/s²] at the times ``t`` [s]."""
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
        f = self.file or None
        return replace(self, time=_numbers(time, f, "speed.time"),
                       speed=_numbers(speed, f, "speed.speed"))


def _numbers(values, file, key) -> np.ndarray:
    """``values`` as floats, else an :class:`InputError` naming ``key``."""
    try:
        return np.asarray(values, float)
    except (TypeError, ValueError):
        raise InputError("expected numbers", file=file, key=key) from None


def _finite(value) -> bool:
    return isinstance(value, (int, float, np.floating, np.integer)) and bool(
        np.isfinite(value))


def _require(ok, message, file, key):
    if not ok:
        raise InputError(message, file=file, key=key)


def _times(time, value, file, table, column="speed"):
    """A table's time and value columns, checked (finite, from 0, increasing, bounded)."""
    key = f"{table}.time"
    t, v = _numbers(time, file, key), _numbers(value, file, f"{table}.{column}")
    _require(t.ndim == 1 and t.size >= 2, "at least two rows", file, key)
    _require(v.shape == t.shape, f"{v.size} values for {t.size} times", file, key)
    _require(np.all(np.isfinite(t)), "not a finite number", file, key)
    _require(np.all(np.isfinite(v)), "not a finite number", file, f"{table}.{column}")
    _require(t[0] == 0.0, f"must start at 0 s, starts at {t[0]:g} s", file, key)
    step = np.diff(t)
    i = int(np.argmax(step <= 0)) + 1
    _require(np.all(step > 0), f"times must increase (row {i + 1}: {t[i]:g} s after "
             f"{t[i - 1]:g} s)", file, key)
    _require(t[-1] <= MAX_DURATION, f"a {t[-1]:g} s profile; at most {MAX_DURATION:g} s",
             file, key)
    gaps = (step > MAX_GAP) & (np.diff(v) != 0)
    i = int(np.argmax(gaps))
    _require(not gaps.any(), f"a gap of {step[i]:g} s after {t[i]:g} s over which the "
             f"value changes; rows at most {MAX_GAP:g} s apart there (a hold may be longer)",
             file, key)
    return t, v
