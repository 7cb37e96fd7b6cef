"""The blind benchmark of the diagnosis and the rate tests: data it was not made from.

Beside the package, not installed with it (the wheel takes ``src/`` only); imported from the
top of the checkout (pytest's ``pythonpath``, ``python -m benchmarks.rates``, and the scripts,
which put the checkout on ``sys.path``).

* :mod:`benchmarks.truth` — the *truth simulator*: its own assembly of the powertrain (mount
  networks with their ground nodes, optional chassis bases and a powertrain bending mode) run
  in the time domain by Newmark integration, with higher-fidelity effect models written
  independently of the diagnosis' candidates;
* :mod:`benchmarks.kinds` — the truth effects (how their parameters are drawn and applied);
* :mod:`benchmarks.cases` — the case plan of the blind benchmark, its engines, the case maker
  (on :func:`powertrain.workflows.measurement.draw_case`, the measurement of
  ``powertrain synth``) and the one detectability rule, decided from the noise-free truth;
* :mod:`benchmarks.passive`, :mod:`benchmarks.plans` — both sides of every mount measured;
  one hidden truth measured at several loads;
* :mod:`benchmarks.scoring` — the benchmark's scores from verdict rows, with Wilson score
  intervals;
* :mod:`benchmarks.sizing` — the rate tests' Wilson rule and group-sequential rule;
* :mod:`benchmarks.rate_tests` — the ten rate tests (their cases, successes, targets and
  fixed seeds); :mod:`benchmarks.rates` — ``python -m benchmarks.rates [--fresh]``;
* :mod:`benchmarks.signals` — synthetic time data with known order content (test oracles).

The truth generator never imports the diagnosis: the benchmark script and the rate tests hand
the measured run-up to :func:`powertrain.diagnosis.diagnose` and read its answer through
``to_dict()``.
"""
