"""Every shell command shown in README.md and docs/**/*.md runs (issue 10: "every command
shown in README and docs/ runs in a test, so no figure or flag can go stale again").

The rules a docs author must know are in docs/extending.md, "Writing docs"; in short:

* ```bash blocks are executed, every other fence (```text for output, ```toml, ```python)
  is not; ```sh, ```shell, ```console and ```zsh are refused so that no command escapes;
  ```python blocks must compile.
* README.md's commands run in the wheel test (tests/test_package.py: built, installed in a
  fresh venv, every command in an empty folder, the same rules), not here again.
* Each other doc file runs in its own empty temporary folder. On the developer pages
  (``docs/validation*``) the repository's ``scripts/`` is reachable by that name (a symbolic
  link); the user pages (the guide, the reference) run only what a wheel install and
  ``powertrain examples`` give, so a script call there fails. A page that runs
  ``powertrain examples DIR`` makes its own copy of the shipped files, as a user after a wheel
  install does; on any other page ``examples/``, ``engines/`` and ``mounts/`` are linked too.
  Its commands run in order, so a later block may read what an earlier one wrote.
  ``powertrain`` and ``python`` are the interpreter under test; a ``powertrain`` command
  that needs no shell (no pipe, redirection, glob or variable) runs in the test's own process
  through click's test runner, as the console script would run it; any other command runs in
  ``bash``, where ``powertrain`` is ``python -m powertrain.cli``.
* One command is one line (backslash continuations joined); comment lines are dropped.
* In a ``&&`` chain, install steps (``python3 -m venv``, ``. .venv/bin/activate``,
  ``source .venv/bin/activate``, ``pip install``) and the test-suite command
  (``python -m pytest``) are not run: the environment under test is installed already and
  CI runs the suite itself (running it here would recurse). The rest of the chain runs.
  Each skipped part is reported as a skipped test naming file, line and rule.
* A command must exit 0 within ``TIMEOUT_S`` (a command whose trailing comment says
  ``# exits 1`` must exit 1 with exactly one line on stderr), and every file it names as an
  output (``--out``, ``--csv``, ``--plot``, ``--json``, ``--truth``, ``--report``,
  ``--target-out``, ``--target-plot``, ``> FILE``) must exist afterwards, outside the
  repository (docs commands never write into the source tree).
* A ```text block is a *shown output* when the fence before it is a ```bash block, only
  prose (no heading) stands between, and its first line does not start with ``$ `` (a
  ``$ COMMAND`` block is a transcript of a full run that is not repeated here). A shown
  output must match what the bash block's commands printed (their stdout, or else their
  stderr, in order): its lines are an excerpt of consecutive printed lines; a line that is
  just ``...`` stands for any number of printed lines, and ``...`` inside a line for any
  text; whitespace runs are equal whatever their length; every number within
  ``NUMBER_REL_TOL`` relative or one unit of its last shown digit, whichever is larger.

Failures name the doc file and line.
"""

from __future__ import annotations

import difflib
import os
import re
import shlex
import signal
import subprocess
import sys
import textwrap
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import pytest

import powertrain

ROOT = Path(__file__).resolve().parents[1]
#: Folders of the repository reachable by their relative names from the commands of the
#: developer pages (:data:`DEVELOPER_PAGES`).
LINKED = ("scripts",)
#: Pages for developers (validation figures, printed by scripts of a source checkout).
DEVELOPER_PAGES = ("docs/validation",)
#: Linked too, unless the page copies the shipped files itself with ``powertrain examples``.
SHIPPED = ("examples", "engines", "mounts")
COPIES_SHIPPED = re.compile(r"(^|&&\s*)powertrain examples\b")
#: A number in a shown output matches the printed one within this relative tolerance or one
#: unit of its last shown digit, whichever is larger.
NUMBER_REL_TOL = 0.01
ELISION = "..."
TRANSCRIPT = "$ "
#: A command shown in the docs should take <= ~20 s; this is the hard stop (a loaded 2-core
#: CI machine runs several times slower than the figures quoted in the docs).
TIMEOUT_S = 120.0
#: Fences whose content is executed, and shell fences that are refused (use ```bash).
RUN_FENCE = "bash"
REFUSED_FENCES = ("sh", "shell", "console", "zsh")
#: Options whose value is a file (or folder) the command writes.
OUTPUT_OPTIONS = ("--out", "--csv", "--plot", "--json", "--truth", "--report", "--target-out",
                  "--target-plot")
