"""``powertrain report`` / ``pt.report`` (issue 39, item 1): the shipped study
``examples/study.toml`` (compare, diagnose, what-if, modes) becomes one self-contained HTML file
under 10 MB, summary first, a section per step, the commands and versions last; headless
Chromium opens it with no console error and no failed resource, its screenshot at 1280 px
shows the summary, and its print to PDF draws every figure on one page. Bad study files are
one line naming the file and the key, and write nothing."""

from __future__ import annotations

import hashlib
import io
import re
import shlex
from html import escape as html_text
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from headless_chromium import Chromium, images_per_page, installed_chromium

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

import powertrain as pt  # noqa: E402
from powertrain.cli import main  # noqa: E402
from powertrain.reporting.steps import STEPS  # noqa: E402
from powertrain.reporting.study import read_study  # noqa: E402

STUDY = EXAMPLES / "study.toml"
#: The issue's limit on the report file [bytes].
MAX_BYTES = 10_000_000
#: The window of the screenshot [CSS px].
WIDTH, HEIGHT = 1280, 900
#: The tests of the example's report (about 12 s of CPU to make it, figures mostly, and a
#: browser): with the slow tests, like the other many-panel figures; bad study files are quick.


def on_the_example(test):
    """A slow test of the example's report: all of them on one test process (the report is
    made once) and last (the ``browser`` marker, tests/conftest.py), so that the Chromium
    install .ci/run starts in the background has ended by then."""
    for mark in (pytest.mark.slow, pytest.mark.browser, pytest.mark.xdist_group("report")):
        test = mark(test)
    return test
NO_CHROMIUM = ("headless Chromium not installed (Debian: apt-get install chromium-headless-shell; .ci/run "
               "installs it where apt-get works): the browser checks of the report did not run")


@pytest.mark.xdist_group("report")
def test_the_report_tests_share_one_test_process(request):
    """Under ``--dist loadgroup`` (pyproject.toml) the example's report is made once, on the
    process that runs its group: pytest-xdist marks a grouped test by a ``@group`` suffix of
    its node id, which pytest 9.2 drops (pytest-dev/pytest-xdist#1386; hence pytest < 9.2)."""
    if request.config.getoption("loadgroup", False):
        assert request.node.nodeid.endswith("@report"), (
            f"xdist_group ignored on pytest {pytest.__version__} (pytest-xdist#1386)")


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """The shipped example study's report, written to a file."""
    out = tmp_path_factory.mktemp("report") / "report.html"
    return pt.report(STUDY, out=out), out


@pytest.fixture(scope="module")
def html(made) -> str:
    return made[1].read_text(encoding="utf-8")


@on_the_example
def test_one_self_contained_file_under_10_mb(made, html):
    rep, out = made
    assert out.stat().st_size < MAX_BYTES
    assert html == rep.to_html()
    assert "<script" not in html.lower()
    sources = re.findall(r'(?:src|href)="([^"]*)"', html)
    assert sources and all(s.startswith("data:") for s in sources), \
        [s[:40] for s in sources if not s.startswith("data:")]
    assert "default-src 'none'" in html           # the page itself forbids any other source
    assert html.count("<img ") == html.count("data:image/png;base64,") == 7


@on_the_example
def test_summary_first_then_a_section_per_step_then_reproduction(made, html):
    rep, _ = made
    ids = re.findall(r'<section[^>]* id="([a-z]+)"', html)
    assert ids == ["summary", "compare", "diagnose", "whatif", "modes", "transient",
                   "reproduce"]
    summary = html[html.index('id="summary"'):html.index('id="compare"')]
    assert rep.study.engine.name in summary and "SYNTHETIC" in summary
    assert html_text("VERDICT: " + rep.parts["diagnose"][0][1].verdict_text) in summary
    for name in ("study.toml", "measured-runup.csv", "whatif-variants.toml"):
        digest = hashlib.sha256((EXAMPLES / name).read_bytes()).hexdigest()
        assert digest in summary, name
    worst = rep.parts["compare"][0][1].worst_first()[0]
    top = re.search(r"Top gaps.*?<tbody><tr>(.*?)</tr>", summary, re.S).group(1)
    assert [worst.mount, worst.direction, worst.quantity] == re.findall(
        r"<td>([^<]*)</td>", top)[:3]


