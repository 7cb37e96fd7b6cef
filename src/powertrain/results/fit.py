"""Outcome of a mount parameter identification (:func:`powertrain.workflows.fitting.fit_mount`):
the fitted model, its error and the effort."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.models.mount import MountModel
from powertrain.plotting import plot_mount_fit
from powertrain.plotting.stiffness import fit_frequencies
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result
from powertrain.units import from_si

#: Datasheet unit of a mount parameter, by its first letter (spring, damper, mass).
PARAMETER_UNITS = {"c": "N/mm", "d": "N*s/mm", "m": "kg"}


@dataclass(frozen=True)
class FitResult(Result):
    """Outcome of :func:`fit_mount`.

    Attributes
    ----------
    model : MountModel
        Fitted model (SI parameters).
    frequency_hz : ndarray
        Frequencies of the fitted data [Hz].
    kcp_measured : ndarray of complex
        Measured cross-point stiffness [N/m].
    objective_n : float
        Thesis objective :math:`f_{obj}` (eq. 19) of the fitted model [N].
    rel_rms : float
        Relative RMS error :math:`\\varepsilon` of the fitted model [1].
    n_starts, n_polished : int
        Starting points screened, and those run to convergence.
    success : bool
        The best polishing run converged (did not hit the evaluation limit).
    polish_success, polish_rel_rms : tuple
        Convergence flag and :math:`\\varepsilon` of each polishing run (spread =
        multi-modality).
    n_hops, hops_accepted : int
        Perturbations of the incumbent tried, and those that improved the fit.
    time_s : float
        Wall-clock time [s].
    nfev : int
        Model evaluations (K_CP and Jacobian together).
    seed : int or None
        Seed of the starting points.
    data_name : str
        The data's file ("" for arrays).
    synthetic : bool
        The data are marked synthetic (so is the figure).
    """

    model: MountModel
    frequency_hz: np.ndarray
    kcp_measured: np.ndarray
    objective_n: float
    rel_rms: float
    n_starts: int
    n_polished: int
    success: bool
    polish_success: tuple
    polish_rel_rms: tuple
    n_hops: int
    hops_accepted: int
    time_s: float
    nfev: int
    seed: object = None
    data_name: str = ""
    synthetic: bool = False

    @property
    def kcp_fitted(self) -> np.ndarray:
        """Cross-point stiffness of the fitted model at the data frequencies [N/m]."""
        return self.model.cross_point_stiffness(self.frequency_hz)

    def summary(self) -> str:
        """A few lines: objective, error, effort."""
        return (f"model {self.model.topology.name}: f_obj = {self.objective_n:.4g} N "
                f"(eq. 19, |k_t - k_m| in N/mm x 1 mm over {self.frequency_hz.size} "
                f"frequencies), relative RMS error = {100 * self.rel_rms:.3g} %\n"
                f"{self.n_starts} starts screened, {self.n_polished} polished, "
                f"{self.hops_accepted} of {self.n_hops} hops accepted, "
                f"{'converged' if self.success else 'evaluation limit reached'}, "
                f"{self.nfev} evaluations, {self.time_s:.2f} s")

    def to_text(self) -> str:
        """What ``powertrain fit-mount`` prints: summary and parameters in datasheet units."""
        return "\n".join([self.summary(), "parameters:", *parameter_lines(self.model)])

    def file_comment(self) -> str:
        """The comment of the fitted mount file: data, error, starts and seed."""
        f = self.frequency_hz
        return (f"Fitted by powertrain fit-mount (Kovarik 2016 sec. 2.2, eq. 19) to "
                f"{self.data_name or 'the data'}: {f.size} frequencies, "
                f"{f[0]:g}-{f[-1]:g} Hz.\n"
                f"f_obj = {self.objective_n:.6g} N, relative RMS error = "
                f"{100 * self.rel_rms:.4g} %, starts = {self.n_starts}, seed = {self.seed}.")

    def plot(self, ax=None, path=None, *, form="magnitude-phase", freq_axis="log",
             provenance=None):
        """Measured and fitted K*(f) [N/mm]: |K*| and loss angle (datasheets, ISO 10846) or
        real and imaginary part (``form="real-imag"``, the thesis) over ``log`` or ``linear``
        frequency; returns the figure (:func:`powertrain.plotting.plot_mount_fit`)."""
        ax, path = target_and_path(ax, path)
        f = fit_frequencies(self.frequency_hz, freq_axis)
        return plot_mount_fit(self.frequency_hz, self.kcp_measured,
                              (f, self.model.cross_point_stiffness(f)),
                              label=f"{self.model.topology.name} fit",
                              title=(f"{self.model.name}: " if self.model.name else "")
                              + f"f_obj = {self.objective_n:.4g}\u00a0N, "
                                    f"rel. RMS error = {100 * self.rel_rms:.3g} %",
                              ax=ax, path=path, form=form, freq_axis=freq_axis,
                              provenance=provenance, synthetic=self.synthetic)


def parameter_lines(model) -> list:
    """``  c1 = 12.5 N/mm`` lines: the ``model``'s parameters in datasheet units."""
    lines = []
    for p in model.topology.parameters:
        unit = PARAMETER_UNITS[p[0]]
        lines.append(f"  {p:>3s} = {from_si(model.params[p], unit):.6g} {unit}")
    return lines
