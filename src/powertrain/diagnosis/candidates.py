"""Step 2 of the diagnosis: the registry's effects that apply to the engine
(:data:`powertrain.effects.EFFECTS`), and what the data cannot tell apart among their
parameters."""

from __future__ import annotations

import math

import numpy as np

from powertrain.diagnosis.evidence import CandidateEvidence
from powertrain.diagnosis.fit import Packing, fit_candidate
from powertrain.diagnosis.significance import improvement_t
from powertrain.effects import EFFECTS


def applicable(engine, names=None) -> list:
    """Names of the registry's effects (or of ``names``) that apply to ``engine``."""
    return [e for e in (names or EFFECTS) if EFFECTS[e].applicable(engine)]


def at_location(names, sides) -> list:
    """The candidates among ``names`` whose ``locations`` admit ``sides``' location."""
    where = None if not sides else sides.get("location")
    return [e for e in names if EFFECTS[e].locations is None or where in EFFECTS[e].locations]


def warm_caches(hm, effects):
    """Fill the parts of cached model ``hm`` that ``effects`` need, before any subset."""
    hm.two_ports()
    _ = hm.load
    for e in effects:
        EFFECTS[e].warm(hm)


def restatements(outcome, engine, band=None) -> tuple:
    """``((effects, reason), ...)``: candidates whose finding ``outcome``'s fit restates
    (``Effect.restates`` on ``engine``; ``band`` the measured frequency span [Hz])."""
    out = []
    for e in outcome.effects:
        r = EFFECTS[e].restates(outcome.params[e], engine, band)
        if r is not None:
            other = tuple(sorted([x for x in outcome.effects if x != e] + [r[0]]))
            out.append((other, r[1]))
    return tuple(out)


def _refit(setup, e, params, budget):
    """Effect ``e`` refitted from ``params``."""
    pack = Packing.of((e,), setup.problem.engine)
    x = np.array([math.log(params[pn]) if lg else params[pn] for (_, pn), lg in zip(pack.names, pack.log)])
    return fit_candidate(setup.problem, (e,), starts=[x], grid=False, budget=budget, defaults=False)


def _same(a, b, tol=0.01):
    return all(abs(a[k] - b[k]) <= tol * max(1.0, abs(b[k])) for k in b)


def equivalents(setup, chosen, rule, budget=400, noise_mse=0.0) -> list:
    """Parameter sets that explain the data as well as the answer ``chosen``, within noise.

    The answer is refitted (``budget`` evaluations) from each of ``Effect.alternatives``; a
    refit that lands elsewhere is equivalent when held-out t ≤ ``rule.t_min`` (``noise_mse``
    [dB²]) and its training BIC is within ``rule.bic_margin``. ``setup``: the diagnosis'.
    """
    if chosen is None or len(chosen.effects) != 1:
        return []
    e = chosen.effects[0]
    mine = CandidateEvidence(chosen.label, chosen.effects, chosen.heldout_mse,
                             chosen.heldout_per_rpm, chosen.bic)
    out, seen = [], [chosen.params[e]]
    for text, params in EFFECTS[e].alternatives(chosen.params[e], setup.problem.engine):
        fo = _refit(setup, e, {**chosen.params[e], **params}, budget)
        p = fo.params[e]
        if any(_same(p, q) for q in seen):
            continue
        seen.append(p)
        alt = CandidateEvidence(e, (e,), fo.heldout_mse, fo.heldout_per_rpm, fo.bic)
        t = improvement_t(alt, mine, noise_mse)
        if t <= rule.t_min and fo.bic - chosen.bic <= rule.bic_margin:
            desc = ", ".join(f"{k}={v:.3g}" for k, v in p.items())
            out.append({"effect": e, "parameters": p, "start": text,
                        "text": f"{e} ({desc}; refitted from '{text}')",
                        "heldout_rms_db": fo.heldout_rms_db, "t_answer_vs_this": t,
                        "train_bic_loss": fo.bic - chosen.bic})
    return out
