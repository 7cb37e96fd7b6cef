"""Step 2 of the diagnosis: the candidate effects for this engine, and what the data cannot
tell apart among their parameters.

Candidates come from the effect registry (:data:`powertrain.effects.EFFECTS`); an effect
is a candidate when it applies to the engine (``applicable(engine)``).
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.diagnosis.rule import CandidateEvidence, improvement_t
from powertrain.effects import EFFECTS


def applicable(engine, names=None) -> list:
    """Names of the registry's effects (or of ``names``) that apply to ``engine``."""
    return [e for e in (names or EFFECTS) if EFFECTS[e].applicable(engine)]


def warm_caches(hm, effects):
    """Fill the cached model's parts the candidates need (two-ports, loads, derivatives)
    once, before any subset is taken."""
    hm.two_ports()
    _ = hm.load
    for e in effects:
        EFFECTS[e].warm(hm)


def equivalents(setup, chosen, rule) -> list:
    r"""Parameter sets that explain the data as well as the chosen answer, within the noise.

    For each alternative the chosen effect offers (``Effect.alternatives``: another
    reference cylinder, swapped mirror-image mounts...) the held-out gap is evaluated; it is
    *equivalent* when the held-out speeds do not prefer the answer significantly (per-speed
    t ≤ ``rule.t_min``, as between rival candidates) and its training BIC is not worse by
    more than ``rule.bic_margin``. The answer is then one of several; the report lists
    them instead of picking one silently. (Order magnitudes only: measured phases, which
    would separate some of them, are not read.)
    """
    if chosen is None or len(chosen.effects) != 1:
        return []
    e = chosen.effects[0]
    p = setup.problem
    mine = CandidateEvidence(chosen.label, chosen.effects, chosen.heldout_mse,
                             chosen.heldout_per_rpm, chosen.bic)
    out = []
    for text, params in EFFECTS[e].alternatives(chosen.params[e], p.engine):
        sc = {e: params}
        g = p.gaps(sc, "test")
        ok = np.isfinite(g)
        per = np.array([np.mean(g[i][ok[i]] ** 2) if ok[i].any() else np.nan
                        for i in range(g.shape[0])])
        r = p.vector(sc)
        n, k = r.size, chosen.n_params
        bic = n * math.log(max(float(np.sum(r ** 2)), 1e-300) / n) + k * math.log(n)
        alt = CandidateEvidence(e, (e,), float(np.mean(g[ok] ** 2)), per, bic)
        t = improvement_t(alt, mine)
        if t <= rule.t_min and bic - chosen.bic <= rule.bic_margin:
            out.append({"effect": e, "parameters": params, "text": f"{e}: {text}",
                        "heldout_rms_db": math.sqrt(alt.heldout_mse),
                        "t_answer_vs_this": t, "train_bic_loss": bic - chosen.bic})
    return out
