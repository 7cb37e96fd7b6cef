"""The evidence the decision rule (:mod:`powertrain.diagnosis.rule`) reads and its verdict."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np


class Status(Enum):
    """Status of a candidate after the decision."""

    SUPPORTED = "supported"
    NOT_SUPPORTED = "not supported"
    NOT_BETTER_THAN_MEMBER = "not better than its better member"
    STRUCTURED_RESIDUAL = "residual structured"
    FAILS_HELDOUT_CELLS = "fails held-out cells"
    INDISTINGUISHABLE = "indistinguishable"
    RESTATES = "restates another candidate"
    PARTIAL = "partial"
    CHOSEN = "chosen"


class VerdictKind(Enum):
    """Kind of answer."""

    EFFECT = "effect"
    NO_EFFECT = "no effect"
    UNEXPLAINED = "unexplained"
    AMBIGUOUS = "ambiguous"
    PENDING = "pending"          # a check is needed first


@dataclass
class CandidateEvidence:
    """What the fits measured for one candidate (or the baseline, no effects)."""

    label: str
    effects: tuple
    heldout_mse: float
    heldout_per_rpm: np.ndarray
    bic: float
    struct_db: float = float("nan")
    cells: dict | None = None
    #: mean squared gap per speed over all speed folds; None until cross-fitted
    crossfit: np.ndarray | None = None
    #: ((effects, reason), ...) this fit restates
    restates: tuple = ()


@dataclass
class Evidence:
    """All the decision needs: baseline, candidates, noise, the 'where' phrase."""

    baseline: CandidateEvidence
    candidates: list
    noise_mse: float
    sigma_db: float
    where_text: str = ""


@dataclass
class Assessment:
    """A candidate's numbers and status after the decision."""

    t_stat: float
    bic_gain: float
    explained: float
    status: Status
    text: str
    t_crossfit: float = float("nan")
    crossfit_labels: tuple = ()


@dataclass
class Verdict:
    """The answer: kind, JSON label, text, assessments, chosen and ambiguous labels."""

    kind: VerdictKind
    label: str
    text: str
    assessments: dict = field(default_factory=dict)
    order: list = field(default_factory=list)
    chosen: str | None = None
    ambiguous: list = field(default_factory=list)
    second_effect_between: list = field(default_factory=list)
    needs_cells_check: str | None = None
    needs_crossfit: list = field(default_factory=list)
