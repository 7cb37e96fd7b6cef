"""Safe file output: each file is written to a temporary file beside its target and renamed
onto it when complete (:func:`atomic_path`, :func:`atomic_write`). :class:`OutputTransaction`
(around every CLI command) stages the files written inside it and renames them together on
success, each target folder locked; a failure removes the staged files and the folders
created. Temporary files are ``.NAME.pt<PID>-<random>.tmp``; finished files get
``0666 & ~umask``. Guarantees: docs/reference/outputs.md.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import json
import os
import re
import tempfile
from pathlib import Path

from powertrain.errors import InputError

#: Longest file name written [bytes]: the file-system limit (255) minus room for the
#: temporary name's prefix and suffix.
MAX_NAME_BYTES = 255 - 40
_TEMP = re.compile(r"^\..+\.pt(\d+)-[A-Za-z0-9_]+\.tmp$")
#: The transaction in progress in this context (the innermost ``with``), or None.
_CURRENT: contextvars.ContextVar[OutputTransaction | None] = contextvars.ContextVar(
    "powertrain_output_transaction", default=None)


def current_umask() -> int:
    """The process umask (read without changing it where the OS allows)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True                         # someone else's process (or unknowable): keep
    return True


def sweep_stale_temps(folder) -> list[Path]:
    """Remove ``folder``'s temporary files left by killed powertrain processes."""
    removed = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            m = _TEMP.match(entry.name)
            if m and int(m.group(1)) != os.getpid() and not _pid_alive(int(m.group(1))):
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
                    removed.append(Path(entry.path))
    return removed


def check_writable(target, key: str | None = None) -> Path:
    """Raise InputError before any work if ``target`` cannot be written (folder or path
    clash, name too long; ``key``: the option named); returns it as a Path."""
    target = Path(target)
    if len(target.name.encode("utf-8", "surrogateescape")) > MAX_NAME_BYTES or \
            any(len(p.encode("utf-8", "surrogateescape")) > 255 for p in target.parts):
        raise InputError(f"file name too long (at most {MAX_NAME_BYTES} bytes)", file=target,
                         key=key)
    try:
        if target.is_dir():
            raise InputError("is a folder, not a file", file=target, key=key)
        parent = target.parent
        for folder in [parent, *parent.parents]:
            if folder.exists():
                if not folder.is_dir():
                    raise InputError(f"cannot write: {folder} is not a folder", file=target,
                                     key=key)
                if not os.access(folder, os.W_OK | os.X_OK) and folder == parent:
                    raise InputError("cannot write: folder not writable", file=target,
                                     key=key)
                break
    except OSError as exc:
        raise InputError(f"cannot write ({exc.strerror or exc})", file=target, key=key) \
            from None
    return target


def _make_parent(target: Path, created: list) -> None:
    """Create the target's missing folders, remembering them (deepest last)."""
    missing = [p for p in [target.parent, *target.parent.parents] if not p.exists()]
    for folder in reversed(missing):
        try:
            folder.mkdir()
        except FileExistsError:
            continue
        created.append(folder)


def _cannot_write(target, exc) -> InputError:
    return InputError(f"cannot write ({exc.strerror or exc})", file=target)


def _replace(tmp, target) -> None:
    os.chmod(tmp, 0o666 & ~current_umask())
    try:
        os.replace(tmp, target)
    except OSError as exc:
        raise _cannot_write(target, exc) from None


class OutputTransaction:
    """Stage every file written inside the ``with`` block; commit all of them on success,
    remove them (and the folders created for them) on failure."""

    def __init__(self):
        self.staged: dict = {}              # target -> temporary file
        self.created: list = []             # folders created for the outputs
        self.committed: list = []
        self._token = None

    def __enter__(self):
        self._token = _CURRENT.set(self)
        return self

    def __exit__(self, exc_type, exc, tb):
        _CURRENT.reset(self._token)
        if exc_type is None or not _failed(exc):
            self.commit()
        else:
            self.abort()
        return False

    def stage(self, target: Path, tmp: Path) -> None:
        """Keep ``tmp`` until the commit (a second write of one target replaces the first)."""
        old = self.staged.pop(target, None)
        if old is not None:
            with contextlib.suppress(OSError):
                os.unlink(old)
        self.staged[target] = tmp

    def commit(self) -> list[Path]:
        """Rename every staged file onto its target under folder locks, all or none: targets
        are checked first; a failing rename puts back the files replaced before it (kept as
        hard links until the end)."""
        folders = sorted({str(t.parent.resolve()) for t in self.staged})
        with contextlib.ExitStack() as locks:
            for folder in folders:
                locks.enter_context(_folder_lock(folder))
            backups = []        # (target, hard link of its old file or None, it existed)
            try:
                for target in self.staged:
                    _check_target(target)
                for target, tmp in list(self.staged.items()):
                    backups.append((target, _backup(target), target.exists()))
                    _replace(tmp, target)
                    del self.staged[target]
                    self.committed.append(target)
            except BaseException:
                _restore(backups[:len(self.committed)])
                self.committed.clear()
                raise
            finally:
                self.abort()
                for _, backup, _ in backups:
                    if backup is not None:
                        with contextlib.suppress(OSError):
                            os.unlink(backup)
        return self.committed

    def abort(self) -> None:
        """Remove the staged files and the (now empty) folders created for them."""
        for tmp in self.staged.values():
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        self.staged.clear()
        for folder in reversed(self.created):
            with contextlib.suppress(OSError):
                folder.rmdir()
        self.created.clear()


