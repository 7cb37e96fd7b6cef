"""``powertrain`` for the docs commands, without the interpreter's start-up each time: a fork
server imports the package once; each ``powertrain ...`` a doc command runs is a child forked
from it, in the command's folder, with its environment, its stdin, stdout and stderr, its
arguments and its exit code — the console script's ``main()``, as after a wheel install.

The docs commands start ``powertrain`` about 120 times; importing the package, SciPy and
Matplotlib took about 0.8 s of CPU each time (``python -m powertrain.cli``), a third of the
docs test's time. A forked child starts from the imported modules and runs the command in a
process of its own: what one command does cannot leak into the next. README.md's commands
still start the installed console script itself (the wheel test, tests/test_package.py).

    python tests/forked_commands.py serve SOCKET          # the server (a test fixture)
    python -I -S tests/forked_commands.py run SOCKET ARGS # the ``powertrain`` shim

Only the standard library is imported at the top: the client starts in about 20 ms.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import sys

#: A child that runs longer than this is stopped (the docs test's own timeout kills the
#: shim, not the child): seconds.
CHILD_TIMEOUT_S = 150
#: Largest request (arguments, folder and environment as JSON) [bytes].
MAX_REQUEST = 1 << 20
#: Exit code the shim returns when its child died without reporting one.
NO_EXIT_CODE = 70


def serve(path: str) -> None:
    """Import every module of the package (and pyplot, Agg), then fork a child per request
    on the Unix socket ``path``; prints ``ready`` once listening."""
    import importlib
    import pkgutil

    os.environ.setdefault("MPLBACKEND", "Agg")
    import powertrain
    for m in pkgutil.walk_packages(powertrain.__path__, "powertrain."):
        if not m.name.endswith("__main__"):
            importlib.import_module(m.name)
    import matplotlib.pyplot  # noqa: F401
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)          # children reaped by the kernel
    server = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    server.bind(path)
    server.listen(16)
    print("ready", flush=True)
    while True:
        conn, _ = server.accept()
        if os.fork() == 0:
            server.close()
            _child(conn)
        conn.close()


def _child(conn) -> None:
    """Run one request as the console script would, report its exit code, exit."""
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    code = 1
    try:
        msg, fds, _, _ = socket.recv_fds(conn, MAX_REQUEST, 3)
        request = json.loads(msg)
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
            os.close(fd)
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        signal.alarm(CHILD_TIMEOUT_S)
        code = _main(request["argv"])
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:                              # noqa: BLE001 - exiting anyway
                pass
        try:
            conn.sendall(str(code).encode())
        finally:
            os._exit(code)


def _main(argv) -> int:
    """The console script's entry point with ``argv``; its exit code."""
    import traceback

    from powertrain.cli.group import main
    sys.argv = ["powertrain", *argv]
    try:
        main()
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            return exc.code or 0
        print(exc.code, file=sys.stderr)
        return 1
    except BaseException:                                  # noqa: BLE001 - as Python would
        traceback.print_exc()
        return 1
    return 0


def run(path: str, argv) -> int:
    """The shim: send the arguments, folder, environment and standard streams to the server;
    its child's exit code."""
    request = {"argv": list(argv), "cwd": os.getcwd(), "env": dict(os.environ)}
    with socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET) as conn:
        conn.connect(path)
        socket.send_fds(conn, [json.dumps(request).encode()], [0, 1, 2])
        reply = conn.recv(16)
    return int(reply) if reply else NO_EXIT_CODE


if __name__ == "__main__":
    if sys.argv[1] == "serve":
        serve(sys.argv[2])
    else:
        sys.exit(run(sys.argv[2], sys.argv[3:]))
