"""The one two-port condensation (kernels/two_port.py via physics.mount_network.two_port)
against independent dense solves of the same networks, and its pivot check.

Oracle: :func:`input_point_stiffness` and :func:`cross_point_stiffness` (LAPACK solve of
the internal block, a different code path): a = K_IP, b = −K_CP; c = K_IP of the network
turned round (engine side and ground swapped). Same linear algebra, so round-off only."""

from __future__ import annotations

import numpy as np
import pytest

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics.mount_network import GROUND, cross_point_stiffness, input_point_stiffness, two_port

EXACT = 1e-9


def _networks():
    eng = read_engine(DEFAULT_ENGINE_PATH)
    return [m.directions[ax].network() for m in eng.mounts for ax in ("x", "y", "z")]


def _reversed(elem_nodes):
    en = np.array(elem_nodes, int).reshape(-1, 2).copy()
    e0, g = en == 0, en == GROUND
    en[e0], en[g] = GROUND, 0
    return en


@pytest.mark.parametrize("k", range(9))
def test_two_port_equals_independent_solves(k):
    masses, en, c, d = _networks()[k]
    w = np.geomspace(5.0, 2000.0, 40)
    a, b, cc = two_port(w, masses, en, c, d)
    kip = input_point_stiffness(w, masses, en, c, d)
    kcp = cross_point_stiffness(w, masses, en, c, d)
    kip_rev = input_point_stiffness(w, masses, _reversed(en), c, d)
    for x, ref in ((a, kip), (-b, kcp), (cc, kip_rev)):
        assert np.max(np.abs(x - ref)) <= EXACT * np.max(np.abs(ref))


def test_spring_and_damper_scales_act_separately():
    masses, en, c, d = _networks()[0]
    w = np.array([30.0, 300.0])
    got = two_port(w, masses, en, c, d, spring_scale=1.7, damper_scale=0.6)
    ref = two_port(w, masses, en, 1.7 * np.asarray(c), 0.6 * np.asarray(d))
    for x, y in zip(got, ref):
        assert np.max(np.abs(x - y)) <= EXACT * np.max(np.abs(y))


def test_singular_network_is_refused_not_nan():
    # internal node 1 joined to nothing and massless: the pivot is zero
    with pytest.raises(FloatingPointError):
        two_port(np.array([10.0]), np.array([0.0]), [[0, GROUND]], np.array([1e5]),
                 np.array([10.0]))
