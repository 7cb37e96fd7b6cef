r"""Diagnosis of the sim-to-real gap: where it lies, which unmodelled effect causes it, how far
it shrinks.

A measured run-up (order curves per mount channel) is compared with the baseline engine
model as the gap :math:`\Delta L = 20\log_{10}(s/m)` [dB] (+ = simulation higher). The steps,
in order: :mod:`.data` (speed grid, censoring, noise, split), :mod:`.where` (gap map,
regions, decomposition), :mod:`.candidates`, :mod:`.fit`, :mod:`.checks`, :mod:`.rule`
(:func:`decide` → :class:`Verdict`), :mod:`.result`, :mod:`.report`; :func:`diagnose`
(:mod:`.core`) drives them.
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
