"""Several run-ups of one car in one diagnosis (a test plan, :mod:`powertrain.iotools.plan`).

Every run keeps its own data, split, noise estimate, cached model (the engine at that run's
load or pressure traces) and crank-angle offset. :class:`JointProblem` stacks the runs'
residuals (speed axis: run 1's speeds, then run 2's, ...) so that **one set of effect
parameters** is fitted to all runs. Step 1 and the figures describe the first run.
"""

from __future__ import annotations

import numpy as np

from powertrain.diagnosis.data import GapData, noise_sigma_db
from powertrain.diagnosis.fit import baseline_outcome, score
from powertrain.errors import InputError


def stacked(datas) -> GapData:
    """The runs' :class:`GapData` ``datas`` one after the other along the speed axis."""
    d0 = datas[0]
    phase = None
    if any(d.phase is not None for d in datas):
        phase = np.concatenate([d.phase if d.phase is not None else np.full(d.level.shape, np.nan)
                                for d in datas])
    return GapData(np.concatenate([d.rpm for d in datas]), d0.channels, d0.quantities,
                   d0.harmonic, np.concatenate([d.level for d in datas]), d0.floor, d0.n_engine_side, phase)


def _offsets(sizes):
    return np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(int)


class JointProblem:
    """The ``runs``' :class:`~powertrain.diagnosis.fit.Problem` fitted as one on the stacked
    ``data``: residuals concatenated, gaps stacked along the speed axis."""

    def __init__(self, runs, data: GapData):
        self.runs = list(runs)
        self.data = data
        self.sub = data.orders_only()
        self.engine = self.runs[0].engine
        off = _offsets([p.data.rpm.size for p in self.runs])
        self.idx = {k: np.concatenate([p.idx[k] + o for p, o in zip(self.runs, off)])
                    for k in ("train", "test")}
        self.meas = {k: np.concatenate([p.meas[k] for p in self.runs]) for k in self.idx}
        self.valid = {k: np.concatenate([p.valid[k] for p in self.runs]) for k in self.idx}
        sig = noise_sigma_db(data)
        self.sigma_db = sig if np.isfinite(sig) and sig > 0 else 1.0
        self.phase_w = None
        if any(p.phase_w is not None for p in self.runs):
            self.phase_w = {k: np.concatenate([self._phase_w(p, k) for p in self.runs]) for k in self.idx}
            self.phase_on = {k: np.isfinite(w) for k, w in self.phase_w.items()}

    @staticmethod
    def _phase_w(p, part):
        return p.phase_w[part] if p.phase_w is not None else np.full(p.meas[part].shape, np.nan)

    def reset_warm(self):
        for p in self.runs:
            p.reset_warm()

    def restricted(self, train_cells=None, test_cells=None) -> JointProblem:
        return JointProblem([p.restricted(train_cells, test_cells) for p in self.runs], self.data)

    def gaps(self, scenario, part="train"):
        return np.concatenate([p.gaps(scenario, part) for p in self.runs])

    def complex_excess(self, scenario):
        """The runs' :meth:`Problem.complex_excess` stacked (None when no run has phase)."""
        parts = [p.complex_excess(scenario) for p in self.runs]
        if all(e is None for e in parts):
            return None
        return np.concatenate([np.full(p.meas["train"].shape, np.nan) if e is None else e
                               for p, e in zip(self.runs, parts)])

    def phase_gaps(self, scenario, part="train"):
        if self.phase_w is None:
            return None
        return np.concatenate([p.phase_gaps(scenario, part) if p.phase_w is not None
                               else np.full(p.meas[part].shape, np.nan) for p in self.runs])

    def vector(self, scenario, part="train"):
        return np.concatenate([p.vector(scenario, part) for p in self.runs])

    def clusters(self) -> np.ndarray:
        """The runs' :meth:`Problem.clusters` joined; each run's offset prior its own cluster."""
        return np.concatenate([np.where(c < 0, c - k, c)
                               for k, c in enumerate(p.clusters() for p in self.runs)])

    def read_vectors(self, scenarios) -> list | None:
        """The runs' :meth:`Problem.read_vectors` joined (None if one is None)."""
        parts = [p.read_vectors(scenarios) for p in self.runs]
        if any(v is None for v in parts):
            return None
        return [np.concatenate(vs) for vs in zip(*parts)]

    def crank_offsets(self, scenario) -> list:
        """Each run's crank-angle offset [rad] (None where the run has no phase)."""
        return [p.crank_offsets(scenario)[0] for p in self.runs]


class PlanSetup:
    """The setup of a plan diagnosis: one ``setup_class`` per run of ``plan`` (``runs``),
    joined; ``first`` is run 1's."""

    def __init__(self, plan, engine, noise_floor, effects, setup_class):
        self.plan, self.runs = plan, []
        for i, run in enumerate(plan.runs, start=1):
            s = setup_class(run.measured, run.engine(engine), noise_floor, effects)
            if i > 1 and (s.data.channels != self.runs[0].data.channels
                          or s.data.quantities != self.runs[0].data.quantities):
                raise InputError("every run of a plan must measure the same channels and "
                                 "quantities as run 1", file=plan.source or None,
                                 key=f"runs[{i}].file")
            self.runs.append(s)
        self.first = self.runs[0]
        self.src = plan.source
        self.effects = self.first.effects
        self.data = stacked([s.data for s in self.runs])
        self.problem = JointProblem([s.problem for s in self.runs], self.data)
        self.test_idx = self.problem.idx["test"]
        self._folds = None

    def fold_problems(self) -> list:
        """``[(JointProblem, baseline outcome)]`` of speed folds 1, 2 of every run."""
        if self._folds is None:
            per_run = [s.fold_problems() for s in self.runs]
            self._folds = []
            for k in range(len(per_run[0])):
                p = JointProblem([f[k][0] for f in per_run], self.data)
                self._folds.append((p, baseline_outcome(p)))
        return self._folds

    def run_entries(self, chosen) -> list:
        """The JSON's ``runs``: each run's file, load, held-out RMS gap before and after
        ``chosen`` [dB] and crank-angle offset [deg]."""
        sc = {} if chosen is None else {e: chosen.params[e] for e in chosen.effects}
        out = []
        for run, s in zip(self.plan.runs, self.runs):
            before = baseline_outcome(s.problem).heldout_rms_db
            after = before if chosen is None else score(
                s.problem, chosen.effects, sc, {}, {}, 0.0, 1, 0, 0, 0.0).heldout_rms_db
            off = s.problem.crank_offsets(sc)[0]
            out.append({**run.to_dict(), "speeds": int(s.data.rpm.size),
                        "heldout_rms_db_before": before, "heldout_rms_db_after": after,
                        "crank_offset_deg": None if off is None else float(np.degrees(off)),
                        "split": s.split_dict()})
        return out
