r"""Step 4 of the diagnosis: the decision rule, a pure function of the evidence.

:func:`decide` (evidence, rule) → :class:`Verdict`; it never fits. A candidate is
**supported** when it lowers the training BIC by more than ``bic_margin`` and its per-speed
held-out improvement t (:func:`improvement_t`) exceeds ``t_min``; a pair must also beat its
better member. The **answer** is the best supported candidate among the first ``n_checked``
that explains ``explained_min`` of the excess :math:`E_0 - E_n` [dB²], leaves no structured
residual and predicts withheld (channel, order) cells; a rival of another family it cannot
be told from makes it **ambiguous**. Else **no effect** (excess below ``excess_min_db``) or
**unexplained**. A missing check or cross-fit yields a ``PENDING`` verdict that names it;
the driver computes it and decides again. Details: docs/guide/diagnose.md, "Decision rule".
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from powertrain.diagnosis.evidence import Assessment, Evidence, Status, Verdict, VerdictKind
from powertrain.diagnosis.significance import crossfit_t, improvement_t


@dataclass(frozen=True)
class DecisionRule:
    """Constants of the decision rule (tests/test_decision_rule.py checks each threshold).

    Attributes
    ----------
    t_min : float
        Held-out significance: 4 standard errors (chance p ≈ 3e-5 per candidate, < 1e-3
        over ~25 candidates).
    bic_margin : float
        Training BIC gain: 10 is "very strong" evidence (Kass & Raftery 1995).
    explained_min : float
        Fraction of the held-out excess over noise the answer must explain (its main cause).
    pair_gain_min : float
        Fraction of what the better member leaves that a pair must remove.
    excess_min_db : float
        Excess RMS gap over noise below which the model agrees [dB]: a test lab's
        run-to-run repeatability of order levels.
    struct_abs_db : float
        Structured held-out residual beyond noise the answer may keep [dB].
    struct_rel : float
        ... or this fraction of the baseline's structured gap.
    xv_explained_min : float
        Fraction of the withheld cells' excess the refitted answer must predict.
    xv_t_min : float
        Significance of that prediction (one-sided p ≈ 0.004 with ~17 held-out speeds);
        below ``t_min``: it confirms one candidate, no search to correct for.
    n_checked : int
        Supported candidates (best first) put through the structure and cells checks.
    t_screen : float
        Held-out t above which a candidate (or rival) short of ``t_min`` is cross-fitted and
        judged on all speeds: three times the speeds raise t by about √3, so below 2
        cross-fitting cannot reach 4.
    xv_t_screen : float
        Cells-check t above which a check at the held-out speeds only that misses
        ``xv_t_min`` is repeated over every speed fold (3/√3 ≈ 1.7).
    """

    t_min: float = 4.0
    bic_margin: float = 10.0
    explained_min: float = 0.6
    pair_gain_min: float = 0.5
    excess_min_db: float = 0.5
    struct_abs_db: float = 0.6
    struct_rel: float = 0.35
    xv_explained_min: float = 0.5
    xv_t_min: float = 3.0
    n_checked: int = 3
    t_screen: float = 2.0
    xv_t_screen: float = 1.7

    def to_dict(self) -> dict:
        """Upper-case keys (the diagnosis JSON's ``decision_rule``)."""
        return {k.upper(): v for k, v in dataclasses.asdict(self).items()}


def _assess(ev: Evidence, rule: DecisionRule) -> dict:
    e0 = ev.baseline.heldout_mse
    excess0 = max(e0 - ev.noise_mse, 0.0)
    out = {c.label: _support(ev, rule, c, e0, excess0) for c in ev.candidates}
    by_label = {c.label: c for c in ev.candidates}
    for c in ev.candidates:
        if len(c.effects) != 2 or out[c.label].status is not Status.SUPPORTED:
            continue
        best_m = min((by_label[e] for e in c.effects), key=lambda m: m.heldout_mse)
        t, dbic = crossfit_t(best_m, c, ev.noise_mse), best_m.bic - c.bic
        left = best_m.heldout_mse - ev.noise_mse
        gain = (best_m.heldout_mse - c.heldout_mse) / left if left > 0 else 0.0
        if _member_suffices(ev, rule, best_m, out[best_m.label]):
            out[c.label].status = Status.NOT_BETTER_THAN_MEMBER
            out[c.label].text = (f"not better than {best_m.label} alone (it leaves "
                                 f"{math.sqrt(max(left, 0.0)):.2f} dB RMS over noise)")
            continue
        if not (t > rule.t_min and dbic > rule.bic_margin and gain >= rule.pair_gain_min):
            out[c.label].status = Status.NOT_BETTER_THAN_MEMBER
            out[c.label].text = f"not better than {best_m.label} alone"
            if (t > rule.t_screen and dbic > rule.bic_margin and gain >= rule.pair_gain_min
                    and (c.crossfit is None or best_m.crossfit is None)):
                out[c.label].crossfit_labels = tuple(x.label for x in (c, best_m) if x.crossfit is None)
    return out


def _support(ev, rule, c, e0, excess0) -> Assessment:
    """Support of one candidate against the baseline (cross-fit asked for when t is short)."""
    t, dbic = improvement_t(ev.baseline, c, ev.noise_mse), ev.baseline.bic - c.bic
    explained = (e0 - c.heldout_mse) / excess0 if excess0 > 0 else float("nan")
    base_ok = dbic > rule.bic_margin and c.heldout_mse < e0
    tx = crossfit_t(ev.baseline, c, ev.noise_mse) if c.crossfit is not None else float("nan")
    ok = base_ok and (t > rule.t_min or tx > rule.t_min)
    st = Status.SUPPORTED if ok else Status.NOT_SUPPORTED
    need = (base_ok and c.crossfit is None and rule.t_screen < t <= rule.t_min
            and np.isfinite(explained) and explained >= rule.explained_min)
    return Assessment(t, dbic, explained, st, st.value, t_crossfit=tx,
                      crossfit_labels=(c.label,) if need else ())


def _member_suffices(ev, rule, m, a) -> bool:
    """Member ``m`` is supported and leaves no excess or structure for a second effect."""
    left = math.sqrt(max(m.heldout_mse - ev.noise_mse, 0.0))
    return (a.status is Status.SUPPORTED and left < rule.excess_min_db
            and m.struct_db <= _struct_max(ev, rule))


def _within_noise(ev, rule) -> bool:
    """The baseline leaves no excess or structure for a candidate to explain."""
    left = math.sqrt(max(ev.baseline.heldout_mse - ev.noise_mse, 0.0))
    return left < rule.excess_min_db and ev.baseline.struct_db <= rule.struct_abs_db


def _struct_max(ev, rule):
    return max(rule.struct_abs_db, rule.struct_rel * ev.baseline.struct_db)


def _big(a, rule):
    return np.isfinite(a.explained) and a.explained >= rule.explained_min


def _choose(ev, rule, ranked, ass):
    """``(chosen, None)``, ``(None, label)`` whose cells check is missing, or ``(None, None)``."""
    smax = _struct_max(ev, rule)
    big = [c for c in ranked if ass[c.label].status is Status.SUPPORTED and _big(ass[c.label], rule)]
    for c in big[:rule.n_checked]:
        a = ass[c.label]
        r = next((r for r in big if r is not c and _restated(c, r)
                  and not crossfit_t(r, c, ev.noise_mse) > rule.t_min), None)
        if r is not None:
            a.status, a.text = Status.RESTATES, f"restates {r.label} ({_restated(c, r)})"
            continue
        if not c.struct_db <= smax:
            a.status = Status.STRUCTURED_RESIDUAL
            a.text = f"residual structured ({c.struct_db:.2f} dB > {smax:.2f} dB beyond noise)"
            continue
        if c.cells is None:
            return None, c.label
        xv = c.cells
        if xv["baseline_excess_db"] >= rule.excess_min_db and not (
                xv["explained"] >= rule.xv_explained_min and xv["t"] > rule.xv_t_min):
            if (xv.get("speed_folds", 1) == 1 and xv["explained"] >= rule.xv_explained_min
                    and xv["t"] > rule.xv_t_screen):
                return None, c.label             # again, over every speed fold
            a.status = Status.FAILS_HELDOUT_CELLS
            a.text = (f"fails held-out {xv['kind']} (explains {xv['explained']:.0%}, t {xv['t']:.1f})")
            continue
        return c, None
    return None, None


def _rivals(ev, rule, ranked, ass, chosen):
    """Rivals the held-out speeds cannot tell from ``chosen``, and labels to cross-fit."""
    mine, smax, out, need = set(chosen.effects), _struct_max(ev, rule), [], []
    for c in ranked:
        theirs, a = set(c.effects), ass[c.label]
        if (c is chosen or a.status is not Status.SUPPORTED or theirs <= mine
                or mine <= theirs or not _big(a, rule) or not c.struct_db <= smax):
            continue
        t_rival = crossfit_t(c, chosen, ev.noise_mse)
        if t_rival > rule.t_min:
            continue
        if _restated(c, chosen):
            a.status, a.text = Status.RESTATES, f"restates {chosen.label} ({_restated(c, chosen)})"
            continue
        if _needs_more_causes(rule, c, chosen):
            a.text = f"supported, but needs {len(c.effects)} effects where {chosen.label} does better"
            continue
        if t_rival > rule.t_screen:
            need += [x.label for x in (chosen, c) if x.crossfit is None]
        out.append((c, t_rival))
    return out, list(dict.fromkeys(need))


def _needs_more_causes(rule, c, chosen) -> bool:
    """Rival ``c`` names more effects than the answer yet is worse held-out and in BIC."""
    return (len(c.effects) > len(chosen.effects) and c.heldout_mse > chosen.heldout_mse
            and c.bic - chosen.bic > rule.bic_margin)


def _restated(c, r) -> str:
    """Why ``c``'s fit restates candidate ``r`` ('' when it does not)."""
    key = tuple(sorted(r.effects))
    return next((why for eff, why in c.restates if tuple(eff) == key), "")


def decide(evidence: Evidence, rule: DecisionRule = DecisionRule()) -> Verdict:
    """The verdict for ``evidence`` under ``rule`` (pure: no fitting, no side effects)."""
    ev = evidence
    ass = _assess(ev, rule)
    ranked = sorted(ev.candidates, key=lambda c: c.heldout_mse)
    order = [c.label for c in ranked]
    cross = list(dict.fromkeys(lab for c in ranked for lab in ass[c.label].crossfit_labels))
    if cross:
        return Verdict(VerdictKind.PENDING, "pending", "", ass, order, needs_crossfit=cross)
    if _within_noise(ev, rule):
        return _no_answer(ev, rule, ass, order, ranked)
    chosen, pending = _choose(ev, rule, ranked, ass)
    if pending is not None:
        return Verdict(VerdictKind.PENDING, "pending", "", ass, order, needs_cells_check=pending)
    rivals, cross = _rivals(ev, rule, ranked, ass, chosen) if chosen is not None else ([], [])
    if cross:
        return Verdict(VerdictKind.PENDING, "pending", "", ass, order, needs_crossfit=cross)
    if rivals:
        pairs = [chosen] + [c for c, _ in rivals]
        member = _shared_member(rule, ranked, ass, pairs)
        if member is not None:
            return _member_answer(ev, ass, order, member, pairs)
        return _ambiguous(ev, rule, ass, order, chosen, rivals)
    if chosen is not None:
        return _chosen(ev, ass, order, chosen)
    return _no_answer(ev, rule, ass, order, ranked)


def _ambiguous(ev, rule, ass, order, chosen, rivals):
    a = ass[chosen.label]
    a.text = "indistinguishable from " + ", ".join(c.label for c, _ in rivals)
    a.status = Status.INDISTINGUISHABLE
    for c, t in rivals:
        ass[c.label].status = Status.INDISTINGUISHABLE
        ass[c.label].text = f"indistinguishable from {chosen.label} (t {t:.1f})"
    text = ("ambiguous: " + " or ".join(f"{c.label} (explains {ass[c.label].explained:.0%})"
                                       for c in [chosen] + [r for r, _ in rivals])
            + f"; each passes the decision rule but the held-out speeds do not tell them "
              f"apart (t {max(t for _, t in rivals):.1f} <= {rule.t_min:g}); data at other "
              f"amplitudes, loads or channels are needed to decide")
    return Verdict(VerdictKind.AMBIGUOUS, "ambiguous", text, ass, order,
                   ambiguous=[chosen.label] + [c.label for c, _ in rivals])


def _shared_member(rule, ranked, ass, pairs):
    """The one effect all indistinguishable pairs share, if big and supported alone."""
    if any(len(c.effects) != 2 for c in pairs):
        return None
    shared = set.intersection(*(set(c.effects) for c in pairs))
    return next((c for c in ranked if len(shared) == 1 and set(c.effects) == shared
                 and ass[c.label].status is Status.SUPPORTED and _big(ass[c.label], rule)),
                None)


def _member_answer(ev, ass, order, m, pairs):
    """Answer ``m``; its indistinguishable pairs' second effects named as not identified."""
    seconds = [next(e for e in c.effects if e not in m.effects) for c in pairs]
    for c in pairs:
        ass[c.label].status = Status.INDISTINGUISHABLE
        ass[c.label].text = "second effect not identified: " + " or ".join(seconds)
    a = ass[m.label]
    a.status, a.text = Status.CHOSEN, Status.CHOSEN.value
    text = (f"{m.label}: explains {a.explained:.0%} of the held-out excess gap over noise; held-out RMS gap "
            f"{ev.baseline.heldout_mse ** 0.5:.2f} -> {m.heldout_mse ** 0.5:.2f} dB; with it a second effect "
            f"is supported, but the held-out speeds cannot tell {' from '.join(seconds)}")
    return Verdict(VerdictKind.EFFECT, m.label, text, ass, order, chosen=m.label,
                   second_effect_between=[c.label for c in pairs])


def _chosen(ev, ass, order, c):
    a = ass[c.label]
    a.status, a.text = Status.CHOSEN, Status.CHOSEN.value
    text = (f"{c.label}: explains {a.explained:.0%} of the held-out excess gap over noise; held-out RMS gap "
            f"{ev.baseline.heldout_mse ** 0.5:.2f} -> {c.heldout_mse ** 0.5:.2f} dB; structured residual "
            f"{c.struct_db:.2f} dB (baseline {ev.baseline.struct_db:.2f} dB); withheld {c.cells['kind']}: "
            f"explains {c.cells['explained']:.0%}")
    return Verdict(VerdictKind.EFFECT, c.label, text, ass, order, chosen=c.label)


def _no_answer(ev, rule, ass, order, ranked):
    e0 = ev.baseline.heldout_mse
    excess_db = math.sqrt(max(e0 - ev.noise_mse, 0.0))
    supported = [c for c in ranked if ass[c.label].status is not Status.NOT_SUPPORTED
                 and ass[c.label].status is not Status.NOT_BETTER_THAN_MEMBER]
    if excess_db < rule.excess_min_db:
        extra = (f"; the best supported candidate, {supported[0].label}, would change it by "
                 f"{abs(e0 ** 0.5 - supported[0].heldout_mse ** 0.5):.2f} dB only"
                 if supported else " and no candidate improves it significantly")
        text = (f"no effect: the held-out gap ({e0 ** 0.5:.2f} dB RMS) is within noise "
                f"({ev.sigma_db:.2f} dB; excess {excess_db:.2f} dB < {rule.excess_min_db:g} dB){extra}")
        return Verdict(VerdictKind.NO_EFFECT, "no effect", text, ass, order)
    if supported:
        best = ass[supported[0].label]
        if best.status is Status.SUPPORTED:
            best.status, best.text = Status.PARTIAL, Status.PARTIAL.value
        text = (f"unexplained: the best candidate, {supported[0].label}, explains "
                f"{best.explained:.0%} of the held-out excess gap ({excess_db:.2f} dB RMS "
                f"over noise) but fails the decision rule ({best.text}); " + ev.where_text)
        return Verdict(VerdictKind.UNEXPLAINED, "unexplained", text, ass, order)
    text = (f"unexplained: no candidate improves the held-out gap significantly; excess "
            f"over noise {excess_db:.2f} dB RMS; " + ev.where_text)
    return Verdict(VerdictKind.UNEXPLAINED, "unexplained", text, ass, order)
