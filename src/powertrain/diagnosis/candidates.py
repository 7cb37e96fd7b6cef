"""Step 2 of the diagnosis: the candidate effects for this engine, and what the data cannot
tell apart among their parameters.

Candidates come from the effect registry (:data:`powertrain.effects.EFFECTS`); an effect
is a candidate when it applies to the engine (``applicable(engine)``).
"""

from __future__ import annotations

from powertrain.effects import EFFECTS


def applicable(engine, names=None) -> list:
    """Names of the registry's effects (or of ``names``) that apply to ``engine``."""
    return [e for e in (names or EFFECTS) if EFFECTS[e].applicable(engine)]


def warm_caches(hm, effects):
    """Fill the cached model's parts the candidates need (two-ports, loads, derivatives)
    once, before any subset is taken."""
    hm.two_ports()
    _ = hm.load
    for e in effects:
        EFFECTS[e].warm(hm)


def equivalents(setup, chosen, verdict) -> list:
    """Parameter sets of the chosen effect that explain the data equally well (none known
    for this effect: an empty list)."""
    return []
