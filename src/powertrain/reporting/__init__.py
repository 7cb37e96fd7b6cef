"""The study report (``powertrain report``, ``pt.report``): a study file names the engine, the
measured run-ups (or a test plan) and the steps to run (compare, diagnose, what-if, modes,
transient manoeuvres); each step is run through the library's own functions and the whole written as one
self-contained HTML file: a summary (engine, files with provenance and SHA-256, verdict, top
gaps), a section per step with its tables and figures, and the commands and versions that
reproduce it.

* :mod:`powertrain.reporting.keys`: checking a study file's values (errors name file and key);
* :mod:`powertrain.reporting.steps`: the steps a study may include (:data:`STEPS`; a new kind
  of step is one more entry there);
* :mod:`powertrain.reporting.study`: reading the study file;
* :mod:`powertrain.reporting.document`: the HTML document;
* :mod:`powertrain.reporting.report`: :func:`report` and its result.
"""
