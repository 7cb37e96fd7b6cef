"""Scoring of the blind benchmark: hand-made verdict rows with known scores.

Oracles: counts done by hand on the rows below; Wilson intervals from the closed form
(Wilson 1927; values cross-checked against the tabulated 95 % interval for 0/10 and 5/10).
"""

import math

import numpy as np
import pytest

from benchmarks.scoring import (
    Rate,
    false_claim,
    meets_targets,
    noise_free_shrink,
    score,
    score_line,
    top1_hit,
    wilson_interval,
)


def row(category, detectable, truth, claimed, verdict=None, expected=None, shrink=None):
    return {"category": category, "detectable": detectable, "truth_set": sorted(truth),
            "expected_set": sorted(expected if expected is not None else truth),
            "claimed": sorted(claimed), "shrink": shrink,
            "verdict": verdict or ("+".join(claimed) if claimed else "no effect")}


ROWS = [
    # detectable in-library: 3 right (one via the expected subset of a pair), 1 wrong, 1 silent
    row("in", True, ["balancer_error"], ["balancer_error"], shrink=0.9),
    row("in", True, ["mount_stiffness"], ["mount_stiffness"], shrink=0.8),
    row("in", True, ["balancer_error", "sensor_error"], ["balancer_error"],
        expected=["balancer_error"], shrink=0.75),
    row("in", True, ["cylinder_imbalance"], ["sensor_error"], shrink=0.1),
    row("in", True, ["cylinder_imbalance"], [], verdict="unexplained: ..."),
    # undetectable in-library: naming the hidden effect is fine, naming another is false
    row("in", False, ["base_compliance"], ["base_compliance"], shrink=0.2),
    row("in", False, ["mount_stiffness"], ["sensor_error"], shrink=0.0),
    # effect-free: one false claim in three
    row("none", False, [], []),
    row("none", False, [], [], verdict="unexplained: x"),
    row("none", False, [], ["mount_stiffness"]),
    # out of library: detectable 2 (one unexplained), undetectable 1 (silent)
    row("out", True, ["outside"], [], verdict="unexplained: band 200 Hz"),
    row("out", True, ["outside"], ["sensor_error"]),
    row("out", False, ["outside"], [], verdict="no effect"),
]


def test_wilson_interval_closed_form():
    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = wilson_interval(5, 10)
    assert (lo, hi) == (pytest.approx(0.2366, abs=1e-4), pytest.approx(0.7634, abs=1e-4))
    assert wilson_interval(0, 0) == (0.0, 1.0)
    lo, hi = wilson_interval(10, 10)
    assert hi == 1.0 and lo == pytest.approx(1 - 0.2775, abs=1e-4)


def test_row_rules():
    assert top1_hit(ROWS[2])                  # expected subset of a pair
    assert not top1_hit(ROWS[3])
    assert not false_claim(ROWS[5])           # undetectable but the hidden effect named
    assert false_claim(ROWS[6])
    assert false_claim(ROWS[9]) and not false_claim(ROWS[8])
    assert false_claim(ROWS[11])              # out-of-library answered with a library effect


def test_scores_of_hand_made_rows():
    s = score(ROWS)
    assert (s["top1"].k, s["top1"].n) == (3, 5)
    # detectable in-library shrinks 0.9, 0.8, 0.75, 0.1 and 0 (no claim): median 0.75
    assert s["shrink_median"] == pytest.approx(0.75)
    # quiet = 3 effect-free + 2 undetectable in-library + 1 undetectable out: 2 false
    assert (s["false_claims"].k, s["false_claims"].n) == (2, 6)
    assert (s["unexplained_ok"].k, s["unexplained_ok"].n) == (1, 2)
    raw = s["raw"]
    assert (raw["top1"].k, raw["top1"].n) == (3, 7)          # exact hidden set only
    assert (raw["false_claims"].k, raw["false_claims"].n) == (1, 3)
    assert (raw["unexplained_ok"].k, raw["unexplained_ok"].n) == (1, 3)
    assert raw["shrink_median"] == pytest.approx(0.2)        # 0.9 .8 .75 .1 0 .2 0
    assert score_line(s) == "top1=0.60 shrink_median=0.75 false_claims=0.33 unexplained_ok=0.50"
    assert meets_targets(s) == {"top1": False, "shrink_median": True, "false_claims": False,
                                "unexplained_ok": False}


def test_rate_text_and_empty_rate():
    assert str(Rate(9, 10)).startswith("0.90 (9/10, 95% Wilson 0.60-0.98)")
    assert math.isnan(Rate(0, 0).value)


def test_noise_free_shrink_from_reported_gaps():
    """Model levels recovered from gaps against the noisy measurement: a model 2 dB above the
    truth before and 0.5 dB above after shrinks by 0.75 whatever the noise."""
    rpm = np.array([1000.0, 1100.0, 1200.0, 1300.0])
    rng = np.random.default_rng(0)
    truth = np.full(4, 1e-4)
    meas = truth * 10 ** (rng.normal(0, 1, 4) / 20)
    g0 = 20 * np.log10(truth * 10 ** (2 / 20) / meas)
    g1 = 20 * np.log10(truth * 10 ** (0.5 / 20) / meas)
    g1[0] = np.nan                          # censored after: left out
    where = {"rpm": rpm.tolist(), "channels": [["left", "x"]],
             "quantities": ["order_2", "synthesis"],
             "gap_db": [[[x, 0.0]] for x in g0], "gap_db_after": [[[x, 0.0]] for x in g1]}
    s = noise_free_shrink(where, [1100.0, 1200.0, 1000.0], lambda *a: truth,
                          lambda *a: meas, 1e-9)
    assert s == pytest.approx(0.75, abs=1e-6)
    assert noise_free_shrink({**where, "gap_db_after": None}, rpm, lambda *a: truth,
                             lambda *a: meas, 1e-9) is None


def test_two_sided_rates_of_hand_made_rows():
    """Issue 21: side attribution right per kind, a missing mode found only within 5 % in
    frequency and 30 % in modal mass, undetectable cases not counted."""
    from benchmarks.scoring import mode_found, sides_rate, two_sided_line
    truth = {"frequency_hz": 50.0, "modal_mass_kg": 10.0}

    def mode(f, m, claimed=("missing_body_mode",)):
        return {"names": ["missing_mode"], "detectable": True, "where_side": "body",
                "claimed": list(claimed), "truth_mode": truth,
                "parameters": {"missing_body_mode": {"frequency_hz": f, "modal_mass_kg": m}}}
    assert mode_found(mode(52.4, 12.9)) and not mode_found(mode(52.6, 10.0))
    assert not mode_found(mode(50.0, 13.1)) and not mode_found(mode(50.0, 10.0, ()))
    rows = [mode(50.0, 10.0), mode(60.0, 10.0),
            {"names": ["balancer_shafts"], "detectable": True,
             "where_side": "engine side or excitation", "claimed": []},
            {"names": ["mount_temperature"], "detectable": True, "where_side": "body",
             "claimed": []},
            {"names": ["body_modes"], "detectable": False, "where_side": "mounts",
             "claimed": []}]
    r = sides_rate(rows)
    assert (r.k, r.n) == (3, 4)
    assert two_sided_line(rows).startswith("two-sided: sides_right=0.75 (3/4, Wilson ")
    assert "missing_mode_found=0.50 (1/2," in two_sided_line(rows)