@on_the_example
def test_tables_are_worst_first(made, html):
    comp = made[0].parts["compare"][0][1]
    section = html[html.index('id="compare"'):html.index('id="diagnose"')]
    first = re.search(r"<tbody>(.*?)</tbody>", section, re.S).group(1)
    rms = [float(x) for x in re.findall(r"<tr>(?:<td>[^<]*</td>){3}<td[^>]*>\d+</td>"
                                        r"<td[^>]*>([\d.]+)</td>", first)]
    assert len(rms) == len(comp.channels) and rms == sorted(rms, reverse=True)


@on_the_example
def test_the_commands_shown_reproduce_the_numbers(made, html):
    """The compare command of the reproduction section prints the report's overall gap."""
    rep, _ = made
    repro = html[html.index('id="reproduce"'):]
    lines = [ln for ln in re.search(r"<pre>(.*?)</pre>", repro, re.S).group(1).splitlines()
             if ln.startswith("powertrain ")]
    assert lines[0] == rep.command()
    assert lines[0].startswith("powertrain report examples/study.toml --out ")
    words = shlex.split(next(ln for ln in lines if ln.startswith("powertrain compare")))
    run = CliRunner().invoke(main, words[1:])
    assert run.exit_code == 0, run.output
    gap = rep.parts["compare"][0][1].overall_rms_db
    assert f"overall RMS gap {gap:.2f} dB" in run.output
    for package in ("powertrain", "numpy", "scipy", "matplotlib", "Python"):
        assert f"<td>{package}</td>" in repro


@on_the_example
def test_the_report_follows_the_result_protocol(made, tmp_path):
    rep, out = made
    with pytest.raises(AttributeError):
        rep.body = ""
    text = rep.to_text()
    assert text.splitlines()[0].startswith("study: ") and "VERDICT: " in text
    assert rep.save(tmp_path / "again.html").read_text(encoding="utf-8") == rep.to_html()
    with pytest.raises(pt.InputError, match="writes"):
        rep.save(tmp_path / "r.pdf")
    fig = plt.figure()
    assert rep.plot(fig, step="modes") is fig
    plt.close(fig)
    with pytest.raises(pt.InputError, match="no step 'shaker'"):
        rep.plot(step="shaker")


@on_the_example
def test_results_render_in_jupyter(made):
    rep, _ = made
    results = [parts[0][1] for parts in rep.parts.values()] + [rep]
    for r in results:
        frag = r._repr_html_()
        assert frag.startswith("<style>") and "<table>" in frag, r
        assert re.match(r'<style>[^<]*</style><(div|main) class="pt-report">', frag), r
        assert "<img" not in frag or r is rep            # tables only: no figure is drawn
        assert "nan" not in re.sub(r"<[^>]*>", " ", frag).lower().split(), r


def test_a_result_renders_in_jupyter_without_nan_or_minus_zero():
    """The modes table as a notebook shows it: one row per mode, numbers right-aligned,
    signed energy shares that round to zero printed as 0.0."""
    frag = pt.modes(pt.read_engine())._repr_html_()
    assert frag.count("<tr><td class=\"num\">") == 6
    cells = re.findall(r"<td[^>]*>([^<]*)</td>", frag)
    assert "-0.0" not in cells and not any("nan" in c.lower() for c in cells)


# ------------------------------------------------------------------ in the browser
@pytest.fixture(scope="module")
def browser(made, tmp_path_factory):
    """What Chromium saw: problems while loading, the summary's boxes, a screenshot at
    1280 px, the PDF of the page; and the PDF of a page that cuts an image (the check's
    control)."""
    exe, why = installed_chromium()
    if exe is None:
        pytest.skip(f"{NO_CHROMIUM} ({why})")
    _, out = made
    control = tmp_path_factory.mktemp("control") / "cut.html"
    image = re.search(r'src="(data:image/png;base64,[^"]*)"', out.read_text()).group(1)
    control.write_text(f'<!DOCTYPE html><div style="height:800px"></div><img src="{image}" '
                       'style="display:block;width:600px;height:1500px">')
    with Chromium(exe) as b:
        b.open(out, WIDTH, HEIGHT)
        seen = {"problems": b.problems(out.resolve().as_uri()), "boxes": b.evaluate(
            "['#summary h2', '.verdict', '#summary table'].map(s => {const r = document."
            "querySelector(s).getBoundingClientRect(); return [r.left, r.top, r.right, "
            "r.bottom];})"), "width": b.evaluate("window.innerWidth"),
            "screenshot": b.screenshot(), "pdf": b.pdf()}
        b.media("print")
        seen["figures"] = b.evaluate(
            "[...document.querySelectorAll('figure')].map(f => [f.getBoundingClientRect()."
            "height, getComputedStyle(f).breakInside])")
        b.open(control)
        seen["control_pdf"] = b.pdf()
    return seen


