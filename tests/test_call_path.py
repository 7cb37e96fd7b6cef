"""scripts/call_path.py: the path of a what-if variant from the command line to the solver
(issue 19 quotes its hops); the variant is applied once on its way."""

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "call_path.py"


def _load():
    spec = importlib.util.spec_from_file_location("call_path", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
def test_whatif_variant_reaches_the_condensation_once_applied(tmp_path):
    stack, applied = _load().trace(
        ["whatif", "--workers", "1", "--from", "2000", "--to", "3000", "--scale",
         "left.z.stiffness=1.2", "--json", str(tmp_path / "w.json"), "--quiet"],
        "harmonic_solve", "apply")
    assert applied == 1
    names = [f"{m}.{f}" for m, f in stack]
    assert names[0] == "powertrain.cli.whatif.whatif"
    assert names[-1] == "powertrain.physics.condensation.harmonic_solve"
    assert len(names) - 1 <= 15
