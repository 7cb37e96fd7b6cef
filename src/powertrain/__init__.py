"""powertrain: powertrain mount vibration (NVH) simulator.

The study functions are importable from here, loaded on first use::

    run = pt.runup(pt.read_engine(), rpm="1000:6000:500")
    print(run.to_text())

Each checks its arguments as the command line does and returns a result with ``to_text()``,
``plot(ax=None)`` and ``save(path)`` (docs/guide/python-api.md; SI inside).
"""

from importlib import import_module as _import_module

from powertrain.errors import InputError, PowertrainWarning

__version__ = "0.1.0"

#: Public name -> (module, attribute); imported on first access (PEP 562).
API = {
    "read_engine": ("powertrain.iotools.engine_file", "read_engine"),
    "read_mount": ("powertrain.iotools.mount_file", "read_mount"),
    "read_measured": ("powertrain.iotools.measured", "read_measured"),
    "read_raw": ("powertrain.iotools.raw", "read_raw"),
    "read_plan": ("powertrain.iotools.plan", "read_plan"),
    "runup": ("powertrain.workflows.runup", "runup"),
    "modes": ("powertrain.workflows.modes", "modes"),
    "static": ("powertrain.workflows.static", "static"),
    "excitation": ("powertrain.workflows.excitation", "excitation"),
    "stiffness": ("powertrain.workflows.stiffness", "stiffness"),
    "fit_mount": ("powertrain.workflows.amplitude_fit", "fit_mount"),
    "compare": ("powertrain.workflows.comparison", "compare"),
    "whatif": ("powertrain.workflows.whatif", "whatif"),
    "track": ("powertrain.workflows.tracking", "track"),
    "diagnose": ("powertrain.diagnosis", "diagnose"),
    "synth": ("powertrain.workflows.synth", "synth"),
    "report": ("powertrain.reporting.report", "report"),
    "transient": ("powertrain.workflows.transient", "transient"),
    "read_manoeuvre": ("powertrain.iotools.manoeuvre_file", "read_manoeuvre"),
}

__all__ = ["InputError", "PowertrainWarning", "__version__", *API]


def __getattr__(name: str):
    """The functions of :data:`API`, imported when first used."""
    try:
        module, attr = API[name]
    except KeyError:
        raise AttributeError(f"module 'powertrain' has no attribute {name!r}") from None
    value = getattr(_import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    """The public names: :data:`__all__` and :data:`API`."""
    return sorted([*__all__, "API"])
