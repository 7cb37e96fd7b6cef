"""The static operating point per speed (``powertrain static``): the engine read, its
excitation required, the speeds checked against its range, the equilibrium solved per speed
(:func:`powertrain.solvers.operating_point.operating_points`)."""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.results.static import StaticResult
from powertrain.solvers.operating_point import operating_points


def static(engine=None, rpm=None) -> StaticResult:
    """The static operating point of ``engine`` at each speed of ``rpm``.

    Parameters
    ----------
    engine : Engine, str or Path, optional
        The engine, or its file (default: the shipped ``engines/default.toml``).
    rpm : array_like, optional
        Speeds [rpm] (default: the run-up's, 1000..6000 step 500).

    Returns
    -------
    StaticResult
        ``to_text()`` is what ``powertrain static`` prints; ``to_json(path=None)``.

    Raises
    ------
    InputError
        Naming the engine file and key, or ``--rpm``, of bad input; naming the speed where
        the equilibrium is not found.
    """
    from powertrain.iotools.engine_file import engine_or_default
    from powertrain.workflows.runup import default_rpm
    engine = engine_or_default(engine)
    engine.require_excitation()
    rpm = default_rpm() if rpm is None else np.atleast_1d(np.asarray(rpm, float))
    lo, hi = engine.speed_range_rpm()
    if rpm.size == 0:
        raise InputError("no speed given", key="--rpm")
    bad = rpm[~(np.isfinite(rpm) & (rpm >= lo - 1e-6) & (rpm <= hi + 1e-6))]
    if bad.size:
        raise InputError(f"{bad[0]:g} rpm is outside the engine's range {lo:g}..{hi:g} rpm",
                         key="--rpm")
    return StaticResult(operating_points(engine, rpm), engine.mount_names, engine.name)
