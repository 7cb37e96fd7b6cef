"""Tables of dynamic stiffness in datasheet units, from either solution method."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class StiffnessTable:
    """K*(f) of a mount model, plus x1 and F_T for the verification set-up.

    Attributes are SI; :meth:`columns` gives the datasheet-unit columns written out.
    """

    frequency_hz: np.ndarray
    kcp: np.ndarray                      #: cross-point stiffness [N/m]
    method: str
    x1: np.ndarray | None = None         #: engine-mass displacement [m]
    ft: np.ndarray | None = None         #: transmitted force [N]
    meta: dict = field(default_factory=dict)

    def columns(self) -> dict[str, np.ndarray]:
        k = self.kcp / 1e3
        cols = {
            "frequency_hz": self.frequency_hz,
            "k_real_n_per_mm": k.real,
            "k_imag_n_per_mm": k.imag,
            "k_abs_n_per_mm": np.abs(k),
            "loss_angle_deg": np.degrees(np.angle(k)),
        }
        if self.x1 is not None:
            cols["x1_real_mm"] = (self.x1 * 1e3).real
            cols["x1_imag_mm"] = (self.x1 * 1e3).imag
            cols["ft_real_n"] = self.ft.real
            cols["ft_imag_n"] = self.ft.imag
        return cols

    def to_csv(self) -> str:
        cols = self.columns()
        lines = [",".join(cols)]
        for i in range(self.frequency_hz.size):
            lines.append(",".join(f"{cols[c][i]:.10g}" for c in cols))
        return "\n".join(lines) + "\n"

    def to_text(self) -> str:
        from powertrain.analysis.text_table import format_table
        cols = self.columns()
        header = list(cols)
        rows = [[float(cols[c][i]) for c in cols] for i in range(self.frequency_hz.size)]
        return f"# method: {self.method}\n" + format_table(header, rows) + "\n"

    def plot(self, ax=None, *, path=None, label=None, form="magnitude-phase", freq_axis="log",
             measured=None, provenance=None):
        """K*(f) as |K*| and loss angle (datasheets, ISO 10846; default) or real and imaginary
        part (``form="real-imag"``, the thesis), over ``log`` or ``linear`` frequency;
        returns the figure (see :func:`powertrain.plotting.plot_stiffness`)."""
        from powertrain.plotting import plot_stiffness
        return plot_stiffness([(label or self.meta.get("name", "model"), self)], path,
                              measured=measured, ax=ax, form=form, freq_axis=freq_axis,
                              provenance=provenance or getattr(self, "provenance", None))


def stiffness_table(model, frequency_hz, method="frequency", engine_mass=None, force=None,
                    steps_per_period=None) -> StiffnessTable:
    """Compute K*(f) (and x1, F_T when ``engine_mass`` and ``force`` are given).

    Parameters
    ----------
    model : MountModel
    frequency_hz : ndarray
        [Hz]
    method : {"frequency", "time"}
        Condensed network (eq. 39) or Newmark integration processed by FFT.
    engine_mass : float, optional
        [kg]
    force : float, optional
        [N]
    steps_per_period : int, optional
        Newmark steps per excitation period for the time method (default
        :data:`powertrain.solvers.mount_time_domain.STEPS_PER_PERIOD`).
    """
    f = np.asarray(frequency_hz, float)
    kw = {} if steps_per_period is None else {"steps_per_period": steps_per_period}
    if method == "frequency":
        if engine_mass is None:
            return StiffnessTable(f, model.cross_point_stiffness(f), method)
        x1, ft = model.forced_engine_mass_response(f, engine_mass, force)
        return StiffnessTable(f, model.cross_point_stiffness(f), method, x1, ft)
    if method == "time":
        from powertrain.solvers.mount_time_domain import (
            time_cross_point_stiffness,
            time_forced_response,
        )
        if engine_mass is None:
            r = time_cross_point_stiffness(model, f, **kw)
            return StiffnessTable(f, r.kcp, method, meta={"periodicity": r.periodicity})
        r = time_forced_response(model, f, engine_mass, force, **kw)
        return StiffnessTable(f, r.kcp, method, r.x1, r.ft, meta={"periodicity": r.periodicity})
    raise ValueError(f"unknown method {method!r}")