@on_the_example
def test_chromium_opens_it_with_no_console_error_and_no_failed_resource(browser):
    assert browser["problems"] == []


@on_the_example
def test_the_screenshot_at_1280_px_shows_the_summary(browser, tmp_path):
    shot = mpimg.imread(io.BytesIO(browser["screenshot"]))
    (tmp_path / "summary.png").write_bytes(browser["screenshot"])
    assert browser["width"] == WIDTH and shot.shape[:2] == (HEIGHT, WIDTH)
    heading, verdict, _ = browser["boxes"]
    assert 0 <= heading[1] and verdict[3] <= HEIGHT, browser["boxes"]
    left, top, right, bottom = (int(round(v)) for v in verdict)
    ink = shot[top:bottom, left:right, :3].mean(axis=2) < 0.5      # dark text on the panel
    assert ink.mean() > 0.02, ink.mean()


@on_the_example
def test_the_pdf_print_cuts_no_figure(browser, made):
    """Printed to PDF (A4 pages), each image of the report is drawn on exactly one page, and
    every figure of the report is there. An image cut by a page break is drawn on each page
    it spans: the control page's image, taller than a page, is found on two. Chromium moves
    an image that fits a page whole to the next one, so what could still be cut is a figure
    taller than a page or a caption parted from its image: every figure (image and caption)
    is at most the A4 text height and ``break-inside: avoid``."""
    pages = images_per_page(browser["pdf"])
    drawn = [img for page in pages for img in page]
    assert len(drawn) == len(set(drawn)) == made[1].read_text().count("<img ")
    boxes = re.findall(rb"/MediaBox\s*\[\s*0 0 ([\d.]+) ([\d.]+)\s*\]", browser["pdf"])
    assert boxes and all(np.allclose([float(w), float(h)], [595.3, 841.9], atol=1.0)
                         for w, h in boxes), boxes[:3]
    control = [img for page in images_per_page(browser["control_pdf"]) for img in page]
    assert len(control) == 2 and len(set(control)) == 1, control       # one image, two pages
    text_height = (297 - 2 * 12) / 25.4 * 96                  # A4 less the @page margins [px]
    assert browser["figures"] and all(h <= text_height and how == "avoid"
                                      for h, how in browser["figures"]), browser["figures"]


# ------------------------------------------------------------------ bad study files
GOOD = {"measured": str(EXAMPLES / "measured-runup.csv")}


