"""Every function of ``import powertrain as pt`` called with bad input: a wrong type, a value out
of range, a missing file, and the strings the command line takes. Each raises
``pt.InputError`` (with the command's line, naming the option) or works; never a raw
``ValueError``, ``TypeError`` or ``AttributeError``. The strings the CLI accepts
(``"1000:6000:500"``, ``"1:400:1"``) give what the CLI computes from them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import ENGINES, EXAMPLES, MOUNTS
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import powertrain as pt
from powertrain.cli import main
from powertrain.workflows import arguments

MOUNT = str(MOUNTS / "hydraulic-engine-mount-z.toml")
MEASURED = str(EXAMPLES / "measured-runup.csv")
RAW = str(EXAMPLES / "raw-runup.csv")
AMPLITUDES = str(EXAMPLES / "hydraulic-mount-amplitudes.csv")
MISSING = "no-such-file.toml"
START = str(EXAMPLES / "start.toml")
QUICK = {"solver": "harmonic"}


def _engine():
    return pt.read_engine()


#: (call, must fail): ``call(engine)`` runs one API function with one bad (or CLI-string)
#: argument; ``must fail`` True: an InputError is required, False: it may also work.
CASES = {
    # read_*: missing files, wrong types
    "read_engine missing": (lambda e: pt.read_engine(MISSING), True),
    "read_engine int": (lambda e: pt.read_engine(123), True),
    "read_mount None": (lambda e: pt.read_mount(None), True),
    "read_measured missing": (lambda e: pt.read_measured(MISSING), True),
    "read_measured descriptor": (lambda e: pt.read_measured(0), True),
    "read_measured mounts": (lambda e: pt.read_measured(MEASURED, mounts=5), True),
    "read_raw channel map": (lambda e: pt.read_raw(RAW, 3), True),
    "read_raw channel map file": (lambda e: pt.read_raw(RAW, str(EXAMPLES / "raw-channels"
                                                                 ".toml")), False),
    "read_raw list": (lambda e: pt.read_raw([]), True),
    "read_plan missing": (lambda e: pt.read_plan(MISSING, e), True),
    # runup
    "runup negative speed": (lambda e: pt.runup(e, rpm=[-100, 1000], **QUICK), True),
    "runup speed text": (lambda e: pt.runup(e, rpm="abc", **QUICK), True),
    "runup no speed": (lambda e: pt.runup(e, rpm=[], **QUICK), True),
    "runup decreasing": (lambda e: pt.runup(e, rpm=[2000, 1000], **QUICK), True),
    "runup above range": (lambda e: pt.runup(e, rpm=[1000, 90000], **QUICK), True),
    "runup CLI string": (lambda e: pt.runup(e, rpm="1000:3000:1000", **QUICK), False),
    "runup solver": (lambda e: pt.runup(e, rpm=[1000], solver="exact"), True),
    "runup stepper": (lambda e: pt.runup(e, rpm=[1000], stepper=3), True),
    "runup angle step text": (lambda e: pt.runup(e, rpm=[1000], angle_step_deg="a"), True),
    "runup angle step": (lambda e: pt.runup(e, rpm=[1000], angle_step_deg=7.0), True),
    "runup engine type": (lambda e: pt.runup(5, rpm=[1000], **QUICK), True),
    "runup engine missing": (lambda e: pt.runup(MISSING, rpm=[1000], **QUICK), True),
    "runup effect unknown": (lambda e: pt.runup(e, rpm=[1000], effects=["bogus"], **QUICK),
                             True),
    "runup effect string": (lambda e: pt.runup(e, rpm=[1000], effects="sensor_error:g1=1",
                                               **QUICK), False),
    "runup effect type": (lambda e: pt.runup(e, rpm=[1000], effects=[1.5], **QUICK), True),
    "runup sweep negative": (lambda e: pt.runup(e, rpm=[2000, 3000], sweep=-1), True),
    "runup sweep text": (lambda e: pt.runup(e, rpm=[2000, 3000], sweep="fast"), True),
    "runup balancers": (lambda e: pt.runup(e, rpm=[1000], balancers="no", **QUICK), True),
    # modes, static, excitation
    "modes engine type": (lambda e: pt.modes([1, 2]), True),
    "modes static flag": (lambda e: pt.modes(e, static="yes"), True),
    "static CLI string": (lambda e: pt.static(e, rpm="1000:6000:2500"), False),
    "static speed text": (lambda e: pt.static(e, rpm="1000;2000"), True),
    "static out of range": (lambda e: pt.static(e, rpm=[100]), True),
    "excitation rpm text": (lambda e: pt.excitation(e, rpm="3000"), False),
    "excitation rpm word": (lambda e: pt.excitation(e, rpm="fast"), True),
    "excitation no rpm": (lambda e: pt.excitation(e), True),
    "excitation load": (lambda e: pt.excitation(e, rpm=3000, load=-1), True),
    "excitation step": (lambda e: pt.excitation(e, rpm=3000, angle_step_deg="x"), True),
    # stiffness
    "stiffness CLI string": (lambda e: pt.stiffness(MOUNT, freq="1:400:1"), False),
    "stiffness negative freq": (lambda e: pt.stiffness(MOUNT, freq=[-1, 2]), True),
    "stiffness no freq": (lambda e: pt.stiffness(MOUNT, freq=[]), True),
    "stiffness freq type": (lambda e: pt.stiffness(MOUNT, freq={"a": 1}), True),
    "stiffness method": (lambda e: pt.stiffness(MOUNT, method="fft"), True),
    "stiffness mount None": (lambda e: pt.stiffness(None), True),
    "stiffness mount int": (lambda e: pt.stiffness(5), True),
    "stiffness missing": (lambda e: pt.stiffness(MISSING), True),
    "stiffness mount.dir": (lambda e: pt.stiffness("left.q", engine=e), True),
    "stiffness engine type": (lambda e: pt.stiffness("left.z", engine=5), True),
    "stiffness amplitude string": (lambda e: pt.stiffness(MOUNT, amplitude="0.05,0.1",
                                                          freq="1:20:1"), False),
    "stiffness amplitude zero": (lambda e: pt.stiffness(MOUNT, amplitude=[0.0]), True),
    "stiffness amplitude type": (lambda e: pt.stiffness(MOUNT, amplitude=["a"]), True),
    "stiffness set-up": (lambda e: pt.stiffness(MOUNT, engine_mass=100), True),
    "stiffness force text": (lambda e: pt.stiffness(MOUNT, engine_mass=100, force="x"), True),
    # fit_mount
    "fit_mount missing": (lambda e: pt.fit_mount(MISSING), True),
    "fit_mount lengths": (lambda e: pt.fit_mount([1, 2], [1]), True),
    "fit_mount model": (lambda e: pt.fit_mount([1, 2, 3], [1, 2, 3], model="x"), True),
    "fit_mount too few": (lambda e: pt.fit_mount([1, 2, 3], [1, 2, 3]), True),
    "fit_mount starts": (lambda e: pt.fit_mount(AMPLITUDES, starts=0), True),
    "fit_mount starts text": (lambda e: pt.fit_mount(AMPLITUDES, starts="many"), True),
    "fit_mount friction arrays": (lambda e: pt.fit_mount(np.arange(1.0, 20.0),
                                                         np.arange(1.0, 20.0) * 1e5,
                                                         friction=True), True),
    "fit_mount reference": (lambda e: pt.fit_mount(AMPLITUDES, reference=0.7e-3,
                                                   starts=1), True),
    # compare
    "compare missing": (lambda e: pt.compare(MISSING), True),
    "compare int": (lambda e: pt.compare(5), True),
    "compare simulated int": (lambda e: pt.compare(MEASURED, simulated=5), True),
    "compare engine and sim": (lambda e: pt.compare(MEASURED, engine=e, simulated="x.h5"),
                               True),
    "compare noise floor": (lambda e: pt.compare(MEASURED, engine=e, noise_floor=-1,
                                                 **QUICK), True),
    "compare solver": (lambda e: pt.compare(MEASURED, engine=e, solver=None), True),
    "compare step text": (lambda e: pt.compare(MEASURED, engine=e, step="a", **QUICK), True),
    # whatif
    "whatif scale string": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2",
                                                rpm="1000:2000:1000", workers=1), False),
    "whatif scale type": (lambda e: pt.whatif(e, scale=[1.2], rpm=[1000]), True),
    "whatif no variant": (lambda e: pt.whatif(e, rpm=[1000]), True),
    "whatif speed": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=[-5]), True),
    "whatif above range": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2",
                                               rpm=[100000]), True),
    "whatif solver": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=[1000],
                                          solver="x"), True),
    "whatif signal": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=[1000],
                                          signal="x"), True),
    "whatif measured type": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=[1000],
                                                 measured=5, workers=1), True),
    "whatif workers": (lambda e: pt.whatif(e, scale="left.z.stiffness=1.2", rpm=[1000],
                                           workers="two"), True),
    # track
    "track missing": (lambda e: pt.track(MISSING), True),
    "track raw type": (lambda e: pt.track(5), True),
    "track channel map type": (lambda e: pt.track(RAW, channel_map=5), True),
    "track orders text": (lambda e: pt.track(RAW, orders="a:b"), True),
    "track orders list": (lambda e: pt.track(RAW, orders=[2, "x"]), True),
    "track CLI orders": (lambda e: pt.track(RAW, orders="1,2,4"), False),
    "track rpm step": (lambda e: pt.track(RAW, rpm_step=-1), True),
    "track rpm step text": (lambda e: pt.track(RAW, rpm_step="fine"), True),
    "track method": (lambda e: pt.track(RAW, method="fft"), True),
    "track pulses": (lambda e: pt.track(RAW, tacho_column="tacho", pulses_per_rev="x"), True),
    # diagnose, synth
    "diagnose missing": (lambda e: pt.diagnose(MISSING, e), True),
    "diagnose measured type": (lambda e: pt.diagnose(3.5, e), True),
    "diagnose effect": (lambda e: pt.diagnose(MEASURED, e, effects="bogus"), True),
    "diagnose noise floor": (lambda e: pt.diagnose(MEASURED, e, noise_floor=-1), True),
    "diagnose scheduler": (lambda e: pt.diagnose(MEASURED, e, scheduler="x"), True),
    "diagnose budget": (lambda e: pt.diagnose(MEASURED, e, budget=0), True),
    "synth effect": (lambda e: pt.synth("bogus"), True),
    "synth seed": (lambda e: pt.synth([], -1), True),
    "synth seed text": (lambda e: pt.synth([], "a"), True),
    "synth none": (lambda e: pt.synth("none", 0), False),
    # report (every bad study file: tests/test_report.py)
    "report missing": (lambda e: pt.report(MISSING), True),
    "report type": (lambda e: pt.report(5), True),
    "report not toml": (lambda e: pt.report(MEASURED), True),
    "report out suffix": (lambda e: pt.report(str(EXAMPLES / "study.toml"), out="r.pdf"), True),
    # transient, read_manoeuvre
    "transient missing": (lambda e: pt.transient(MISSING, e), True),
    "transient int": (lambda e: pt.transient(5, e), True),
    "transient angle step": (lambda e: pt.transient(START, e, angle_step_deg="fine"), True),
    "transient angle step range": (lambda e: pt.transient(START, e, angle_step_deg=50), True),
    "transient seat": (lambda e: pt.transient(START, e, seat="seat_rail"), True),
    "transient seat type": (lambda e: pt.transient(START, e, seat=3), True),
    "transient trigger edge alone": (lambda e: pt.transient(START, e, trigger_edge="up"), True),
    "transient pulses alone": (lambda e: pt.transient(START, e, pulses_per_rev=60), True),
    "transient pulses": (lambda e: pt.transient(START, e, speed_from=MISSING, pulses_per_rev=0),
                         True),
    "transient average type": (lambda e: pt.transient(START, e, speed_average="yes"), True),
    "read_manoeuvre missing": (lambda e: pt.read_manoeuvre(MISSING), True),
    "read_manoeuvre engine file": (lambda e: pt.read_manoeuvre(ENGINES / "default.toml"), True),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_input_is_an_input_error(name, default_engine):
    call, must_fail = CASES[name]
    try:
        call(default_engine)
    except pt.InputError as err:
        assert "\n" not in str(err), err
        return
    assert not must_fail, f"{name}: no InputError"


def test_every_api_function_is_called_with_bad_input():
    called = {name.split()[0] for name in CASES}
    assert called == set(pt.API), set(pt.API) - called


# ------------------------------------------------------------------ the CLI's strings
def _cli_error(*args) -> str:
    res = CliRunner().invoke(main, list(args))
    assert res.exit_code == 1, res.output
    return res.output.strip().removeprefix("error: ")


@pytest.mark.parametrize("text", ["-100,1000", "abc", "2000,1000", "1000:900:10", ""])
def test_a_bad_speed_list_says_what_the_command_says(text, default_engine):
    with pytest.raises(pt.InputError) as err:
        pt.static(default_engine, rpm=text)
    assert str(err.value) == _cli_error("static", "--rpm", text)


@pytest.mark.parametrize("text", ["-1,5", "1:x:1", "5,3", "0:1e9:1"])
def test_a_bad_frequency_list_says_what_the_command_says(text):
    with pytest.raises(pt.InputError) as err:
        pt.stiffness(MOUNT, freq=text)
    assert str(err.value) == _cli_error("stiffness", MOUNT, "--freq", text)


def test_the_cli_strings_give_what_the_command_computes(default_engine):
    np.testing.assert_array_equal(pt.static(default_engine, rpm="1000:6000:2500").rpm,
                                  [1000.0, 3500.0, 6000.0])
    k = pt.stiffness(MOUNT, freq="1:400:1")
    np.testing.assert_array_equal(k.frequency_hz, np.arange(1.0, 401.0))
    assert k.to_text() == CliRunner().invoke(main, ["stiffness", MOUNT]).output
    run = pt.runup(default_engine, rpm="1000:6000:500", **QUICK)
    np.testing.assert_array_equal(run.rpm, np.arange(1000.0, 6001.0, 500.0))


@pytest.mark.slow
def test_fit_mount_fits_what_the_command_fits(tmp_path):
    """``pt.fit_mount(file)`` on data at several amplitudes is the command's joint fit."""
    fit = pt.fit_mount(AMPLITUDES)
    printed = CliRunner().invoke(main, ["fit-mount", AMPLITUDES, "--out",
                                        str(tmp_path / "f.toml")]).output
    timeless = fit.to_text().split("\n", 1)[1]           # the first line holds the time
    assert timeless in printed
    assert type(fit).__name__ == "AmplitudeFitResult"


