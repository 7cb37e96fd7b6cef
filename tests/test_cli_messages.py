"""Help texts and messages say what the commands do (issue 18, "Help and messages"):
defaults shown as values, names listed from their registries, one name per effect, the
files written named, and SYNTHETIC data labelled in every CSV that stands in for a
measurement."""

from __future__ import annotations

import warnings
from pathlib import Path

import click
import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.cli.common import quiet_option
from powertrain.effects import EFFECTS
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.measured import read_measured
from powertrain.workflows.fitting import DEFAULT_SEED, DEFAULT_STARTS
from powertrain.workflows.synth import TRUTH_ALIASES, TRUTH_EFFECTS, make_case

MOUNT = Path(DEFAULT_ENGINE_PATH).parents[1] / "mounts" / "hydraulic-engine-mount-z.toml"
QUICK = ["--from", "1000", "--to", "2000", "--step", "500", "--solver", "harmonic"]


def invoke(*args):
    res = CliRunner().invoke(main, [str(a) for a in args])
    return res, " ".join(res.output.split())          # output with the wrapping undone


def test_fit_mount_help_shows_default_values():
    _, text = invoke("fit-mount", "--help")
    assert "powertrain.workflows.fitting" not in text
    assert f"[default: {DEFAULT_STARTS}]" in text and f"[default: {DEFAULT_SEED}]" in text


def test_diagnose_and_synth_help_list_their_registries():
    _, text = invoke("diagnose", "--help")
    for name in EFFECTS:
        assert name in text, name
    _, text = invoke("synth", "--help")
    for name in list(TRUTH_EFFECTS) + list(TRUTH_ALIASES):
        assert name in text, name


def test_synth_names_the_balancer_effect_as_the_diagnosis_does():
    """One name (balancer_error) in synth and diagnose; the former synth name is an alias
    that makes the identical case."""
    assert TRUTH_EFFECTS["balancer_error"] == "balancer_error" and "balancer_error" in EFFECTS
    assert "balancer_shafts" not in TRUTH_EFFECTS
    engine = read_engine(DEFAULT_ENGINE_PATH)
    rpm = np.arange(1000.0, 3001.0, 250.0)
    new = make_case(engine, ["balancer_error"], 5, rpm=rpm)
    old = make_case(engine, ["balancer_shafts"], 5, rpm=rpm)
    assert [n for n, _ in old.truth] == ["balancer_error"]
    assert new.csv_text() == old.csv_text()


def test_compare_and_runup_help_say_what_they_do():
    _, text = invoke("compare", "--help")
    assert "one column per quantity" in text and "synthesis, 2nd, 4th order columns" not in text
    _, text = invoke("runup", "--help")
    assert "q uantity" not in text and "velocity_rms_mm_per_s" in text
    assert "undamped, at the mounts' static stiffness" in text


def test_stiffness_plot_prints_a_summary_and_the_path(tmp_path):
    png = tmp_path / "k.png"
    res, text = invoke("stiffness", MOUNT, "--plot", png)
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert len(lines) <= 5 and lines[-1] == f"wrote {png}"
    assert "400 frequencies 1..400 Hz" in text and "loss angle max" in text
    assert png.stat().st_size > 0
    res, _ = invoke("stiffness", MOUNT, "--plot", png, "--format", "table")
    assert len(res.output.splitlines()) > 400           # asked for: every row
    res, _ = invoke("stiffness", MOUNT, "--plot", png, "--format", "csv")
    assert res.stdout.startswith("frequency_hz,") and "wrote" not in res.stdout
    assert res.stderr.strip() == f"wrote {png}"         # CSV on stdout stays clean


def test_fit_mount_names_the_plot_it_wrote(tmp_path):
    k = tmp_path / "k.csv"
    res, _ = invoke("stiffness", MOUNT, "--freq", "1:100:3", "--format", "csv")
    k.write_text(res.output)
    out, png = tmp_path / "fit.toml", tmp_path / "fit.png"
    res, _ = invoke("fit-mount", k, "--model", "kelvin-voigt", "--starts", "2", "--out", out,
                    "--plot", png)
    assert res.exit_code == 0, res.output
    assert f"wrote {out}, {png}" in res.output and png.stat().st_size > 0


