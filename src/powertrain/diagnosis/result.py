"""Step 5 of the diagnosis: the result object and its JSON (``diagnosis.json``, whose keys
are an interface: keep every key)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN
from powertrain.diagnosis.checks import ORDER_FOLDS, ORDER_SPLIT, channel_folds
from powertrain.diagnosis.data import GapData
from powertrain.diagnosis.evidence import VerdictKind
from powertrain.diagnosis.fit import FitOutcome
from powertrain.diagnosis.html import diagnosis_html
from powertrain.diagnosis.report import summary, write_report
from powertrain.diagnosis.rule import DecisionRule
from powertrain.effects import EFFECTS
from powertrain.outputs import atomic_write
from powertrain.plotting import plot_gap_map
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result
from powertrain.results.html import fragment


@dataclass(frozen=True)
class DiagnosisResult(Result):
    """Everything the diagnosis found; ``.to_text()``, ``.to_json()``, ``.plot()``,
    ``.save(path)`` (``.json``, ``.png``), ``.report(dir)``."""

    data: GapData
    source: str
    engine_name: str
    gap: np.ndarray
    gap_after: np.ndarray | None
    parts: dict
    rigid_gap: np.ndarray
    regions: list
    noise_db: float
    split: dict
    baseline: FitOutcome
    outcomes: list
    chosen: FitOutcome | None
    verdict: str
    verdict_text: str
    band_check: list
    seconds: float
    synthetic: bool = False
    notes: list = field(default_factory=list)
    #: E_n: held-out mean squared gap a perfect model would leave [dB²].
    noise_mse_heldout: float = 0.0
    #: Labels that pass the rule but cannot be told apart.
    ambiguous: list = field(default_factory=list)
    #: The answer's pairs not told apart (second effect not identified).
    second_effect_between: list = field(default_factory=list)
    rule: DecisionRule = field(default_factory=DecisionRule)
    verdict_kind: VerdictKind | None = None
    #: Parameter sets that explain the data equally well within the noise.
    equivalents: list = field(default_factory=list)
    #: Labels of fits stopped by their evaluation budget.
    budget_hits: list = field(default_factory=list)
    #: Model levels [m/s RMS] like ``data.level``: baseline and with the answer.
    sim_levels: np.ndarray | None = field(default=None, repr=False, compare=False)
    sim_after: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: The baseline engine diagnosed.
    engine: object = field(default=None, repr=False, compare=False)
    #: What the chosen effect names (``Effect.finding``), or None.
    finding: dict | None = None
    #: Phase used: ``measured``, ``crank_offset_deg``, ``scored_points``.
    phase: dict = field(default_factory=dict)
    #: Per-run entries of a plan diagnosis.
    runs: list = field(default_factory=list)

    def _per_channel(self):
        d, chans = self.data, []
        for c, (m, di) in enumerate(d.channels):
            for k, q in enumerate(d.quantities):
                g = self.gap[:, c, k]
                ok = np.isfinite(g)
                if ok.any():
                    chans.append({"mount": m, "direction": di, "quantity": q,
                                  "rms_db": float(np.sqrt(np.mean(g[ok] ** 2))),
                                  "bias_db": float(np.mean(g[ok])),
                                  "max_abs_db": float(np.max(np.abs(g[ok])))})
        return chans

    def where(self) -> dict:
        """The JSON's ``where`` entry (step 1)."""
        d, p = self.data, self.parts
        rg = self.rigid_gap[np.isfinite(self.rigid_gap)]
        return {
            "gap_definition": "20 log10(sim/measured) dB, + = simulation higher; noise floor "
                              f"added to the model in power; censored below {NOISE_FLOOR_MARGIN:g}x floor",
            "rpm": d.rpm.tolist(), "channels": [list(c) for c in d.channels],
            "quantities": list(d.quantities),
            "gap_db": [[[None if not np.isfinite(x) else round(float(x), 3) for x in row]
                        for row in mat] for mat in self.gap],
            "gap_db_after": None if self.gap_after is None else
            [[[None if not np.isfinite(x) else round(float(x), 3) for x in row]
              for row in mat] for mat in self.gap_after],
            "per_channel": self._per_channel(), "regions_beyond_3db": self.regions,
            "decomposition": {
                "model": "gap = g_channel + dH_channel(f = order*rpm/60) + dF_order(rpm)",
                "share_alone": p["share_alone"], "r2_alone": p["r2_alone"],
                "r2_full": p["r2_full"], "residual_rms_db": p["residual_rms_db"],
                "channel_const_db": p["channel_const_db"], "structure_curves": p["structure_curves"],
                "excitation_curves": p["excitation_curves"], "attribution": p["attribution"]},
            "sides": p.get("sides"),
            "outside_rigid_span_rms_db": {
                "median": float(np.median(rg)) if rg.size else None,
                "p90": float(np.percentile(rg, 90)) if rg.size else None},
            "noise_sigma_db": self.noise_db,
        }

    def _outcome_dict(self, o: FitOutcome) -> dict:
        return {"effect": o.label, "effects": list(o.effects), "parameters": o.params,
                "summary": "; ".join(t for t in (EFFECTS[e].summary(o.params[e]) for e in o.effects) if t),
                "parameter_sigma": o.sigma, "parameter_interval_95": o.interval, "n_parameters": o.n_params,
                "heldout_rms_db_before": self.baseline.heldout_rms_db,
                "heldout_rms_db_after": o.heldout_rms_db,
                "heldout_channel_rms_db_before": self.baseline.heldout_channel_rms,
                "heldout_channel_rms_db_after": o.heldout_channel_rms,
                "train_bic_gain": o.bic_gain, "heldout_t": o.t_stat, "crossfit_t": o.t_crossfit,
                "explained_fraction_of_excess": o.explained, "verdict": o.status,
                "status": None if o.status_code is None else o.status_code.name.lower(),
                "heldout_structured_residual_db": o.struct_db, "heldout_block_chi2_ratio": o.chi2_ratio,
                "heldout_cells_check": None if o.cells_check is None else {
                    k: v for k, v in o.cells_check.items() if k != "parts"},
                "nfev": o.nfev, "n_eval": o.n_eval, "budget_hit": o.budget_hit, "seconds": o.seconds,
                "alternatives": o.alternatives}

    def _decision_rule_dict(self):
        return {**self.rule.to_dict(), "CHANNEL_FOLDS": channel_folds(len(self.data.channels) // 3),
                "ORDER_SPLIT": ORDER_SPLIT, "ORDER_FOLDS": ORDER_FOLDS}

    def to_dict(self) -> dict:
        b = self.baseline
        excess = math.sqrt(max(b.heldout_mse - self.noise_mse_heldout, 0.0))
        return {
            "source": self.source, "synthetic": self.synthetic, "engine": self.engine_name,
            "where": self.where(), "ranking": [self._outcome_dict(o) for o in self.outcomes],
            "verdict": self.verdict, "verdict_text": self.verdict_text,
            "verdict_kind": None if self.verdict_kind is None else self.verdict_kind.value,
            "chosen": None if self.chosen is None else self._outcome_dict(self.chosen),
            "heldout_rms_db_before": b.heldout_rms_db,
            "heldout_rms_db_after": (self.chosen or b).heldout_rms_db, "heldout_excess_rms_db_before": excess,
            "heldout_noise_mse_db2": self.noise_mse_heldout, "ambiguous_between": self.ambiguous,
            "second_effect_between": self.second_effect_between, "equivalent_explanations": self.equivalents,
            "budget_hits": self.budget_hits, "split": self.split, "confounding_check": self.band_check,
            "decision_rule": self._decision_rule_dict(), "baseline_heldout_structured_db": b.struct_db,
            "effects_library": [e.to_dict() for e in EFFECTS.values()],
            "seconds": self.seconds, "notes": self.notes,
            "finding": self.finding, "phase": self.phase, "runs": self.runs,
        }

    def writers(self) -> dict:
        """``.json`` (:meth:`to_json`), ``.png`` (the gap map)."""
        return {".json": self.to_json, **super().writers()}

    def to_json(self, path=None) -> str:
        """``diagnosis.json``: :meth:`to_dict`, non-finite numbers as null; written
        atomically to ``path`` if given."""
        text = json.dumps(_finite_or_null(self.to_dict()), indent=1, allow_nan=False, default=_jsonable)
        if path is not None:
            with atomic_write(path) as fh:
                fh.write(text)
        return text

    def to_text(self) -> str:
        """Plain-text report (``summary.txt``, what ``powertrain diagnose`` prints)."""
        return summary(self)

    def _repr_html_(self) -> str:
        """HTML of the verdict, where, which and how far."""
        return fragment(diagnosis_html(self))

    def plot(self, ax=None, *, path=None, quantity=None, provenance=None):
        """Gap map figure, one panel per quantity (:func:`powertrain.plotting.plot_gap_map`).

        Parameters
        ----------
        ax : Figure, SubFigure or Axes, optional
            Where to draw (one Axes only for one ``quantity``); None: a new figure.
        path : str or path, optional
            File to save it to.
        quantity : str, optional
            The one quantity shown.
        provenance : dict, optional
            Stamp of the figure.
        """
        ax, path = target_and_path(ax, path)
        return plot_gap_map(self, path, ax=ax, quantity=quantity, provenance=provenance)

    def report(self, directory, provenance=None) -> list:
        """Write ``summary.txt``, ``diagnosis.json`` and the figures into ``directory``."""
        return write_report(self, directory, provenance=provenance)


def _finite_or_null(x):
    """``x`` with every non-finite float replaced by ``None`` (JSON null)."""
    if isinstance(x, dict):
        return {k: _finite_or_null(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite_or_null(v) for v in x]
    if isinstance(x, np.ndarray):
        return _finite_or_null(x.tolist())
    if isinstance(x, (float, np.floating)) and not math.isfinite(float(x)):
        return None
    return x


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(type(x))