#: Parts of a ``&&`` chain that are not run (install steps and the test suite itself).
SKIP_RULES = (
    (re.compile(r"^python3? -m venv\b"), "install step (virtual environment)"),
    (re.compile(r"^(\.|source) \S*activate$"), "install step (virtual environment)"),
    (re.compile(r"^(python3? -m )?pip install\b"), "install step (pip install)"),
    (re.compile(r"^python3? -m pytest\b"), "the test suite itself (CI runs it; would recurse)"),
)
EXPECT_EXIT_1 = re.compile(r"#\s*exits? 1\b")


@dataclass
class Command:
    """One command of a doc file: the text to run and the parts skipped by rule."""

    doc: str                  # path relative to the repository
    line: int                 # 1-based line of the command's first line
    text: str                 # what runs ("" when every part was skipped)
    skipped: list = field(default_factory=list)   # [(part, reason)]
    expect_exit: int = 0
    block: int = 0            # first line of its ```bash block

    @property
    def where(self) -> str:
        return f"{self.doc}:{self.line}"


def doc_files() -> list:
    """README.md and every Markdown file under docs/, in a fixed order."""
    return [ROOT / "README.md"] + sorted((ROOT / "docs").rglob("*.md"))


def _split_outside_quotes(text: str, sep: str) -> list:
    """Split ``text`` at ``sep`` where it stands outside single and double quotes."""
    parts, quote, start, i = [], None, 0, 0
    while i < len(text):
        ch = text[i]
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif text.startswith(sep, i):
            parts.append(text[start:i])
            start = i + len(sep)
            i += len(sep)
            continue
        i += 1
    parts.append(text[start:])
    return parts


def strip_comment(text: str) -> tuple:
    """(command, comment): a ``#`` after whitespace outside quotes starts a comment."""
    quote = None
    for i, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or text[i - 1].isspace()):
            return text[:i].rstrip(), text[i:]
    return text.rstrip(), ""


def skip_reason(part: str):
    """The rule that skips one part of a ``&&`` chain, or None if it runs."""
    for pattern, reason in SKIP_RULES:
        if pattern.search(part.strip()):
            return reason
    return None


@dataclass
class Fence:
    """One fenced block of a Markdown file."""

    kind: str                 # the fence's language ("" if none)
    start: int                # 1-based line of its first content line
    lines: list
    after_heading: bool       # a heading stands between the previous fence and this one


def fenced_blocks(path: Path, root: Path = ROOT) -> list:
    """Every fenced block of a Markdown file, in order (refused shell fences raise)."""
    blocks, current, heading = [], None, False
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        stripped = raw.strip()
        if stripped.startswith("```"):
            if current is None:
                kind = stripped[3:].strip().split()[0] if stripped[3:].strip() else ""
                if kind in REFUSED_FENCES:
                    raise AssertionError(f"{path.relative_to(root)}:{number}: ```{kind} block; "
                                         "shell commands go in ```bash (docs/extending.md)")
                current = Fence(kind, number + 1, [], heading)
            else:
                blocks.append(current)
                current, heading = None, False
        elif current is not None:
            current.lines.append(raw)
        elif stripped.startswith("#"):
            heading = True
    return blocks


def bash_blocks(path: Path, root: Path = ROOT) -> list:
    """[(first line number, [lines])] of the ```bash blocks of a Markdown file."""
    return [(b.start, b.lines) for b in fenced_blocks(path, root) if b.kind == RUN_FENCE]


@dataclass
class Shown:
    """A ```text block showing what the ```bash block before it printed."""

    doc: str
    line: int                 # first line of the shown text
    block: int                # first line of the bash block
    lines: list


def shown_outputs(path: Path, root: Path = ROOT) -> list:
    """The shown outputs of a Markdown file (rule in the module docstring)."""
    doc, blocks = str(path.relative_to(root)), fenced_blocks(path, root)
    return [Shown(doc, here.start, before.start, here.lines)
            for before, here in zip(blocks, blocks[1:])
            if before.kind == RUN_FENCE and here.kind == "text" and not here.after_heading
            and here.lines and not here.lines[0].startswith(TRANSCRIPT)]