def _check_target(target: Path) -> None:
    """A staged file can replace ``target``: not a folder, its folder a folder."""
    if target.is_dir():
        raise InputError("cannot write: is a folder", file=target)
    if not target.parent.is_dir():
        raise InputError(f"cannot write: {target.parent} is not a folder", file=target)


def _backup(target: Path) -> Path | None:
    """A hard link to ``target``'s file under a temporary name (None: no file or no links)."""
    if not target.is_file():
        return None
    name = f".{target.name}.pt{os.getpid()}-{os.urandom(4).hex()}.tmp"
    backup = target.parent / name
    try:
        os.link(target, backup)
    except OSError:
        return None
    return backup


def _restore(backups) -> None:
    """Put the old files back onto the targets replaced so far; remove new ones."""
    for target, backup, existed in reversed(backups):
        with contextlib.suppress(OSError):
            if backup is not None:
                os.replace(backup, target)
            elif not existed:
                os.unlink(target)


def _failed(exc) -> bool:
    """An exception other than a clean exit (``SystemExit(0)``, click's ``Exit(0)``)."""
    if isinstance(exc, SystemExit):
        return exc.code not in (None, 0)
    return getattr(exc, "exit_code", 1) != 0


@contextlib.contextmanager
def _folder_lock(folder):
    """Exclusive ``flock`` of a folder (POSIX); no lock where the OS has none."""
    try:
        import fcntl  # POSIX only: absent on Windows
    except ImportError:                  # pragma: no cover (Windows)
        yield
        return
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        yield
        return
    try:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)                     # closing releases the lock


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path beside ``target`` that replaces it on success (at once, or at
    the commit of the :class:`OutputTransaction` in progress)."""
    target = Path(target)
    txn = _CURRENT.get()
    created = txn.created if txn is not None else []
    try:
        _make_parent(target, created)
        sweep_stale_temps(target.parent)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.pt{os.getpid()}-", suffix=".tmp",
                                   dir=target.parent)
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:
            raise InputError("file name too long", file=target) from None
        raise _cannot_write(target, exc) from None
    os.close(fd)
    tmp = Path(tmp)
    keep = False
    try:
        yield tmp
        if txn is None:
            _replace(tmp, target)
        else:
            txn.stage(target, tmp)
            keep = True
    finally:
        if not keep and tmp.exists():
            tmp.unlink()


@contextlib.contextmanager
def atomic_write(target, mode="w", **kwargs):
    """Open (``mode``, ``kwargs`` as :func:`open`) a temporary file that replaces ``target``
    if the block succeeds (:func:`atomic_path`)."""
    with atomic_path(target) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh


_NONFINITE_CELL = re.compile(r"^(?!#)(?:[^\n]*,)?[ \t]*[-+]?(?:nan|inf|infinity)[ \t]*(?:,|$)",
                             re.IGNORECASE | re.MULTILINE)


def json_text(data, path=None, indent=1, key=None) -> str:
    """``data`` as indented JSON text, written atomically to ``path`` if given (``key``: the
    option an error names).

    Raises
    ------
    InputError
        ``data`` holds NaN or inf (JSON has no such numbers; nothing is written).
    """
    try:
        text = json.dumps(data, indent=indent, allow_nan=False) + "\n"
    except ValueError:
        raise InputError("the result holds a non-finite number (NaN or inf); not written",
                         file=path, key=key) from None
    if path is not None:
        with atomic_write(path) as fh:
            fh.write(text)
    return text


def write_csv(path, text: str) -> None:
    """Write the CSV ``text`` atomically to ``path`` (empty cell: missing value; ``#`` lines:
    comments).

    Raises
    ------
    InputError
        A cell holds NaN or inf (line given; nothing is written).
    """
    bad = _NONFINITE_CELL.search(text)
    if bad is not None:
        line = text.count("\n", 0, bad.start()) + 1
        raise InputError("the result holds a non-finite number (NaN or inf); not written",
                         file=path, line=line)
    with atomic_write(path) as fh:
        fh.write(text)
