"""Atomic file output: write to a temporary file beside the target, then rename.

A failure half-way leaves no half-written output behind, and the finished file gets the mode
an ordinary ``open(path, "w")`` would give (``0666 & ~umask``: 0644 under umask 022), not the
private 0600 of the temporary file. Every file renamed into place is remembered in
:data:`WRITTEN` so that a command that fails after writing some of its outputs can remove them
(:func:`discard_written`): a failed run leaves no output file.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from powertrain.errors import InputError

#: Files written by :func:`atomic_path` since the last :func:`start_tracking`.
WRITTEN: list[Path] = []


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


def start_tracking() -> None:
    """Forget earlier outputs: a new command starts."""
    WRITTEN.clear()


def discard_written() -> list[Path]:
    """Remove every output written since :func:`start_tracking` (after a failed command)."""
    removed = []
    while WRITTEN:
        path = WRITTEN.pop()
        with contextlib.suppress(OSError):
            path.unlink()
            removed.append(path)
    return removed


def check_writable(target, key: str | None = None) -> Path:
    """Fail early, before any work, if ``target`` cannot be written (folder or path clash)."""
    target = Path(target)
    if target.is_dir():
        raise InputError("is a folder, not a file", file=target, key=key)
    parent = target.parent
    for folder in [parent, *parent.parents]:
        if folder.exists():
            if not folder.is_dir():
                raise InputError(f"cannot write: {folder} is not a folder", file=target, key=key)
            if not os.access(folder, os.W_OK | os.X_OK) and folder == parent:
                raise InputError("cannot write: folder not writable", file=target, key=key)
            break
    return target


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path in the target's folder; rename it onto ``target`` on success."""
    target = Path(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise InputError(f"cannot write ({exc.strerror or exc})", file=target) from None
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~current_umask())
        try:
            os.replace(tmp, target)
        except OSError as exc:
            raise InputError(f"cannot write ({exc.strerror or exc})", file=target) from None
        WRITTEN.append(target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@contextlib.contextmanager
def atomic_write(target, mode="w", **kwargs):
    """Open a temporary file for writing; it replaces ``target`` only if the block succeeds."""
    with atomic_path(target) as tmp:
        with open(tmp, mode, **kwargs) as fh:
            yield fh