def commands_of(path: Path, root: Path = ROOT) -> list:
    """The commands of every ```bash block of ``path``, continuations joined."""
    doc = str(path.relative_to(root))
    out = []
    for start, lines in bash_blocks(path, root):
        pending, first = "", None
        for offset, raw in enumerate(lines):
            text = raw.strip()
            if not pending and (not text or text.startswith("#")):
                continue
            first = start + offset if not pending else first
            if text.endswith("\\"):
                pending += text[:-1].rstrip() + " "
                continue
            out.append(_command(doc, first, pending + text, start))
            pending = ""
        assert not pending, f"{doc}:{first}: block ends inside a continued line"
    return out


def _command(doc: str, line: int, text: str, block: int = 0) -> Command:
    body, comment = strip_comment(text)
    run, skipped = [], []
    for part in _split_outside_quotes(body, "&&"):
        reason = skip_reason(part)
        (skipped.append((part.strip(), reason)) if reason else run.append(part.strip()))
    return Command(doc, line, " && ".join(run), skipped,
                   1 if EXPECT_EXIT_1.search(comment) else 0, block)


def output_paths(command: str) -> list:
    """Files and folders a command names as its outputs (options and ``>`` redirection)."""
    paths = []
    for part in _split_outside_quotes(command, "&&"):
        for segment in _split_outside_quotes(part, "|"):
            try:
                tokens = shlex.split(segment)
            except ValueError:
                continue
            for i, tok in enumerate(tokens):
                name, eq, value = tok.partition("=")
                if name in OUTPUT_OPTIONS and eq:
                    paths.append(value)
                elif tok in OUTPUT_OPTIONS + (">", ">>") and i + 1 < len(tokens):
                    paths.append(tokens[i + 1])
                elif tok.startswith(">") and tok.lstrip(">"):
                    paths.append(tok.lstrip(">"))
    return [p for p in paths if not p.startswith("/dev/")]


ALL_COMMANDS = {str(p.relative_to(ROOT)): commands_of(p) for p in doc_files()}
SHOWN = {str(p.relative_to(ROOT)): shown_outputs(p) for p in doc_files()}
#: README.md's commands run after a wheel install (tests/test_package.py), once.
RUN_BY_WHEEL_TEST = "README.md"
RUN_FILES = [doc for doc, cmds in ALL_COMMANDS.items()
             if any(c.text for c in cmds) and doc != RUN_BY_WHEEL_TEST]
SKIPPED_PARTS = [(c, part, reason) for cmds in ALL_COMMANDS.values() for c in cmds
                 for part, reason in c.skipped]


@pytest.fixture(scope="module")
def shim_bin(tmp_path_factory) -> Path:
    """A folder with ``python``, ``python3`` and ``powertrain`` of the interpreter under test
    (``powertrain``: ``python -m powertrain.cli``, started afresh for each command)."""
    bin_dir = tmp_path_factory.mktemp("docs-bin")
    exe = shlex.quote(sys.executable)
    for name, target in (("python", exe), ("python3", exe),
                         ("powertrain", f"{exe} -m powertrain.cli")):
        script = bin_dir / name
        script.write_text(f'#!/bin/sh\nexec {target} "$@"\n')
        script.chmod(0o755)
    return bin_dir


def doc_environment(bin_dir: Path) -> dict:
    env = dict(os.environ)
    src = str(Path(powertrain.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src] + [p for p in [env.get("PYTHONPATH")] if p])
    env["PATH"] = os.pathsep.join([str(bin_dir), env.get("PATH", "")])
    env["MPLBACKEND"] = "Agg"
    return env


#: Characters that make a command line need a shell (pipes, redirection, globs, variables).
SHELL_SYNTAX = re.compile(r"[|<>;&$`*?~(){}\[\]\\]")


def in_process_argvs(text: str):
    """The argument lists of ``text`` when it is ``powertrain ARGS`` (or an ``&&`` chain of
    such) with nothing a shell must expand, else None."""
    argvs = []
    for part in _split_outside_quotes(text, "&&"):
        if SHELL_SYNTAX.search(part):
            return None
        try:
            tokens = shlex.split(part)
        except ValueError:
            return None
        if not tokens or tokens[0] != "powertrain":
            return None
        argvs.append(tokens[1:])
    return argvs or None


