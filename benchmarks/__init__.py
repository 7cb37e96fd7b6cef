"""Validation of the diagnosis on data it was not made from.

* :mod:`benchmarks.truth` — the *truth simulator*: its own assembly of the
  powertrain (mount networks with their ground nodes, optional chassis bases and a
  powertrain bending mode) run in the time domain by Newmark integration, with
  higher-fidelity effect models written independently of the diagnosis' candidates;
* :mod:`benchmarks.kinds` — the truth effects (how their parameters are drawn);
* :mod:`benchmarks.cases` — the one case maker (:func:`~.cases.draw_case`), the
  case plan of the blind benchmark, measurement scatter and the one noise floor, and the one
  detectability rule, decided from the noise-free truth;
* :mod:`benchmarks.synth` — the quick generator of ``powertrain synth``: the
  same case maker on the frequency-domain harmonic model with truth effects of its own;
* :mod:`benchmarks.scoring` — the benchmark's scores from verdict rows, with
  Wilson score intervals.

The diagnosis is never imported here: the benchmark script hands the measured run-up to
:func:`powertrain.diagnosis.diagnose` and reads its answer through ``to_dict()``.
"""
