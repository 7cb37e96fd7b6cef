r"""Diagnosis of the sim-to-real gap: where it lies, which unmodelled effect causes it, how far
it shrinks.

Input: a measured run-up (:class:`~powertrain.iotools.measured.MeasuredRunup`, order curves
per mount channel) and the baseline engine model. Levels are compared as the gap
:math:`\Delta L = 20\log_{10}(s/m)` [dB] (+ = simulation higher).

The modules are the steps, in order:

==================== =====================================================================
:mod:`.data`         measured data on the speed grid, noise floor (censoring), noise
                     estimate, the training / held-out speed split
:mod:`.where`        gap map, regions, decomposition into sensor / structure / excitation
                     parts and the attribution (which orders, which band)
:mod:`.candidates`   the registry's effects that apply to the engine; equivalent
                     explanations
:mod:`.fit`          bounded least squares per candidate on training speeds (evaluation
                     budget), held-out scores
:mod:`.checks`       residual structure, held-out (channel, order) cells, noise level,
                     speed-band confounding check
:mod:`.rule`         :class:`DecisionRule` and the pure :func:`decide` → :class:`Verdict`
:mod:`.result`       :class:`DiagnosisResult` and its JSON
:mod:`.report`       summary text and report folder
:mod:`.core`         :func:`diagnose`, the driver
==================== =====================================================================
"""

from powertrain.diagnosis.checks import heldout_cells_check, noise_mse, structured_residual
from powertrain.diagnosis.core import diagnose
from powertrain.diagnosis.data import (
           DEFAULT_NOISE_FLOOR,
           MIN_RPM,
           GapData,
           gap_data,
           model_levels,
           noise_sigma_db,
           residuals_db,
           speed_groups,
           split_rpm,
)
from powertrain.diagnosis.evidence import Status, Verdict, VerdictKind
from powertrain.diagnosis.fit import EVAL_BUDGET, FitOutcome, fit_candidate
from powertrain.diagnosis.result import DiagnosisResult
from powertrain.diagnosis.rule import DecisionRule, decide
from powertrain.diagnosis.where import REGION_DB, decompose_gap

__all__ = ["DEFAULT_NOISE_FLOOR", "EVAL_BUDGET", "MIN_RPM", "REGION_DB", "DecisionRule",
           "DiagnosisResult", "FitOutcome", "GapData", "Status", "Verdict", "VerdictKind",
           "decide", "decompose_gap", "diagnose", "fit_candidate", "gap_data",
           "heldout_cells_check", "model_levels", "noise_mse", "noise_sigma_db",
           "residuals_db", "speed_groups", "split_rpm", "structured_residual"]
