"""scripts/blind_diagnosis.py: the last two lines keep their keys, and a small benchmark on a
dask LocalCluster gives exactly the rows of a serial run."""

import importlib.util
import json
import re
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "blind_diagnosis.py"
LAST = re.compile(r"^top1=\S+ shrink_median=\S+ false_claims=\S+ unexplained_ok=\S+$")
TIMES = ("t_gen", "t_diag", "cpu_diag")
#: Seed of the one-case benchmark (named in the failure message).
SEED = 31


def _script():
    spec = importlib.util.spec_from_file_location("blind_diagnosis", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _rows(path):
    return [{k: v for k, v in r.items() if k not in TIMES} for r in json.loads(path.read_text())]


@pytest.mark.slow
def test_local_cluster_benchmark_equals_serial(tmp_path, capsys):
    pytest.importorskip("distributed")
    seed = str(SEED)
    mod = _script()
    mod.main(["--cases", "1", "--seed", seed, "--scheduler", "serial", "--jobs", "1",
              "--dump", str(tmp_path / "serial.json")])
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-1].startswith("top1=") and LAST.match(lines[-1])
    assert lines[-2].startswith("raw: top1=")
    assert any("Wilson" in x for x in lines) and any("longest" in x for x in lines)
    mod.main(["--cases", "1", "--seed", seed, "--scheduler", "local", "--jobs", "1",
              "--dump", str(tmp_path / "local.json")])
    assert _rows(tmp_path / "local.json") == _rows(tmp_path / "serial.json"), f"seed {seed}"
