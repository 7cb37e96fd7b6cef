"""powertrain: powertrain mount vibration (NVH) simulator.

Data flows one way: files (:mod:`powertrain.iotools`) -> model objects
(:mod:`powertrain.models`) -> assembled system -> solvers (:mod:`powertrain.kernels`,
:mod:`powertrain.physics`) -> results -> analysis -> plots and reports.
Everything inside the package is SI; datasheet units are converted once, in the loaders,
through the table in :mod:`powertrain.units`.
"""

__version__ = "0.1.0"

from powertrain.errors import InputError  # noqa: E402

__all__ = ["InputError", "__version__"]
