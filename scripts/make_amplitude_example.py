#!/usr/bin/env python
"""Make the SYNTHETIC multi-amplitude dynamic-stiffness table
``examples/hydraulic-mount-amplitudes.csv`` (K*(f) at several test amplitudes, the form of
a supplier's data, Kovarik 2016 Fig. 14), input of ``powertrain fit-mount`` in the guide.

Nothing here was measured. The "measurement" is the sinusoidal displacement test
(``powertrain stiffness --amplitude --method time``: engine side driven with
x = X sin 2πft, first harmonic of the base force, Newmark with the friction element
integrated) of the shipped hydraulic mount, Z direction, given the laws ``LAW`` and
``FRICTION`` below, at the amplitudes ``AMPLITUDES_MM`` and frequencies ``FREQUENCIES_HZ``.
A fit of that file should recover those laws.

Usage: ``python scripts/make_amplitude_example.py [--out examples/hydraulic-mount-amplitudes.csv]``
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from powertrain.iotools.mount_file import read_mount
from powertrain.physics.mount_laws import BergFriction, PowerLaw
from powertrain.workflows.stiffness import amplitude_stiffness

ROOT = Path(__file__).resolve().parents[1]
MOUNT = ROOT / "mounts" / "hydraulic-engine-mount-z.toml"
#: The laws of the synthetic mount (SI): power law at 0.1 mm, exponent 0.15, default limits;
#: Berg friction 40 N, x2 = 0.05 mm.
LAW = PowerLaw(0.1e-3, 0.15, (0.2, 5.0))
FRICTION = BergFriction(40.0, 0.05e-3)
AMPLITUDES_MM = (0.05, 0.1, 0.3, 1.0)
FREQUENCIES_HZ = np.round(np.geomspace(1.0, 300.0, 25), 2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(ROOT / "examples" / "hydraulic-mount-amplitudes.csv"))
    args = parser.parse_args()
    model = dataclasses.replace(read_mount(MOUNT), amplitude_law=LAW, port_law=FRICTION)
    result = amplitude_stiffness(model, FREQUENCIES_HZ, np.array(AMPLITUDES_MM) * 1e-3, "time")
    header = (
        "# SYNTHETIC multi-amplitude K*(f) table: nothing here was measured.\n"
        "# Made by scripts/make_amplitude_example.py: the displacement test (time method) of\n"
        f"# {MOUNT.name} with a power amplitude law (reference 0.1 mm, exponent 0.15,\n"
        "# limits [0.2, 5]) and Berg friction (max_force 40 N, half_displacement 0.05 mm).\n")
    Path(args.out).write_text(header + result.to_csv())
    print(f"wrote {args.out}: {len(AMPLITUDES_MM)} amplitudes x {FREQUENCIES_HZ.size} "
          "frequencies")


if __name__ == "__main__":
    main()