# ------------------------------------------------------------------ properties
TEXT = st.one_of(st.text(alphabet="0123456789.:,-+e naif", max_size=24),
                 st.text(max_size=12))
NUMBERS = st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                             st.integers(-10**6, 10**6)), max_size=8)
ANYTHING = st.one_of(TEXT, NUMBERS, st.none(), st.booleans(), st.floats(),
                     st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
                     st.lists(st.text(max_size=4), max_size=3))


@settings(max_examples=300, deadline=None)
@given(ANYTHING)
def test_a_speed_list_is_checked_or_refused(value):
    try:
        rpm = arguments.speeds(value)
    except pt.InputError as err:
        assert err.key == "--rpm"
        return
    assert rpm.ndim == 1 and 1 <= rpm.size <= arguments.MAX_SPEEDS
    assert np.all(np.isfinite(rpm)) and np.all(rpm > 0) and np.all(np.diff(rpm) > 0)


@settings(max_examples=300, deadline=None)
@given(ANYTHING)
def test_a_frequency_list_is_checked_or_refused(value):
    try:
        f = arguments.frequencies(value)
    except pt.InputError as err:
        assert err.key == "--freq"
        return
    assert f.ndim == 1 and 1 <= f.size <= arguments.MAX_FREQUENCIES
    assert np.all(f >= 0) and np.all(f <= arguments.MAX_FREQUENCY_HZ)
    assert np.all(np.diff(f) > 0)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(TEXT, NUMBERS, st.floats(), st.none()))
def test_stiffness_takes_any_frequency_argument_or_refuses_it(value):
    try:
        k = pt.stiffness(MOUNT, freq=value)
    except pt.InputError:
        return
    assert np.all(np.isfinite(k.kcp))


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.floats(), st.integers(), TEXT, st.none(), st.booleans()))
def test_excitation_takes_any_speed_or_refuses_it(default_engine, value):
    try:
        result = pt.excitation(default_engine, rpm=value)
    except pt.InputError:
        return
    assert math.isfinite(result.excitation.rpm) and result.excitation.rpm > 0
