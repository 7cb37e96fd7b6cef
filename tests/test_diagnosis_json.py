"""The diagnosis JSON never carries NaN/inf: undefined quantities are null (issue 10: a
1e-300 level into ``diagnose --json`` gave NaN; a candidate's explained fraction is undefined
when the baseline leaves no excess over noise)."""

from __future__ import annotations

import json

import numpy as np

from powertrain.diagnosis import result as dr


def test_non_finite_values_become_null_at_any_depth():
    raw = {"a": float("nan"), "b": [1.0, np.inf, {"c": np.float64(-np.inf)}],
           "d": np.array([np.nan, 2.0]), "e": "text", "f": 3}
    out = dr._finite_or_null(raw)
    assert out == {"a": None, "b": [1.0, None, {"c": None}], "d": [None, 2.0], "e": "text",
                   "f": 3}
    json.dumps(out, allow_nan=False)


def test_to_json_writes_null_for_an_undefined_explained_fraction(monkeypatch, tmp_path):
    class Stub:
        to_json = dr.DiagnosisResult.to_json

        def to_dict(self):
            return {"ranking": [{"explained": float("nan"), "heldout_rms_db": 0.66}]}

    text = Stub().to_json(tmp_path / "d.json")
    assert "NaN" not in text
    assert json.loads((tmp_path / "d.json").read_text())["ranking"][0]["explained"] is None
