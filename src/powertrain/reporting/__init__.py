"""The study report (``powertrain report``, ``pt.report``): a study file's steps run through
the library's own functions and written as one self-contained HTML file (module map:
docs/architecture.md; the study file: docs/reference/study-file.md)."""
