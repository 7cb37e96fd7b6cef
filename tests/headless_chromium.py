"""A headless Chromium driven through the DevTools protocol over a pipe (standard library
only): open a page, collect what its console and network report, take a screenshot at a
given width, evaluate an expression, print it to PDF; and the page count and the pages on
which each image of a Chromium PDF is drawn.

``--remote-debugging-pipe`` makes Chromium read protocol messages (JSON, each ended by a NUL
byte) from its file descriptor 3 and write its answers and events to descriptor 4; a shell
``exec`` maps them to the pipes of :class:`subprocess.Popen`.
"""

from __future__ import annotations

import base64
import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
import zlib
from pathlib import Path

#: The browsers tried, in order: Debian's ``chromium-headless-shell`` (the headless build
#: .ci/run installs: no GTK, no desktop), then a full Chromium or Chrome.
CANDIDATES = ("chromium-headless-shell", "/usr/bin/chromium", "chromium", "chromium-browser",
              "google-chrome")
#: Seconds to wait for one answer or for a page to load.
TIMEOUT_S = 60.0


#: Set by .ci/run to a folder while it installs Chromium in the background: the folder gets
#: ``rc`` (apt-get's exit code) when the install ends, and ``log``.
INSTALL_ENV = "PT_CHROMIUM_INSTALL"
#: Seconds to wait for that install at the most.
INSTALL_WAIT_S = 600.0


def find_chromium():
    """The path of a Chromium executable, or None."""
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


def installed_chromium():
    """``(path or None, why not)``: a Chromium executable, after waiting for the background
    install .ci/run started (:data:`INSTALL_ENV`) where it is still running."""
    folder = os.environ.get(INSTALL_ENV)
    if find_chromium() is None and folder:
        rc = Path(folder) / "rc"
        deadline = time.monotonic() + INSTALL_WAIT_S
        while not rc.exists() and time.monotonic() < deadline:
            time.sleep(2.0)
        if not rc.exists():
            return None, f"the background install did not end within {INSTALL_WAIT_S:.0f} s"
        if rc.read_text().strip() != "0":
            log = (Path(folder) / "log").read_text(errors="replace").strip().splitlines()
            return None, f"apt-get failed: {log[-1] if log else 'no output'}"
    return find_chromium(), "not installed"