class _Timeout(Exception):
    pass


def _raise_timeout(signum, frame):
    raise _Timeout


def run_in_process(argvs: list, cwd: Path) -> tuple:
    """``(exit code, stdout, stderr)`` of ``powertrain ARGS`` run in this process, as the console
    script runs it (click's test runner: its own streams, a fresh set of warning filters as a
    new interpreter has them, ``cwd`` as the working folder); a chain stops at its first
    failure. Saves an interpreter start and the imports per command (about 1.3 CPU-s each);
    commands that need a shell still run in one (:func:`run_command`)."""
    from click.testing import CliRunner

    from powertrain.cli.group import main
    code, out, err = 0, "", ""
    here = os.getcwd()
    old_alarm = signal.signal(signal.SIGALRM, _raise_timeout)
    signal.setitimer(signal.ITIMER_REAL, TIMEOUT_S)
    try:
        os.chdir(cwd)
        for argv in argvs:
            with warnings.catch_warnings():
                warnings.resetwarnings()
                for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning,
                                 ResourceWarning):
                    warnings.simplefilter("ignore", category)
                result = CliRunner().invoke(main, argv, prog_name="powertrain")
            if isinstance(result.exception, _Timeout):
                raise _Timeout
            if result.exception is not None and not isinstance(result.exception, SystemExit):
                raise result.exception
            out, err, code = out + result.stdout, err + result.stderr, result.exit_code
            if code:
                break
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old_alarm)
        os.chdir(here)
    return code, out, err


