"""Six rigid-body modes of the default powertrain on the static stiffness of the thesis mounts.

Each mount direction contributes its static (0 Hz) cross-point stiffness, rotated from the
mount's local axes to engine axes; undamped, rigid chassis. Prints frequency and the share of
kinetic energy in each rigid-body coordinate (x, y, z translation of the CG; rx, ry, rz
rotation about axes through the CG parallel to engine X, Y, Z).

Usage: python scripts/engine_rigid_body_modes.py [ENGINE_FILE]
"""

from __future__ import annotations

import sys

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine


def main(argv):
    engine = read_engine(argv[1] if len(argv) > 1 else DEFAULT_ENGINE_PATH)
    freq, modes = engine.rigid_body_modes()
    M = engine.body.mass_matrix()
    names = ["x", "y", "z", "rx", "ry", "rz"]
    print(f"{engine.name}: mass {engine.body.mass:g} kg")
    for m in engine.mounts:
        k = [m.directions[d].static_stiffness() / 1e3 for d in "xyz"]
        print(f"  mount {m.name:8s} static stiffness x/y/z = "
              + " / ".join(f"{v:.1f}" for v in k) + " N/mm")
    print(" f [Hz]  " + "  ".join(f"{n:>5s}" for n in names))
    for f, v in zip(freq, modes.T):
        share = v * (M @ v)
        share = share / share.sum()
        print(f"{f:7.2f}  " + "  ".join(f"{s:5.2f}" for s in share))


if __name__ == "__main__":
    main(sys.argv)