class Chromium:
    """One headless browser with one page (a tab); use as a context manager."""

    def __init__(self, executable: str):
        self._profile = tempfile.mkdtemp(prefix="pt-chromium-")
        args = ["--headless", "--remote-debugging-pipe", "--no-first-run",
                "--no-default-browser-check", "--disable-gpu", "--disable-dev-shm-usage",
                "--disable-extensions", "--mute-audio", f"--user-data-dir={self._profile}"]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            args.append("--no-sandbox")        # Chromium refuses to run as root otherwise
        self.proc = subprocess.Popen(
            ["sh", "-c", 'exec "$0" "$@" 3<&0 4>&1 0</dev/null 1>/dev/null', executable,
             *args, "about:blank"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        self._next = 0
        self._answers: dict = {}
        self._lock = threading.Condition()
        self.events: list = []
        threading.Thread(target=self._read, daemon=True).start()
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target,
                                 flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable", session=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Stop the browser and remove its profile."""
        try:
            self.call("Browser.close", timeout=10)
        except Exception:                     # already gone
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for pipe in (self.proc.stdin, self.proc.stdout):
            try:
                pipe.close()
            except OSError:
                pass
        shutil.rmtree(self._profile, ignore_errors=True)

    # ------------------------------------------------------------------ protocol
    def _read(self) -> None:
        buf = b""
        while True:
            chunk = self.proc.stdout.read1(1 << 16)
            if not chunk:
                break
            buf += chunk
            while b"\0" in buf:
                raw, buf = buf.split(b"\0", 1)
                msg = json.loads(raw)
                with self._lock:
                    if "id" in msg:
                        self._answers[msg["id"]] = msg
                    else:
                        self.events.append(msg)
                    self._lock.notify_all()

    def call(self, method: str, *, session: bool = False, timeout: float = TIMEOUT_S,
             **params) -> dict:
        """Send one command and wait for its answer (its ``result``)."""
        with self._lock:
            self._next += 1
            ident = self._next
        msg = {"id": ident, "method": method, "params": params}
        if session:
            msg["sessionId"] = self.session
        self.proc.stdin.write(json.dumps(msg).encode() + b"\0")
        self.proc.stdin.flush()
        with self._lock:
            if not self._lock.wait_for(lambda: ident in self._answers, timeout):
                raise TimeoutError(f"{method}: no answer within {timeout:g} s")
            answer = self._answers.pop(ident)
        if "error" in answer:
            raise RuntimeError(f"{method}: {answer['error']}")
        return answer.get("result", {})

    def wait_event(self, method: str, timeout: float = TIMEOUT_S) -> dict:
        """Wait for an event of ``method`` (one that has come already counts)."""
        deadline = time.monotonic() + timeout
        with self._lock:
            while True:
                for event in self.events:
                    if event.get("method") == method:
                        return event
                left = deadline - time.monotonic()
                if left <= 0 or not self._lock.wait(left):
                    raise TimeoutError(f"no {method} within {timeout:g} s")

    # ------------------------------------------------------------------ page
    def open(self, path, width: int = 1280, height: int = 900) -> None:
        """Load a local file in a window of ``width`` × ``height`` CSS pixels (the events of
        the page before are dropped)."""
        with self._lock:
            self.events.clear()
        self.call("Emulation.setDeviceMetricsOverride", session=True, width=width,
                  height=height, deviceScaleFactor=1, mobile=False)
        self.call("Page.navigate", session=True, url=Path(path).resolve().as_uri())
        self.wait_event("Page.loadEventFired")

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page."""
        out = self.call("Runtime.evaluate", session=True, expression=expression,
                        returnByValue=True)
        if "exceptionDetails" in out:
            raise RuntimeError(f"{expression}: {out['exceptionDetails']}")
        return out["result"].get("value")

    def media(self, name: str) -> None:
        """Lay the page out for ``name`` media (``print``, ``screen``)."""
        self.call("Emulation.setEmulatedMedia", session=True, media=name)

    def screenshot(self) -> bytes:
        """PNG of the window."""
        data = self.call("Page.captureScreenshot", session=True, format="png")["data"]
        return base64.b64decode(data)

    def pdf(self) -> bytes:
        """The page printed to PDF as a browser's "print to PDF" does: the page size and
        margins of the document's ``@page`` rule (A4 when unset), backgrounds printed."""
        data = self.call("Page.printToPDF", session=True, preferCSSPageSize=True,
                         paperWidth=8.27, paperHeight=11.69, printBackground=True)["data"]
        return base64.b64decode(data)

    def problems(self, allowed_url: str) -> list:
        """What went wrong while the page loaded: console errors, uncaught exceptions, log
        entries of level error, failed requests, and requests for anything but
        ``allowed_url`` and data URIs."""
        out = []
        for e in list(self.events):
            method, p = e.get("method"), e.get("params", {})
            if method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                out.append(f"console {p['type']}: {p.get('args')}")
            elif method == "Runtime.exceptionThrown":
                out.append(f"exception: {p.get('exceptionDetails')}")
            elif method == "Log.entryAdded" and p["entry"].get("level") == "error":
                out.append(f"log error: {p['entry'].get('text')} {p['entry'].get('url', '')}")
            elif method == "Network.loadingFailed":
                out.append(f"failed resource: {p.get('errorText')} ({p.get('type')})")
            elif method == "Network.requestWillBeSent":
                url = p["request"]["url"]
                if url != allowed_url and not url.startswith("data:"):
                    out.append(f"request for {url}")
        return out


# ------------------------------------------------------------------ PDF
_OBJ = re.compile(rb"(\d+) 0 obj\s*(.*?)endobj", re.S)
_STREAM = re.compile(rb"stream\r?\n(.*)\r?\nendstream", re.S)
_REF = re.compile(rb"/(\w+)\s+(\d+) 0 R")


def _objects(pdf: bytes) -> dict:
    """Object number -> its bytes; objects packed in object streams are unpacked."""
    objs = {int(m.group(1)): m.group(2) for m in _OBJ.finditer(pdf)}
    for body in list(objs.values()):
        if b"/ObjStm" not in body:
            continue
        data = zlib.decompress(_STREAM.search(body).group(1))
        n = int(re.search(rb"/N (\d+)", body).group(1))
        first = int(re.search(rb"/First (\d+)", body).group(1))
        nums = [int(x) for x in data[:first].split()]
        offsets = [(nums[2 * i], first + nums[2 * i + 1]) for i in range(n)]
        for i, (num, start) in enumerate(offsets):
            end = offsets[i + 1][1] if i + 1 < n else len(data)
            objs[num] = data[start:end]
    return objs


def _dictionary(objs: dict, body: bytes, key: bytes) -> bytes:
    """The dictionary under ``/key`` in ``body``, inline or by reference."""
    m = re.search(rb"/" + key + rb"\s*(\d+) 0 R", body)
    if m:
        return objs.get(int(m.group(1)), b"")
    m = re.search(rb"/" + key + rb"\s*<<", body)
    if not m:
        return b""
    depth, i = 0, m.end() - 2
    while i < len(body):
        if body[i:i + 2] == b"<<":
            depth, i = depth + 1, i + 2
        elif body[i:i + 2] == b">>":
            depth, i = depth - 1, i + 2
            if depth == 0:
                return body[m.end() - 2:i]
        else:
            i += 1
    return b""


def images_per_page(pdf: bytes) -> list:
    """For each page of a PDF (in the order of its objects), the object numbers of the
    images it draws, also through form XObjects (the pages an image is split across each
    draw it)."""
    objs = _objects(pdf)
    pages = [n for n, body in sorted(objs.items())
             if re.search(rb"/Type\s*/Page(?!s)", body)]

    def images(body, seen) -> set:
        found = set()
        xobjects = _dictionary(objs, _dictionary(objs, body, b"Resources"), b"XObject")
        for _, num in _REF.findall(xobjects):
            num = int(num)
            if num in seen:
                continue
            seen.add(num)
            target = objs.get(num, b"")
            if re.search(rb"/Subtype\s*/Image", target):
                found.add(num)
            elif re.search(rb"/Subtype\s*/Form", target):
                found |= images(target, seen)
        return found

    return [images(objs[n], set()) for n in pages]