def run_command(cmd: Command, cwd: Path, env: dict, printed: list | None = None,
                in_process: bool = True):
    """Run one command; the failure message (None if it passed). ``powertrain`` commands that
    need no shell run in this process (:func:`run_in_process`) unless ``in_process`` is
    False (the wheel test: the installed console script, not this source tree), others in
    ``bash``, whose whole process group is killed on timeout. ``printed`` (if given)
    receives ``(stdout, stderr)``."""
    argvs = in_process_argvs(cmd.text) if in_process else None
    if argvs is not None:
        try:
            returncode, out, err = run_in_process(argvs, cwd)
        except _Timeout:
            return _timed_out(cmd)
        return _judge(cmd, cwd, returncode, out, err, printed)
    proc = subprocess.Popen(["bash", "-c", "set -o pipefail\n" + cmd.text], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return _timed_out(cmd)
    return _judge(cmd, cwd, proc.returncode, out, err, printed)


def _timed_out(cmd: Command) -> str:
    return (f"{cmd.where}: `{cmd.text}` did not finish within {TIMEOUT_S:.0f} s (docs "
            "commands must be quick: show the quick form, quote the full one in a "
            "```text block)")


def _judge(cmd: Command, cwd: Path, returncode: int, out: str, err: str, printed):
    """The failure message of a finished command (exit code, stderr, outputs), else None."""
    if printed is not None:
        printed.append((out, err))
    if returncode != cmd.expect_exit:
        tail = "\n".join((out + err).strip().splitlines()[-15:])
        return (f"{cmd.where}: `{cmd.text}` exited {returncode} (expected "
                f"{cmd.expect_exit}):\n{tail}")
    if cmd.expect_exit and len(err.strip().splitlines()) != 1:
        return f"{cmd.where}: `{cmd.text}`: expected one line on stderr, got:\n{err}"
    return None if cmd.expect_exit else check_outputs(cmd, cwd)


def check_outputs(cmd: Command, cwd: Path):
    """Failure message if a named output is missing or lies in the repository, else None."""
    for name in output_paths(cmd.text):
        path = cwd / name
        if not path.exists():
            return f"{cmd.where}: `{cmd.text}` did not write {name}"
        if ROOT in path.resolve().parents:
            return (f"{cmd.where}: `{cmd.text}` writes {name} into the repository "
                    f"({path.resolve()})")
    return None


NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"


def line_pattern(shown: str) -> tuple:
    """(regex, [shown numbers]) of one shown line: ``...`` any text, whitespace runs
    ``\\s+``, numbers captured."""
    regex, numbers = [], []
    for k, literal in enumerate(shown.strip().split(ELISION)):
        if k:
            regex.append(".*?")
        for token in re.findall(rf"(?<![\w.]){NUMBER}|\s+|\w+|.", literal):
            if re.fullmatch(NUMBER, token):
                regex.append(rf"(?<![\w.])({NUMBER})")
                numbers.append(token)
            else:
                regex.append(r"\s+" if token.isspace() else re.escape(token))
    return "".join(regex), numbers


def numbers_agree(shown: str, printed: str) -> bool:
    """Within NUMBER_REL_TOL relative or one unit of the last shown digit."""
    mantissa = re.split("[eE]", shown)[0]
    digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(re.split("[eE]", shown)[1]) if re.search("[eE]", shown) else 0
    unit = 10.0 ** (exponent - digits)
    tol = max(NUMBER_REL_TOL * abs(float(shown)), unit * (1 + 1e-9))
    return abs(float(printed) - float(shown)) <= tol


def line_matches(shown: str, printed: str) -> bool:
    regex, numbers = line_pattern(shown)
    found = re.fullmatch(regex, printed.strip())
    return bool(found) and all(numbers_agree(a, b) for a, b in zip(numbers, found.groups()))


def match_shown(shown: list, printed: list):
    """None if the shown lines are an excerpt of the printed ones (``...`` lines skip any
    number of lines), else the first shown line that has no match where it should."""
    segments, current = [], []
    for line in shown:
        if line.strip() == ELISION:
            segments.append(current)
            current = []
        else:
            current.append(line)
    segments.append(current)
    cursor = 0
    for segment in (s for s in segments if s):
        for at in range(cursor, len(printed) - len(segment) + 1):
            if all(line_matches(a, b) for a, b in zip(segment, printed[at:])):
                cursor = at + len(segment)
                break
        else:
            return _first_unmatched(segment, printed[cursor:])
    return None


def _first_unmatched(segment: list, printed: list) -> str:
    """The first line of ``segment`` that matches no printed line, with the nearest one."""
    lonely = [a for a in segment if not any(line_matches(a, b) for b in printed)]
    if not lonely:
        return f"lines from `{segment[0].strip()}` on are not consecutive printed lines"
    near = difflib.get_close_matches(lonely[0].strip(), [b.strip() for b in printed], 1, 0)
    return f"shown `{lonely[0].strip()}`; nearest printed `{near[0] if near else '(nothing)'}`"


def check_shown(shown: Shown, printed: list):
    """Failure message if a shown output matches neither the stdout nor the stderr."""
    streams = ["".join(out for out, _ in printed), "".join(err for _, err in printed)]
    misses = [match_shown(shown.lines, stream.splitlines()) for stream in streams]
    if all(misses):
        return (f"{shown.doc}:{shown.line}: the ```text block does not show what the commands "
                f"of {shown.doc}:{shown.block} printed: {misses[0]} (rule: docs/extending.md, "
                "'Writing docs')")
    return None


def run_doc(doc: str, folder: Path, env: dict):
    """Run a doc file's commands in order in ``folder`` and compare its shown outputs; the
    first failing command, or every shown output that does not match (None if all pass)."""
    commands = ALL_COMMANDS[doc]
    copies = any(COPIES_SHIPPED.search(c.text) for c in commands)
    linked = LINKED if doc.startswith(DEVELOPER_PAGES) else ()
    for name in linked + (() if copies else SHIPPED):
        (folder / name).symlink_to(ROOT / name, target_is_directory=True)
    printed = {}
    for cmd in commands:
        failure = (run_command(cmd, folder, env, printed.setdefault(cmd.block, []))
                   if cmd.text else None)
        if failure:
            return failure
    misses = [check_shown(shown, printed.get(shown.block, [])) for shown in SHOWN[doc]]
    return "\n".join(m for m in misses if m) or None


# ----------------------------------------------------------------------------- the parser
def test_parser_joins_continuations_drops_comments_and_applies_the_skip_rule(tmp_path):
    doc = tmp_path / "page.md"
    doc.write_text("text\n```bash\n# a comment\npowertrain stiffness m.toml \\\n"
                   "    --freq 5,10 --format csv > k.csv   # trailing\n\n"
                   "python3 -m venv .venv && . .venv/bin/activate && pip install -e . && "
                   "powertrain runup --csv r.csv\n"
                   "powertrain runup --angle-step 0  # exits 1\n```\n"
                   "```text\npowertrain not-run\n```\n")
    cmds = commands_of(doc, root=tmp_path)
    assert [c.line for c in cmds] == [4, 7, 8]
    assert cmds[0].text == "powertrain stiffness m.toml --freq 5,10 --format csv > k.csv"
    assert output_paths(cmds[0].text) == ["k.csv"]
    assert cmds[1].text == "powertrain runup --csv r.csv"
    assert [reason for _, reason in cmds[1].skipped] == [
        "install step (virtual environment)", "install step (virtual environment)",
        "install step (pip install)"]
    assert cmds[2].expect_exit == 1 and cmds[0].expect_exit == 0
    assert skip_reason('python -m pytest -q') and not skip_reason("python scripts/x.py")
    assert output_paths("powertrain diagnose c.csv --report=out/d --json out/d.json") == [
        "out/d", "out/d.json"]


def test_shell_fences_other_than_bash_are_refused(tmp_path):
    doc = tmp_path / "page.md"
    doc.write_text("```sh\nls\n```\n")
    with pytest.raises(AssertionError, match="page.md:1"):
        bash_blocks(doc, root=tmp_path)


def test_readme_shows_the_two_commands_and_ci_runs_the_second():
    """The README's first block is the front door: install + main job, install + tests;
    .ci/run runs the same test command."""
    first = bash_blocks(ROOT / "README.md")[0][1]
    lines = [s.strip() for s in first if s.strip() and not s.strip().startswith("#")]
    assert len(lines) == 2, lines
    main_job, tests = lines
    assert "pip install -e ." in main_job and "powertrain runup" in main_job
    assert tests.endswith("python -m pytest -q") and 'pip install -e ".[test]"' in tests
    assert tests in (ROOT / ".ci" / "run").read_text()


def test_failures_name_the_doc_file_and_line(tmp_path):
    env = dict(os.environ)
    assert run_command(Command("a.md", 3, "true"), tmp_path, env) is None
    assert run_command(Command("a.md", 3, "false"), tmp_path, env).startswith(
        "a.md:3: `false` exited 1")
    assert "did not write out.csv" in run_command(
        Command("a.md", 4, "true --csv out.csv"), tmp_path, env)
    assert run_command(Command("a.md", 5, "echo bad >&2; exit 1", expect_exit=1),
                       tmp_path, env) is None
    assert "one line on stderr" in run_command(
        Command("a.md", 6, "printf 'a\\nb\\n' >&2; exit 1", expect_exit=1), tmp_path, env)
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    assert "into the repository" in run_command(
        Command("a.md", 7, "true --out examples/whatif-variants.toml"), tmp_path, env)


def test_shown_outputs_are_text_blocks_right_after_a_bash_block(tmp_path):
    doc = tmp_path / "page.md"
    doc.write_text("```bash\necho a\n```\nprose\n```text\na\n```\n"
                   "```text\nnot after bash\n```\n```bash\necho b\n```\n# Heading\n"
                   "```text\nafter a heading\n```\n```bash\necho c\n```\n"
                   "```text\n$ long-command\nits output\n```\n")
    shown = shown_outputs(doc, root=tmp_path)
    assert [(s.line, s.block, s.lines) for s in shown] == [(6, 2, ["a"])]
    assert [c.block for c in commands_of(doc, root=tmp_path)] == [2, 12, 19]


@pytest.mark.parametrize(("shown", "printed", "ok"), [
    ("overall RMS gap 0.81 dB over 3624 points", "overall RMS gap 0.81 dB over 3624 points", True),
    ("gap 0.81 dB", "gap 0.82 dB", True),              # one unit of the last shown digit
    ("gap 0.81 dB", "gap 0.83 dB", False),
    ("explains 91% ... 3.80 -> 1.24 dB; ...", "explains 100% of it; 3.80 -> 0.45 dB; x", False),
    ("explains 100% ... 3.80 -> 0.45 dB; ...", "explains 100% of it; 3.80 -> 0.45 dB; x", True),
    ("t 10.7", "t 40.0", False),
    ("3624 points", "3650 points", True),              # 1 % relative
    ("3624 points", "3700 points", False),
    ("a  +0.00 / 0.74", "a -0.00 /  0.74", True),       # whitespace runs, signed zero
    ("ratio 1.6e-05", "ratio 1.7e-05", True),
    ("ratio 1.6e-05", "ratio 1.9e-05", False),
    ("solver time: ... s; wrote r.h5", "solver time: 0.011 s; wrote r.h5", True),
    ("order_2 1000-6000 rpm", "order_2 1000-6000 rpm", True),
    ("order_2 1000-6000 rpm", "order_4 1000-6000 rpm", False),
    ("0 missing", "0 missing; 15.97 s", False),        # a line is matched whole
])
def test_a_shown_line_matches_a_printed_line(shown, printed, ok):
    assert line_matches(shown, printed) is ok


def test_shown_lines_are_an_excerpt_with_elision_lines():
    printed = ["head", "a 1", "b 2", "c 3", "d 4", "tail"]
    assert match_shown(["a 1", "b 2"], printed) is None
    assert match_shown(["a 1", "...", "d 4"], printed) is None
    assert match_shown(["...", "tail"], printed) is None
    assert "not consecutive" in match_shown(["a 1", "c 3"], printed)
    assert "nearest printed `d 4`" in match_shown(["a 1", "...", "d 9"], printed)
    assert match_shown(["d 4", "...", "a 1"], printed) is not None       # order kept
    stderr_only = Shown("a.md", 5, 1, ["error: x.csv: bad"])
    assert check_shown(stderr_only, [("", "error: x.csv: bad\n")]) is None
    assert check_shown(stderr_only, [("error: y.csv: bad\n", "")]).startswith("a.md:5: ")


LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("doc", list(ALL_COMMANDS))
def test_relative_links_resolve(doc):
    """Every relative link of a doc page points to an existing file (anchors not checked)."""
    path = ROOT / doc
    text = re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S)
    broken = [target for target in LINK.findall(text)
              if not re.match(r"[a-z]+:", target) and not target.startswith("#")
              and not (path.parent / target.split("#")[0]).exists()]
    assert not broken, f"{doc}: broken links {broken}"


