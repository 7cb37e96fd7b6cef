"""Outcome of a multi-amplitude mount fit: the fitted mount with its amplitude law and
friction, and the residual per amplitude."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.plotting.stiffness import fit_frequencies, plot_amplitude_fit
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result
from powertrain.results.fit import FitResult, parameter_lines


@dataclass(frozen=True)
class AmplitudeFitResult(Result):
    """Outcome of :func:`~powertrain.workflows.amplitude_fit.fit_amplitudes`.

    Attributes
    ----------
    model : MountModel
        Fitted network (SI) with its ``amplitude_law`` (PowerLaw) and, with friction, its
        ``port_law`` (BergFriction).
    reference_m : float
        Reference amplitude of the law and of the network [m].
    amplitude_m : ndarray
        The data's amplitudes [m], increasing.
    curves : list of MeasuredStiffness
        The data at each amplitude.
    rel_rms : tuple of float
        Relative RMS error at each amplitude [1].
    network_fit : FitResult
        Stage 1: the network alone at the reference amplitude.
    friction : bool
        Berg's friction element was fitted.
    success : bool
        The best joint least-squares run converged (did not hit the evaluation limit).
    n_joint_starts, nfev : int
        Joint runs and their residual evaluations.
    time_s : float
        Wall-clock time of both stages [s].
    seed : int or None
    data_name : str
    """

    model: object
    reference_m: float
    amplitude_m: np.ndarray
    curves: list
    rel_rms: tuple
    network_fit: FitResult
    friction: bool
    success: bool
    n_joint_starts: int
    nfev: int
    time_s: float
    seed: object = None
    data_name: str = ""

    def kcp_fitted(self, index: int, frequency_hz=None) -> np.ndarray:
        """K*(f) [N/m] at amplitude ``index``, at its data frequencies or ``frequency_hz``."""
        f = self.curves[index].frequency_hz if frequency_hz is None else frequency_hz
        return self.model.element().cross_point_stiffness(f, self.amplitude_m[index])

    @property
    def synthetic(self) -> bool:
        """The data are marked synthetic (so is the figure)."""
        return any(getattr(c, "synthetic", False) for c in self.curves)

    def summary(self) -> str:
        """What was fitted and the residual per amplitude."""
        law = self.model.amplitude_law
        parts = [f"network {self.model.topology.name} at {self.reference_m * 1e3:g} mm",
                 f"power law (exponent fitted, limits fixed [{law.limits[0]:g}, "
                 f"{law.limits[1]:g}])"] + (["Berg friction"] if self.friction else [])
        lines = [" + ".join(parts) + f", fitted to {self.amplitude_m.size} amplitudes "
                 f"({'converged' if self.success else 'evaluation limit reached'}, "
                 f"{self.n_joint_starts} joint starts, {self.nfev} evaluations, "
                 f"{self.time_s:.2f} s)",
                 "relative RMS error per amplitude:"]
        for a, e, c in zip(self.amplitude_m, self.rel_rms, self.curves):
            lines.append(f"  {a * 1e3:8.4g} mm: {100 * e:.3g} % ({c.frequency_hz.size} "
                         "frequencies)")
        return "\n".join(lines)

    def to_text(self) -> str:
        """What ``powertrain fit-mount`` prints: summary and values in datasheet units."""
        m = self.model
        lines = [self.summary(), "parameters:", *parameter_lines(m)]
        law = m.amplitude_law
        lines += ["amplitude law:", f"  reference = {law.reference * 1e3:.6g} mm",
                  f"  exponent = {law.exponent:.6g}"]
        if m.port_law is not None:
            lines += ["friction:", f"  max_force = {m.port_law.max_force:.6g} N",
                      f"  half_displacement = {m.port_law.half_displacement * 1e3:.6g} mm"]
        return "\n".join(lines)

    def file_comment(self) -> str:
        """The comment of the fitted mount file: data and residual per amplitude."""
        errs = ", ".join(f"{a * 1e3:g} mm {100 * e:.3g} %"
                         for a, e in zip(self.amplitude_m, self.rel_rms))
        return (f"Fitted by powertrain fit-mount to {self.data_name or 'the data'} at "
                f"{self.amplitude_m.size} amplitudes (network at {self.reference_m * 1e3:g} "
                f"mm, power law{', Berg friction' if self.friction else ''}).\n"
                f"Relative RMS error per amplitude: {errs}; seed = {self.seed}.")

    def plot(self, ax=None, path=None, *, form="magnitude-phase", freq_axis="log",
             provenance=None):
        """Measured (dots) and fitted (lines) K*(f), one colour per amplitude."""
        ax, path = target_and_path(ax, path)
        curves = []
        for i, (a, c) in enumerate(zip(self.amplitude_m, self.curves)):
            f = fit_frequencies(c.frequency_hz, freq_axis)
            curves.append((f"{a * 1e3:g} mm", c.frequency_hz, c.kcp,
                           (f, self.kcp_fitted(i, f))))
        worst = 100 * max(self.rel_rms)
        return plot_amplitude_fit(curves, path, ax=ax, form=form, freq_axis=freq_axis,
                                  title=f"{self.model.name}: worst rel. RMS error {worst:.3g} "
                                        "%", provenance=provenance,
                                  synthetic=self.synthetic)
