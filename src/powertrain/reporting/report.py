"""``pt.report`` / ``powertrain report``: run a study file's steps through the library and
write one self-contained HTML report."""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import platform
import shlex
import time
from dataclasses import dataclass, field, replace
from datetime import datetime, timezone
from pathlib import Path

from powertrain import __version__
from powertrain.errors import InputError
from powertrain.outputs import atomic_write, check_writable
from powertrain.provenance import Provenance
from powertrain.reporting import document
from powertrain.reporting.keys import Where, restated
from powertrain.reporting.steps import STEPS, shown
from powertrain.reporting.study import Study, check_study_path, read_study
from powertrain.results.base import Result
from powertrain.results.html import styled

#: Packages whose versions the report names (besides Python and the platform).
VERSIONED = ("powertrain", "numpy", "scipy", "numba", "matplotlib", "h5py")
#: Suffixes of the report file.
HTML_SUFFIXES = (".html", ".htm")
#: Channel-quantities in the summary's table of top gaps.
TOP_GAPS = 5
#: Bytes of a file read to find its first comment line.
HEAD_BYTES = 4096
#: Longest provenance text shown for a file [characters].
MAX_COMMENT = 200


@dataclass(frozen=True)
class FileRecord:
    """One file a study read: its role, path, first comment line, size [bytes] and SHA-256."""

    role: str
    path: str
    provenance: str
    size: int
    sha256: str
    synthetic: bool = False


def report(study, out=None, *, progress: bool = False) -> ReportResult:
    """Run the steps of a study file and build its report (``powertrain report``).

    Parameters
    ----------
    study : str or Path
        Study file (TOML, docs/reference/study-file.md): engine, measured run-up or plan, and
        the steps (``[compare]``, ``[diagnose]``, ``[whatif]``, ``[modes]``, ``[transient]``).
    out : str or Path, optional
        HTML file written atomically.
    progress : bool
        Show the steps' progress bars.

    Returns
    -------
    ReportResult

    Raises
    ------
    InputError
        A bad study file (naming the key), an unreadable file it names, an unwritable output;
        nothing is written then.
    """
    t0 = time.perf_counter()
    path = check_study_path(study)
    if out is not None:
        _check_out(out)
    s = read_study(path)
    where = Where(s.path, Path(s.path).parent, s.engine)
    parts = {}
    for name in sorted(s.steps, key=lambda n: STEPS[n].cost):
        try:
            parts[name] = STEPS[name].run(s, s.steps[name], progress)
        except InputError as exc:
            raise restated(exc, where, name) from None
    parts = {name: parts[name] for name in STEPS if name in parts}
    synthetic = {os.path.realpath(m.source) for _, m, _, _ in s.runs() if m.synthetic}
    rep = ReportResult(study=s, parts=parts, files=[_record(role, f, synthetic)
                                                    for role, f in s.files],
                       versions=_versions(), created=_now(), out=str(out or ""),
                       seconds=time.perf_counter() - t0)
    prov = Provenance.now(command=rep.command(),
                          engine=f"{s.engine.name} ({shown(s.engine.file)})")
    rep = replace(rep, body=document.body(rep, prov), seconds=time.perf_counter() - t0)
    if out is not None:
        rep.to_html(out)
    return rep


def _check_out(out) -> None:
    if not isinstance(out, (str, os.PathLike)):
        raise InputError(f"expected a file path, got {type(out).__name__}", key="--out")
    if Path(out).suffix.lower() not in HTML_SUFFIXES:
        raise InputError("the report is an HTML file (.html)", file=out, key="--out")
    check_writable(out, key="--out")


