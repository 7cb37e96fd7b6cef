"""A candidate's parameters as one fitted vector: bounds, log scale, start, priors, and back."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from powertrain.effects import EFFECTS


@dataclass
class Packing:
    """Parameters of a candidate as one vector (log space for scale-like parameters)."""

    names: list
    lower: np.ndarray
    upper: np.ndarray
    log: np.ndarray
    x0: np.ndarray
    units: dict = None
    prior_sd: np.ndarray = None

    @property
    def n_prior(self) -> int:
        return 0 if self.prior_sd is None else int(np.isfinite(self.prior_sd).sum())

    @classmethod
    def of(cls, effects, engine=None):
        """The packing of ``effects``' parameters (for ``engine``)."""
        names, lo, hi, logs, x0, units, prior = [], [], [], [], [], {}, []
        for e in effects:
            for p in EFFECTS[e].parameters(engine):
                prior.append(np.nan if p.prior_sd is None else p.prior_sd)
                units[(e, p.name)] = p.unit
                names.append((e, p.name))
                lo.append(math.log(p.lower) if p.log else p.lower)
                hi.append(math.log(p.upper) if p.log else p.upper)
                logs.append(p.log)
                x0.append(math.log(p.default) if p.log else p.default)
        return cls(names, np.array(lo), np.array(hi), np.array(logs, bool), np.array(x0), units,
                   np.array(prior, float))

    def scenario(self, x):
        """``{effect: {parameter: value}}`` (SI) at vector ``x``."""
        sc = {}
        for (e, p), lg, v in zip(self.names, self.log.tolist(), np.asarray(x, float).tolist()):
            sc.setdefault(e, {})[p] = math.exp(v) if lg else v
        return sc

    def values(self, x, sd):
        """``params``, ``sigma`` dicts (SI) from vector ``x`` and its 1σ ``sd``."""
        params, sigma = {}, {}
        for (e, pn), lg, v, s in zip(self.names, self.log, x, sd):
            val = math.exp(v) if lg else v
            params.setdefault(e, {})[pn] = float(val)
            sigma.setdefault(e, {})[pn] = float(val * s if lg else s)
        return params, sigma
