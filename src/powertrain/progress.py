"""Progress bars on stderr (tqdm) for commands longer than about two seconds; silent with
``--quiet`` or a redirected stderr (tqdm's ``disable=None``)."""

from __future__ import annotations

import contextlib
import sys
import threading


def progress_bar(iterable=None, *, enabled: bool = True, **kwargs):
    """A tqdm bar over ``iterable`` on stderr; shown only if ``enabled`` and stderr is a TTY."""
    from tqdm import tqdm  # deferred: heavy optional package
    kwargs.setdefault("leave", False)
    kwargs.setdefault("dynamic_ncols", True)
    return tqdm(iterable, disable=None if enabled else True, file=sys.stderr, **kwargs)


@contextlib.contextmanager
def activity(desc: str, *, enabled: bool = True, interval: float = 0.25):
    """Yield an elapsed-time bar for a step of unknown length, refreshed every ``interval``
    [s] by a background thread."""
    bar = progress_bar(None, enabled=enabled, desc=desc, total=None,
                       bar_format="{desc}: {elapsed} elapsed{postfix}")
    if bar.disable:
        try:
            yield bar
        finally:
            bar.close()
        return
    stop = threading.Event()

    def tick():
        while not stop.wait(interval):
            bar.refresh()

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()
    try:
        yield bar
    finally:
        stop.set()
        thread.join()
        bar.close()
