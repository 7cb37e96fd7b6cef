"""Dynamic stiffness K*(f) of a mount model in datasheet units, from either solution method."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.text_table import format_table
from powertrain.outputs import write_csv
from powertrain.plotting import plot_stiffness
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result


class _Columns(Result):
    """A result of datasheet-unit columns (``columns()``) computed by ``method``."""

    def to_csv(self, path=None) -> str:
        """The CSV text (datasheet units, 10 significant digits), written atomically to
        ``path`` if given."""
        cols = self.columns()
        rows = zip(*cols.values())
        text = "\n".join([",".join(cols)] + [",".join(f"{v:.10g}" for v in r) for r in rows])
        if path is not None:
            write_csv(path, text + "\n")
        return text + "\n"

    def writers(self) -> dict:
        """``.csv``, ``.png``."""
        return {".csv": self.to_csv, **super().writers()}

    def to_text(self) -> str:
        """The table of every row (``powertrain stiffness``)."""
        cols = self.columns()
        rows = [[float(v) for v in r] for r in zip(*cols.values())]
        return f"# method: {self.method}\n" + format_table(list(cols), rows) + "\n"


@dataclass(frozen=True)
class StiffnessResult(_Columns):
    """K*(f) of a mount model, plus x1 and F_T for the verification set-up (SI;
    :meth:`columns` in datasheet units)."""

    frequency_hz: np.ndarray
    kcp: np.ndarray                      #: cross-point stiffness [N/m]
    method: str
    x1: np.ndarray | None = None         #: engine-mass displacement [m]
    ft: np.ndarray | None = None         #: transmitted force [N]
    #: Cycle-to-cycle periodicity per frequency of the time method [1] (None otherwise).
    periodicity: np.ndarray | None = None
    #: Legend label of the plot (the model's name, else where it came from).
    label: str = ""

    def columns(self) -> dict[str, np.ndarray]:
        k = self.kcp / 1e3
        cols = {"frequency_hz": self.frequency_hz, "k_real_n_per_mm": k.real,
                "k_imag_n_per_mm": k.imag, "k_abs_n_per_mm": np.abs(k),
                "loss_angle_deg": np.degrees(np.angle(k))}
        if self.x1 is not None:
            cols["x1_real_mm"] = (self.x1 * 1e3).real
            cols["x1_imag_mm"] = (self.x1 * 1e3).imag
            cols["ft_real_n"] = self.ft.real
            cols["ft_imag_n"] = self.ft.imag
        return cols

    def summary(self) -> str:
        """|K*| range [N/mm] and loss-angle peak [deg] (``stiffness --plot`` without
        ``--format``)."""
        f = self.frequency_hz
        return (f"# method: {self.method}; {f.size} frequencies {f[0]:g}..{f[-1]:g} Hz "
                "(every value: --format table or csv)\n" + _ranges(self.columns()))

    def plot(self, ax=None, *, path=None, label=None, form="magnitude-phase", freq_axis="log",
             measured=None, provenance=None):
        """K*(f) as |K*| and loss angle (datasheets, ISO 10846; default) or real and
        imaginary part (``form="real-imag"``, the thesis) over ``log`` or ``linear``
        frequency; returns the figure (:func:`powertrain.plotting.plot_stiffness`). ``ax``:
        None, a Figure or SubFigure, a pair of Axes (magnitude-phase) or one (real-imag)."""
        ax, path = target_and_path(ax, path)
        name = label or self.label or "model"
        return plot_stiffness([(name, self)], path, measured=measured, ax=ax, form=form,
                              freq_axis=freq_axis, provenance=provenance)


def _ranges(cols) -> str:
    """|K*| at the first frequency, its min and max, and the loss-angle peak (two lines)."""
    f, k, phi = cols["frequency_hz"], cols["k_abs_n_per_mm"], cols["loss_angle_deg"]
    lo, hi, top = int(np.argmin(k)), int(np.argmax(k)), int(np.argmax(phi))
    return (f"|K*| {k[0]:.4g} N/mm at {f[0]:g} Hz; min {k[lo]:.4g} N/mm at {f[lo]:g} Hz, "
            f"max {k[hi]:.4g} N/mm at {f[hi]:g} Hz\n"
            f"loss angle max {phi[top]:.3g} deg at {f[top]:g} Hz")


@dataclass(frozen=True)
class AmplitudeStiffnessResult(_Columns):
    """K*(f, X) of the sinusoidal displacement test at several amplitudes X (``powertrain
    stiffness --amplitude``), one :class:`StiffnessResult` per amplitude; :meth:`columns`
    prepends ``amplitude_mm``, one block per amplitude (a valid ``fit-mount`` input)."""

    amplitude_m: np.ndarray               #: test amplitudes X [m]
    curves: list                          #: StiffnessResult per amplitude
    method: str
    label: str = ""

    def columns(self) -> dict[str, np.ndarray]:
        per = [c.columns() for c in self.curves]
        cols = {"amplitude_mm": np.concatenate(
            [np.full(c.frequency_hz.size, a * 1e3) for a, c in zip(self.amplitude_m,
                                                                   self.curves)])}
        for name in per[0]:
            cols[name] = np.concatenate([p[name] for p in per])
        return cols

    def summary(self) -> str:
        """:meth:`StiffnessResult.summary` per amplitude."""
        f = self.curves[0].frequency_hz
        lines = [f"# method: {self.method}; {self.amplitude_m.size} amplitudes x "
                 f"{f.size} frequencies {f[0]:g}..{f[-1]:g} Hz "
                 "(every value: --format table or csv)"]
        for a, c in zip(self.amplitude_m, self.curves):
            lines.append(f"X = {a * 1e3:g} mm: " + _ranges(c.columns()).replace("\n", "; "))
        return "\n".join(lines)

    def plot(self, ax=None, *, path=None, form="magnitude-phase", freq_axis="log",
             provenance=None):
        """One K*(f) curve per amplitude (as :meth:`StiffnessResult.plot`)."""
        ax, path = target_and_path(ax, path)
        curves = [(f"X = {a * 1e3:g} mm", c) for a, c in zip(self.amplitude_m, self.curves)]
        return plot_stiffness(curves, path, ax=ax, form=form, freq_axis=freq_axis,
                              title=f"{self.label} ({self.method} method)" if self.label
                              else None, provenance=provenance)