@pytest.mark.parametrize("effect", [None, "amplitude_stiffness:exponent=0.2"])
def test_runup_csv_with_effects_is_labelled_synthetic_with_provenance(tmp_path, effect):
    """With --effect the run-up CSV stands in for a measurement: SYNTHETIC label and
    provenance, as `synth` and `track` label theirs; a plain run-up CSV starts with its
    header as before."""
    csv = tmp_path / "r.csv"
    res, _ = invoke("runup", *QUICK, "--csv", csv, "--quiet",
                    *(["--effect", effect] if effect else []))
    assert res.exit_code == 0, res.output
    head = csv.read_text().splitlines()[:3]
    assert read_measured(csv).synthetic is bool(effect)
    if not effect:
        assert head[0].startswith("mount,direction,quantity,rpm,")
        return
    assert head[0].startswith("# SYNTHETIC: simulated run-up with added effects "
                              "amplitude_stiffness(exponent=0.2, damping_exponent=1)")
    assert head[1].startswith("# provenance: powertrain ") and "$ powertrain runup" in head[1]
    assert "--effect amplitude_stiffness:exponent=0.2" in head[1]


def test_quiet_means_the_same_on_every_command():
    """Every command has --quiet, with one help text: only errors are printed."""
    from powertrain.cli.common import QUIET_HELP
    from powertrain.cli.group import COMMANDS

    ctx = main.make_context("powertrain", ["--help"], resilient_parsing=True)
    for name in sorted(COMMANDS):
        cmd = main.get_command(ctx, name)
        quiet = [p for p in cmd.params if p.name == "quiet"]
        assert quiet and quiet[0].help == QUIET_HELP, name


def test_static_excitation_and_modes_name_the_files_they_wrote(tmp_path):
    """The commands that did not say what they wrote (issue 39) end with ``wrote ...``;
    with --quiet they print nothing and still write."""
    runs = {("static", "--rpm", "1000", "--json", tmp_path / "s.json"): ["s.json"],
            ("excitation", "--rpm", "3000", "--step", "4", "--csv", tmp_path / "e.csv"):
                ["e.csv"],
            ("modes", "--static", "--json", tmp_path / "m.json", "--plot", tmp_path / "m.png"):
                ["m.json", "m.png"]}
    for args, files in runs.items():
        res, _ = invoke(*args)
        assert res.exit_code == 0, res.output
        last = res.output.strip().splitlines()[-1]
        assert last == "wrote " + ", ".join(str(tmp_path / f) for f in files), last
    (tmp_path / "s.json").unlink()
    res, _ = invoke("static", "--rpm", "1000", "--json", tmp_path / "s.json", "--quiet")
    assert res.exit_code == 0 and res.output == "", res.output
    assert (tmp_path / "s.json").is_file()


def test_quiet_silences_warnings_and_only_while_the_command_runs():
    """--quiet: nothing but errors, so a Python warning raised by the command is not shown;
    without it the warning reaches stderr; the filter ends with the command."""
    @click.command()
    @quiet_option
    def warns(quiet):
        warnings.warn("a questionable result", stacklevel=2)

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        quiet = CliRunner().invoke(warns, ["--quiet"])
        loud = CliRunner().invoke(warns, [])
    assert quiet.exit_code == loud.exit_code == 0
    assert [str(w.message) for w in seen] == ["a questionable result"]


def test_the_package_s_warnings_print_as_one_line_on_every_command():
    """A warning class of the package (here the transient's stretch rule) prints as
    ``warning: ...`` on one line, whatever command raises it; --quiet prints nothing."""
    from powertrain.solvers.transient import StretchRuleWarning

    @click.command()
    @quiet_option
    def warns(quiet):
        warnings.warn("left.z: static curve and amplitude law together", StretchRuleWarning,
                      stacklevel=2)

    loud, quiet = CliRunner().invoke(warns, []), CliRunner().invoke(warns, ["--quiet"])
    assert loud.exit_code == quiet.exit_code == 0
    assert loud.stderr == "warning: left.z: static curve and amplitude law together\n"
    assert not quiet.stderr
