"""The static operating point per speed (``powertrain static``)."""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.results.static import StaticResult
from powertrain.solvers.operating_point import operating_points
from powertrain.workflows.arguments import speeds


def static(engine=None, rpm=None) -> StaticResult:
    """The static operating point of ``engine`` at each speed of ``rpm``.

    Parameters
    ----------
    engine : Engine, str or Path, optional
        The engine, or its file (default: the shipped ``engines/default.toml``).
    rpm : array_like or str, optional
        Speeds [rpm], or as ``--rpm`` writes them (default 1000..6000 step 500).

    Returns
    -------
    StaticResult
        ``to_text()`` is what ``powertrain static`` prints.
    """
    rpm = speeds(rpm)
    engine = engine_or_default(engine)
    engine.require_excitation()
    lo, hi = engine.speed_range_rpm()
    bad = rpm[~(np.isfinite(rpm) & (rpm >= lo - 1e-6) & (rpm <= hi + 1e-6))]
    if bad.size:
        raise InputError(f"{bad[0]:g} rpm is outside the engine's range {lo:g}..{hi:g} rpm", key="--rpm")
    return StaticResult(operating_points(engine, rpm), engine.mount_names, engine.name)
