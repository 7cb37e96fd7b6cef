"""Hops from the command line to the solver: how far a parameter travels through the code.

Runs one ``powertrain`` command in this process under a profiler hook and, at the first call
of the target function, prints the call stack inside the package from the click command down
to it: the number of calls ("hops") and of distinct modules they pass, and how many times
the variant's own ``apply`` ran. Issue 19 quotes these for two paths:

    python scripts/call_path.py --target harmonic_solve --after apply -- \
        whatif --workers 1 --scale left.z.stiffness=1.2 --json /tmp/w.json --quiet
    python scripts/call_path.py --target harmonic_solve -- \
        runup --engine src/powertrain/data/engines/default-modal-body.toml \
        --solver harmonic --from 3000 --to 3000 --effect chassis_modes:f1=30

The last line is ``hops N calls over M modules``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile

PACKAGE = "powertrain"


def _frames_in_package(frame):
    """The package's frames of ``frame``'s stack, outermost first, from the click command."""
    out = []
    while frame is not None:
        mod = frame.f_globals.get("__name__", "")
        if mod.startswith(PACKAGE + "."):
            out.append((mod, frame.f_code.co_name))
        frame = frame.f_back
    out.reverse()
    start = next((i for i, (m, _) in enumerate(out) if m.startswith(PACKAGE + ".cli.")
                  and m != PACKAGE + ".cli.group"), 0)
    return out[start:]


def trace(argv, target, after="", counted="apply"):
    """(stack at the first call of ``target`` once a function named ``after`` has run,
    calls of functions named ``counted`` in powertrain.workflows.operations)."""
    from powertrain.cli import main as cli

    found, applied, armed = [], [0], [not after]

    def hook(frame, event, arg):
        if event != "call":
            return
        name = frame.f_code.co_name
        mod = frame.f_globals.get("__name__", "")
        if name == counted and mod == PACKAGE + ".workflows.operations":
            applied[0] += 1
        if name == after and mod.startswith(PACKAGE + "."):
            armed[0] = True
        if name == target and armed[0] and not found and mod.startswith(PACKAGE + "."):
            found.append(_frames_in_package(frame))

    sys.setprofile(hook)
    try:
        cli.main(argv, standalone_mode=False)
    finally:
        sys.setprofile(None)
    return (found[0] if found else []), applied[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", default="condensed_matrix",
                        help="function name where the path ends")
    parser.add_argument("--after", default="",
                        help="count only calls of the target after a function of this name")
    parser.add_argument("command", nargs=argparse.REMAINDER,
                        help="powertrain command and its options, after --")
    args = parser.parse_args()
    argv = [a for a in args.command if a != "--"]
    with tempfile.TemporaryDirectory():
        stack, applied = trace(argv, args.target, args.after)
    if not stack:
        print(f"{args.target} was not called")
        return 1
    for mod, fn in stack:
        print(f"  {mod}.{fn}")
    modules = len({m for m, _ in stack})
    print(f"variant apply calls: {applied}")
    print(f"hops {len(stack) - 1} calls over {modules} modules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