def _study(tmp_path, text: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(text.replace("MEASURED", GOOD["measured"]), encoding="utf-8")
    return path


BAD = {
    "unknown key": ('measured = "MEASURED"\nshaker = {}\n[modes]\n', "shaker",
                    "unknown key"),
    "both measured and plan": ('measured = "MEASURED"\nplan = "p.toml"\n[modes]\n', "plan",
                               "not both"),
    "missing measured file": ('measured = "nope.csv"\n[compare]\n', "measured", "no such file"),
    "compare without measurement": ("[compare]\n", "compare", "needs a measurement"),
    "solver": ('measured = "MEASURED"\n[compare]\nsolver = "exact"\n', "compare.solver",
               "not one of"),
    "step not a number": ('measured = "MEASURED"\n[compare]\nstep = "fast"\n', "compare.step",
                          "expected"),
    "step beyond the range": ('measured = "MEASURED"\n[compare]\nstep = 1e7\n', "compare.step",
                              "rpm"),
    "effect": ('measured = "MEASURED"\n[diagnose]\neffects = ["gremlins"]\n', "diagnose.effects",
               "unknown effect"),
    "pairs": ('measured = "MEASURED"\n[diagnose]\npairs = "no"\n', "diagnose.pairs",
              "true or false"),
    "whatif spec": ('[whatif]\nscale = ["left.q.stiffness=1.2"]\n', "whatif.scale", "q"),
    "whatif variants file": ('[whatif]\nvariants = "v.toml"\n', "whatif.variants",
                             "no such file"),
    "whatif speeds": ('[whatif]\nscale = "left.z.stiffness=1.2"\nfrom = 3000\nto = 2000\n',
                      "whatif.to", "below"),
    "modes static": ("[modes]\nstatic = 1\n", "modes.static", "true or false"),
    "no manoeuvre": ("[transient]\nmanoeuvres = []\n", "transient.manoeuvres", "at least one"),
    "manoeuvre file": ('[transient]\nmanoeuvres = "nope.toml"\n', "transient.manoeuvres",
                       "no such file"),
    "transient key": ('[transient]\nmanoeuvres = "MEASURED"\nspeed = 1\n', "transient.speed",
                      "unknown key"),
    "step not a table": ("modes = 1\n", "modes", "expected a table"),
    "no step": ('measured = "MEASURED"\n', "steps", "no step"),
    "noise floor unit": ('noise_floor = {value = 1, unit = "kg"}\n[modes]\n', "noise_floor",
                         ""),
    "title": ("title = 3\n[modes]\n", "title", "string"),
    "engine file": ('engine = "nope.toml"\n[modes]\n', "engine", "no such file"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_bad_study_file_is_one_line_naming_file_and_key_and_writes_nothing(name, tmp_path):
    text, key, words = BAD[name]
    study = _study(tmp_path, text)
    out = tmp_path / "r.html"
    out.write_text("an older report\n")
    run = CliRunner().invoke(main, ["report", str(study), "--out", str(out)])
    assert run.exit_code == 1, run.output
    line = run.output.strip()
    assert "\n" not in line and line.startswith(f"error: {study}"), line
    assert f"key '{key}" in line and words in line, line
    assert out.read_text() == "an older report\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html", "study.toml"]


def test_not_toml_and_a_bad_output_are_refused_before_any_work(tmp_path):
    study = _study(tmp_path, 'measured = "MEASURED"\n[modes]\n')
    for args, words in (([str(study), "--out", str(tmp_path / "r.pdf")], "HTML file"),
                        ([str(tmp_path / "x.csv"), "--out", str(tmp_path / "r.html")],
                         "TOML file"),
                        ([str(tmp_path), "--out", str(tmp_path / "r.html")], "")):
        run = CliRunner().invoke(main, ["report", *args])
        assert run.exit_code != 0 and words in run.output, run.output
    (tmp_path / "broken.toml").write_text("[modes\n")
    run = CliRunner().invoke(main, ["report", str(tmp_path / "broken.toml"), "--out",
                                    str(tmp_path / "r.html")])
    assert run.exit_code == 1 and "not valid TOML" in run.output, run.output
    assert not (tmp_path / "r.html").exists()


def test_paths_are_relative_to_the_study_file_and_a_plan_names_its_runs(tmp_path):
    (tmp_path / "sub").mkdir()
    study = tmp_path / "sub" / "s.toml"
    study.write_text(f'plan = "{EXAMPLES / "plan.toml"}"\nengine = "../e/x.toml"\n[compare]\n')
    with pytest.raises(pt.InputError, match=r"key 'engine': no such file: .*e/x\.toml"):
        read_study(study)
    study.write_text(f'plan = "{EXAMPLES / "plan.toml"}"\n[compare]\n[modes]\n')
    s = read_study(study)
    assert [label for label, *_ in s.runs()] == ["run 1: plan-full-load.csv (load 1)",
                                                 "run 2: plan-part-load.csv (load 0.4)"]
    assert [role for role, _ in s.files][-3:] == ["plan", "plan run 1", "plan run 2"]
    lines = STEPS["compare"].commands(s, s.steps["compare"])
    assert lines[0].startswith("powertrain compare ") and "plan-full-load.csv" in lines[0]
    assert lines[1].startswith("# run 2") and "run.engine(engine)" in lines[1]
