"""Rigid-body (and chassis) modes of the powertrain on its mounts (computed by
:mod:`powertrain.solvers.modes`), as text, JSON and kinetic-energy figure."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.plotting.body import plot_modes
from powertrain.plotting.style import target_and_path
from powertrain.results.base import JsonResult
from powertrain.results.html import fragment
from powertrain.results.html_tables import modes_html
from powertrain.solvers.modes import AS_MEASURED, COORDINATES, number_or_null


@dataclass
class Mode:
    """One rigid-body (or chassis) mode.

    Attributes
    ----------
    frequency_hz, damping_ratio, damped_frequency_hz : float
        |s|/2π [Hz], −Re s/|s| [-] (0 for the static method), Im s/2π [Hz].
    shape : ndarray complex (6,)
        ``[x, y, z, rx, ry, rz]`` at the CG [m, rad], largest-energy entry real positive,
        unit modal mass.
    ked_percent : ndarray (6,)
        Kinetic-energy distribution [%].
    angle_to_torque_roll_axis_deg : float
        Angle between the mode's rotation axis and the torque-roll axis [deg].
    kind : str
        ``rigid-body`` or ``chassis``.
    iterations : int
        0: all modes come from one eigensolve.
    body_energy_percent : float
        Share of the kinetic energy in the body modes of a modal chassis [%].
    static_frequency_hz : float
        Frequency of the undamped static-stiffness mode paired to this one by the modal
        assurance criterion (its own for the static method) [Hz].
    static_mac : float
        MAC between this mode's shape and that static mode's [-].
    """

    frequency_hz: float
    damping_ratio: float
    damped_frequency_hz: float
    shape: np.ndarray
    ked_percent: np.ndarray
    angle_to_torque_roll_axis_deg: float
    kind: str = "rigid-body"
    iterations: int = 0
    body_energy_percent: float = 0.0
    static_frequency_hz: float = float("nan")
    static_mac: float = float("nan")

    @property
    def dominant(self) -> str:
        return COORDINATES[int(np.argmax(self.ked_percent))]

    def to_dict(self) -> dict:
        shape = self.shape.real
        return {"frequency_hz": float(self.frequency_hz),
                "damping_ratio": float(self.damping_ratio), "dominant": self.dominant,
                "ked_percent": {c: float(v) for c, v in zip(COORDINATES, self.ked_percent)},
                "damped_frequency_hz": float(self.damped_frequency_hz),
                "angle_to_torque_roll_axis_deg": number_or_null(
                    self.angle_to_torque_roll_axis_deg),
                "shape": {c: float(v) for c, v in zip(COORDINATES, shape)}, "kind": self.kind,
                "body_energy_percent": float(self.body_energy_percent),
                "static_frequency_hz": float(self.static_frequency_hz),
                "static_mac": float(self.static_mac)}


@dataclass(frozen=True)
class ModesResult(JsonResult):
    """Modes sorted by frequency, the torque-roll axis and the method used.

    Attributes
    ----------
    modes : list of Mode
    torque_roll_axis : dict
        ``direction`` (unit vector, engine axes) and ``angle_to_crank_axis_deg``.
    method : str
    engine : str
        The engine's name.
    cg_m : list of float, optional
        Centre of gravity [m, engine axes].
    mounts : list of str, optional
        The engine's mount names.
    """

    modes: list
    torque_roll_axis: dict
    method: str
    engine: str = ""
    cg_m: list | None = None
    mounts: list | None = None

    JSON_INDENT = 2

    @classmethod
    def from_solution(cls, solution: dict, engine: str = "", *, cg_m=None,
                      mounts=None) -> ModesResult:
        """The result of :func:`powertrain.solvers.modes.rigid_body_modes`; the keywords
        are the attributes."""
        return cls(modes=[Mode(**m) for m in solution["modes"]],
                   torque_roll_axis=solution["torque_roll_axis"], method=solution["method"],
                   engine=engine, cg_m=cg_m, mounts=mounts)

    def to_dict(self) -> dict:
        """The JSON document (``cg_m`` and ``mounts`` where known)."""
        extra = {k: v for k, v in (("cg_m", self.cg_m), ("mounts", self.mounts))
                 if v is not None}
        return {"modes": [m.to_dict() for m in self.modes],
                "torque_roll_axis": self.torque_roll_axis, "method": self.method,
                "engine": self.engine, **extra}

    def write_json(self, path) -> None:
        """Write :meth:`to_json` to ``path`` atomically."""
        self.to_json(path)

    def is_static(self) -> bool:
        """True for the undamped static-stiffness modes (``--static``)."""
        return self.method.startswith("static")

    def title(self) -> str:
        """What these modes are, in one line."""
        if self.is_static():
            return (f"{self.engine}: rigid-body modes, undamped, mounts at their static "
                    "(0 Hz) stiffness (the kind 'powertrain runup' prints)")
        return (f"{self.engine}: rigid-body modes, damped, each with the mounts' dynamic "
                "stiffness at its own frequency\n'static f': the undamped static-stiffness "
                "mode (--static; the kind 'powertrain runup' prints) of the most similar "
                "shape, paired one to one; MAC: their shape correlation")

    def to_text(self) -> str:
        """Table of the modes, sorted by frequency, with a note on signed energy shares."""
        static = self.is_static()
        head = (f"{'mode':>4}  {'f [Hz]':>7}  {'zeta':>6}"
                + ("" if static else f"  {'static f':>8}  {'MAC':>4}") + f"  {'dominant':>8}  "
                + "  ".join(f"{c:>6}" for c in COORDINATES) + "  TRA angle")
        lines = [self.title(), head, "-" * len(head)]
        if AS_MEASURED in self.method:
            lines.insert(1, AS_MEASURED)
        for i, m in enumerate(self.modes, 1):
            tag = "" if m.kind == "rigid-body" else f"  ({m.kind})"
            lines.append(f"{i:4d}  {m.frequency_hz:7.3f}  {m.damping_ratio:6.3f}"
                         + ("" if static else f"  {m.static_frequency_hz:8.3f}  "
                                               f"{m.static_mac:4.2f}")
                         + f"  {m.dominant:>8}  "
                         + "  ".join(f"{round(v, 1) or 0.0:6.1f}" for v in m.ked_percent)
                         + f"  {m.angle_to_torque_roll_axis_deg:6.1f} deg{tag}")
        t = self.torque_roll_axis
        d = ", ".join(f"{v:.4f}" for v in t["direction"])
        lines.append(f"torque-roll axis through the CG, direction [{d}] (engine axes), "
                     f"{t['angle_to_crank_axis_deg']:.2f} deg from the crank axis")
        lowest = min(float(np.min(m.ked_percent)) for m in self.modes)
        if round(lowest, 1) < 0:
            lines.append(f"energy shares are signed (lowest {lowest:.1f} %): the products of "
                         "inertia couple rx, ry, rz" + ("" if static else " and damped shapes "
                                                        "are complex")
                         + ", so a coordinate can hold a slightly negative share; each row "
                         "adds up to 100 %")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        return fragment(modes_html(self))

    def plot(self, ax=None, *, path=None, provenance=None):
        """Stacked kinetic-energy distribution per mode in one panel; returns the figure.
        ``ax``: None, an Axes, a Figure or SubFigure."""
        ax, path = target_and_path(ax, path)
        return plot_modes(self, path, ax=ax, provenance=provenance)
