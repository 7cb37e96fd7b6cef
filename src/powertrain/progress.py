"""Progress bars on stderr (tqdm), silent when stderr is not a terminal or when asked.

Every command that can run longer than about two seconds shows one; ``--quiet`` switches it
off, and so does a redirected stderr (tqdm's ``disable=None``), so logs and pipes stay clean.
"""

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
    """Elapsed-time bar for a step whose length is not known in advance.

    Yields the bar; a background thread refreshes it every ``interval`` seconds so that the
    elapsed time keeps moving while the library works.
    """
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
