#!/usr/bin/env python
"""Make the SYNTHETIC raw run-up examples ``examples/raw-runup.csv`` and
``examples/raw-runup-lab.csv`` (+ ``examples/raw-channels.toml``).

Nothing here was measured. Both files hold the same 2 s linear sweep 1500 -> 2500 rpm of
the default engine's continuous run-up simulation (:mod:`powertrain.solvers.speed_ramp`,
2048 Hz), mount-point accelerations of the left mount and a tacho:

* ``raw-runup.csv`` names its columns by the convention ``MOUNT.DIRECTION [UNIT]``
  (``left.x [g]`` ...), with ``rpm [1/min]`` and ``tacho [V]`` (1 pulse/rev);
* ``raw-runup-lab.csv`` names them as a test lab might (``ACC_ENG_LEFT_X`` ..., ``EngSpeed``,
  ``Tacho1``); ``raw-channels.toml`` maps them.

Usage: python scripts/make_raw_example.py [--out examples]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks.signals import tacho
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.raw_csv import write_raw_csv
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.solvers.speed_ramp import simulate_sweep

RPM0, RPM1, RATE, FS = 1500.0, 2500.0, 500.0, 2048.0
MAP = """# Channel map of examples/raw-runup-lab.csv (SYNTHETIC): file channel -> mount point
rpm = "EngSpeed"
tacho = "Tacho1"

[channels]
"ACC_ENG_LEFT_X" = { mount = "left", direction = "x", quantity = "acceleration", unit = "g" }
"ACC_ENG_LEFT_Y" = { mount = "left", direction = "y", quantity = "acceleration", unit = "g" }
"ACC_ENG_LEFT_Z" = { mount = "left", direction = "z", quantity = "acceleration", unit = "g" }
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="examples")
    args = ap.parse_args(argv)
    out = Path(args.out)
    sim = simulate_sweep(read_engine(DEFAULT_ENGINE_PATH), RPM0, RPM1, RATE, FS)
    t = sim.time - sim.time[0]
    theta = 2 * np.pi / 60 * ((sim.rpm[0]) * t + 0.5 * RATE * t * t)
    left = [c for c in sim.channels if c.mount == "left"]
    chans = [RawChannel(c.name, c.mount, c.side, c.direction, c.quantity, c.values, "g")
             for c in left]
    note = ("SYNTHETIC: " + sim.comments[0].removeprefix("SYNTHETIC: ")
            + "; left mount only; made by scripts/make_raw_example.py")
    rec = RawRecording(t, chans, sim.rpm, tacho(theta, 1), "", [note])
    write_raw_csv(out / "raw-runup.csv", rec, comment=note)
    text = (out / "raw-runup.csv").read_text().splitlines()
    header = [i for i, ln in enumerate(text) if not ln.startswith("#")][0]
    text[header] = ("time [s],EngSpeed [1/min],Tacho1 [V],ACC_ENG_LEFT_X,ACC_ENG_LEFT_Y,"
                    "ACC_ENG_LEFT_Z")
    (out / "raw-runup-lab.csv").write_text("\n".join(text) + "\n")
    (out / "raw-channels.toml").write_text(MAP)
    print(f"wrote {out / 'raw-runup.csv'}, {out / 'raw-runup-lab.csv'}, "
          f"{out / 'raw-channels.toml'}")


if __name__ == "__main__":
    main()