@dataclass(frozen=True)
class ReportResult(Result):
    """A study's report: the study, each step's results, the files read, the versions and
    the HTML body.

    Attributes
    ----------
    study : Study
    parts : dict
        Step name -> ``[(label, result)]`` (one per measured run for comparing steps).
    files : list of FileRecord
    versions : dict
        Package -> version (also Python and the platform).
    created : str
        UTC, ISO 8601.
    out : str
        The report file ("" if none).
    body : str
        The HTML content (a ``.pt-report`` block).
    seconds : float
        Wall-clock time [s].
    """

    study: Study
    parts: dict
    files: list = field(default_factory=list)
    versions: dict = field(default_factory=dict)
    created: str = ""
    out: str = ""
    body: str = ""
    seconds: float = 0.0

    def out_name(self) -> str:
        """The report file as the reproducing command names it."""
        return shown(self.out) if self.out else "report.html"

    def command(self) -> str:
        """The command that makes this report again."""
        return shlex.join(["powertrain", "report", shown(self.study.path), "--out",
                           self.out_name()])

    def verdict(self) -> str:
        """The diagnosis's verdict, or what the comparison found without one."""
        if "diagnose" in self.parts:
            return "VERDICT: " + self.parts["diagnose"][0][1].verdict_text
        if "compare" in self.parts:
            return "No diagnosis in this study; compare: " + "; ".join(
                (f"{label}: " if label else "") + f"overall RMS gap {r.overall_rms_db:.2f} dB"
                for label, r in self.parts["compare"])
        return "No measurement compared in this study."

    def top_gaps(self, n: int = TOP_GAPS) -> list:
        """The ``n`` channel-quantities with the largest RMS gap [dB] from the comparison
        (else the diagnosis), largest first, as dicts (``run``, ``mount``, ``direction``,
        ``quantity``, ``rms_db``, ``bias_db``, ``max_abs_db``, ``from``...)."""
        rows = []
        for label, r in self.parts.get("compare", []):
            rows += [{"run": label or "-", "mount": c.mount, "direction": c.direction,
                      "quantity": c.quantity, **c.stats, "from": "compare"}
                     for c in r.channels]
        if not rows and "diagnose" in self.parts:
            rows = [{"run": "-", **c, "from": "diagnose, all speeds"}
                    for c in self.parts["diagnose"][0][1].where()["per_channel"]]
        return sorted(rows, key=lambda g: -g["rms_db"])[:n]

    def to_text(self) -> str:
        """What ``powertrain report`` prints."""
        s = self.study
        lines = [f"study: {shown(s.path)}: {s.title}",
                 f"engine: {s.engine.name} ({shown(s.engine.file)})"]
        lines += [f"measured: {shown(m.source)}{' [SYNTHETIC]' if m.synthetic else ''}"
                  + (f" ({label})" if label else "") for label, m, _, _ in s.runs()]
        lines.append(self.verdict())
        for g in self.top_gaps():
            run = "" if g["run"] == "-" else f" ({g['run']})"
            lines.append(f"  gap {g['mount']} {g['direction']} {g['quantity']}{run}: "
                         f"{g['rms_db']:.2f} dB RMS, bias {g['bias_db']:+.2f} dB")
        lines.append(f"steps: {', '.join(self.parts)}; {len(self.files)} files read "
                     f"(SHA-256 in the report); {self.seconds:.1f} s")
        return "\n".join(lines)

    def to_html(self, path=None) -> str:
        """The self-contained HTML document; written atomically to ``path`` if given."""
        text = document.document(self.study.title, self.body)
        if path is not None:
            with atomic_write(path, encoding="utf-8") as fh:
                fh.write(text)
        return text

    def _repr_html_(self) -> str:
        return styled(self.body)

    def writers(self) -> dict:
        """``.html``, ``.htm``, ``.png`` (the first step's figure)."""
        return {".html": self.to_html, ".htm": self.to_html, **super().writers()}

    def plot(self, ax=None, *, path=None, step=None, provenance=None):
        """The figure of ``step``'s (default: the first step's) first result."""
        name = next(iter(self.parts)) if step is None else step
        if name not in self.parts:
            raise InputError(f"no step {name!r} in this report (steps: "
                             f"{', '.join(self.parts)})", key="step")
        return self.parts[name][0][1].plot(ax, path=path, provenance=provenance)


def _record(role: str, path: str, synthetic=frozenset()) -> FileRecord:
    """Hash, size and first comment lines of a file."""
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            head = fh.read(HEAD_BYTES)
            digest.update(head)
            for block in iter(lambda: fh.read(1 << 20), b""):
                digest.update(block)
        size = os.path.getsize(path)
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror or exc})", file=path) from None
    comment = _first_comment(head.decode("utf-8", "replace"))
    return FileRecord(role, path, comment, size, digest.hexdigest(),
                      synthetic=os.path.realpath(path) in synthetic)


def _first_comment(text: str) -> str:
    """The first block of ``#`` comment lines, joined, cut to :data:`MAX_COMMENT` characters."""
    block = []
    for line in text.splitlines():
        if line.startswith("#"):
            block.append(line.lstrip("#").strip())
        elif block:
            break
    comment = " ".join(b for b in block if b)
    return comment if len(comment) <= MAX_COMMENT else comment[:MAX_COMMENT - 3] + "..."


def _versions() -> dict:
    out = {}
    for name in VERSIONED:
        try:
            out[name] = __version__ if name == "powertrain" else importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "not installed"
    out["Python"] = platform.python_version()
    out["platform"] = platform.platform()
    return out


def _now() -> str:
    return datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