PYTHON_BLOCK = re.compile(r"^\s*```python\n(.*?)^\s*```", re.S | re.M)


@pytest.mark.parametrize("doc", list(ALL_COMMANDS))
def test_python_examples_compile(doc):
    """```python blocks are not run (they may be fragments), but they must be valid Python."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    for block in PYTHON_BLOCK.findall(text):
        compile(textwrap.dedent(block), doc, "exec")


def test_every_doc_page_with_commands_is_collected():
    """Every page with commands runs here, but README.md, whose commands the wheel test
    runs (and checks its shown outputs) after a wheel install."""
    import test_package
    assert RUN_BY_WHEEL_TEST not in RUN_FILES and any(c.text for c in ALL_COMMANDS["README.md"])
    assert "test_wheel_runs_the_readme_unchanged_in_an_empty_folder" in dir(test_package)
    assert set(RUN_FILES) == {d for d, c in ALL_COMMANDS.items() if any(x.text for x in c)} \
        - {"README.md"}
    assert len(RUN_FILES) >= 5, RUN_FILES


# ----------------------------------------------------------------------------- the runs
@pytest.mark.parametrize(("cmd", "part", "reason"), SKIPPED_PARTS,
                         ids=[f"{c.where}:{p.split()[0]}" for c, p, _ in SKIPPED_PARTS])
def test_skipped_by_rule(cmd, part, reason):
    """Reported, never silent: the part of a chain the rule does not run."""
    pytest.skip(f"{cmd.where}: `{part}` not run: {reason} "
                "(rule: docs/extending.md, 'Writing docs')")


# Each doc file is its own test: the test processes (pytest-xdist) share them out, and each runs
# once. (A module fixture that ran every file in a thread pool was instantiated by *each*
# test process that drew one of these tests, so CI ran every doc command twice.)
@pytest.mark.slow
@pytest.mark.parametrize("doc", RUN_FILES)
def test_doc_commands_run(doc, shim_bin, tmp_path):
    failure = run_doc(doc, tmp_path, doc_environment(shim_bin))
    assert failure is None, failure
