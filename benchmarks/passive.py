r"""Passive-side cases of the blind benchmark: both sides of every mount measured.

A test lab measures the engine side *and* the body side of each mount. These cases are run
on the default engine with the modal body of ``engines/default-modal-body.toml`` (four
**illustrative** body modes; also with measured pressure traces), and the truth is made on
the truth path (:mod:`benchmarks.truth`: own assembly with the mount bases on the
body's modes, Newmark run-up) with the body side of every mount as further channels
(``NAME/passive``), measured with the same scatter and noise floor as the engine side
(:func:`powertrain.workflows.measurement.measure`).

**Plan** (:func:`passive_plan`), repeated every 14 cases: ``body_modes`` four times (the
body's modes differ from the file's, :data:`benchmarks.kinds.PASSIVE_KINDS`),
``mount_temperature`` four times (one mount 0.5–0.8× or 1.25–2× as stiff), two effect-free,
and (issue 21) two excitation changes (``balancer_shafts``) and two body modes the file
lacks (``missing_mode``); engines alternating. The diagnosis gets the modal-body engine
(nominal body) and the measured file with both sides; with ``phase`` (:func:`make_passive_case`)
the order phase of both sides too, drawn as on the engine side.
"""

from __future__ import annotations

import functools

import numpy as np

from benchmarks import truth as tr
from benchmarks.cases import Case, draw_case, traces_engine
from benchmarks.kinds import KINDS
from powertrain.analysis.channel import passive_name
from powertrain.workflows.measurement import RPM

#: Engine kinds of the passive-side cases (the rigid ones for missing body modes).
ENGINE_KINDS = ("body_sz", "body_traces")
_LAP = [("body_modes", "body_sz"), ("mount_temperature", "body_traces"), ("none", "body_sz"),
        ("body_modes", "body_traces"), ("mount_temperature", "body_sz"),
        ("body_modes", "body_sz"), ("mount_temperature", "body_traces"),
        ("none", "body_traces"), ("body_modes", "body_traces"), ("mount_temperature", "body_sz"),
        ("balancer_shafts", "body_traces"), ("missing_mode", "body_sz"),
        ("balancer_shafts", "body_sz"), ("missing_mode", "body_traces")]


def passive_plan(n_cases, seed):
    """``[(names, engine kind, case seed)]`` of the passive-side plan (module docstring)."""
    out = []
    for i in range(n_cases):
        case_seed = int(np.random.SeedSequence([seed, 13, i]).generate_state(1)[0])
        name, eng = _LAP[i % len(_LAP)]
        out.append(([] if name == "none" else [name], eng, case_seed))
    return out


@functools.cache
def passive_engines():
    """``{"body_sz": the modal-body engine, "body_traces": the same with measured
    traces, "rigid_sz", "rigid_traces": the default (rigid-chassis) engine, whose body side
    the diagnosis holds still}``."""
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    e = read_engine(DEFAULT_ENGINE_PATH.parent / "default-modal-body.toml")
    r = read_engine(DEFAULT_ENGINE_PATH)
    return {"body_sz": e, "body_traces": traces_engine(e), "rigid_sz": r,
            "rigid_traces": traces_engine(r)}


def nominal_body(engine) -> tr.BodyModes:
    """The engine file's modal body as the truth path's :class:`~.truth.BodyModes` (no
    modes for a rigid chassis: the body side held still)."""
    if engine.chassis is None or engine.chassis.is_rigid:
        n_m = len(engine.mounts)
        return tr.BodyModes(np.empty(0), np.empty(0), np.empty(0), np.empty((0, n_m, 3)))
    modes = engine.chassis.modes
    shapes = np.array([[m.shapes[mt.name] for mt in engine.mounts] for m in modes], float)
    return tr.BodyModes(np.array([m.frequency for m in modes], float),
                        np.array([m.modal_mass for m in modes], float),
                        np.array([m.damping_ratio for m in modes], float), shapes)


def channels(engine) -> list:
    """Engine-side channels, then the body side of every mount."""
    act = [(mt.name, a) for mt in engine.mounts for a in "xyz"]
    return act + [(passive_name(mt.name), a) for mt in engine.mounts for a in "xyz"]


def truth_velocity(engine, truth):
    """Noise-free truth (engine and body side) of ``[(kind name, params)]`` on ``engine``."""
    parts = {"engine": engine, "mounts": list(engine.mounts), "chassis": None,
             "bending": None, "amplitude_beta": None, "sensor": [],
             "body": nominal_body(engine), "passive": True}
    for name, params in truth:
        KINDS[name].apply(params, parts)
    return tr.simulate_truth(tr.TruthSpec(**parts), RPM)


@functools.cache
def baseline_velocity(engine_kind):
    """Noise-free baseline on the truth path, both sides (n_r, 18, 16) [m/s peak]."""
    return truth_velocity(passive_engines()[engine_kind], [])


def make_passive_case(index, names, engine_kind, seed, phase=None) -> Case:
    """Draw, simulate and measure one passive-side case; ``phase`` what order phase is
    measured on both sides (:func:`powertrain.workflows.measurement.measure`; the levels are the
    same with and without)."""
    engine = passive_engines()[engine_kind]
    return draw_case(index, names, engine_kind, seed, engine, baseline_velocity(engine_kind),
                     truth_velocity, channels(engine), "blind passive case", phase=phase)



#: Redraws allowed to find a detectable case (:func:`detectable_case`).
MAX_DRAWS = 30


def detectable_case(kind, engine_kind, rng, index, phase=None) -> Case:
    """The first detectable ``kind`` case of up to :data:`MAX_DRAWS` draws (case seeds from
    ``rng``); ValueError when none is."""
    for _ in range(MAX_DRAWS):
        case = make_passive_case(index, [kind], engine_kind, int(rng.integers(2 ** 31)), phase)
        if case.detectable:
            return case
    raise ValueError(f"no detectable {kind} case in {MAX_DRAWS} draws")
