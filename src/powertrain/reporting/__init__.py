"""The study report (``powertrain report``, ``pt.report``): a study file's steps run through
the library and written as one self-contained HTML file (docs/reference/study-file.md)."""
