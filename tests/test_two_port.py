"""The one two-port condensation (kernels/two_port.py via physics.mount_network.two_port)
against independent dense solves of the same networks, and its pivot check.

Oracle: tests/network_oracle.py (LAPACK solve of the assembled nodal matrix, a different code
path) for the two-port, the internal motion and complex Laplace variables; and the network
turned round (engine side and ground swapped): its a is our c. Same linear algebra, so
round-off only."""

from __future__ import annotations

import numpy as np
import pytest
from network_oracle import dense_two_port

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics.mount_network import GROUND, laplace_two_port, two_port

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
    a, b, cc, X = two_port(w, masses, en, c, d, internal=True)
    T, X_ref = dense_two_port(1j * w, masses, en, c, d)
    a_rev = two_port(w, masses, _reversed(en), c, d)[0]
    for x, ref in ((a, T[:, 0, 0]), (b, T[:, 0, 1]), (cc, T[:, 1, 1]), (cc, a_rev),
                   (X, X_ref)):
        assert np.max(np.abs(x - ref)) <= EXACT * np.max(np.abs(ref))


@pytest.mark.parametrize("k", [0, 4, 8])
def test_two_port_at_complex_and_zero_laplace_variable(k):
    masses, en, c, d = _networks()[k]
    s = np.array([0.0, -3.0 + 40.0j, -20.0 + 300.0j])
    a, b, cc, X = laplace_two_port(s, masses, en, c, d, internal=True)
    T, X_ref = dense_two_port(s, masses, en, c, d)
    for x, ref in ((a, T[:, 0, 0]), (b, T[:, 0, 1]), (cc, T[:, 1, 1]), (X, X_ref)):
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


def test_condense_equals_dense_schur_complement():
    """condense(system, keep, s) against a dense Schur complement of the assembled matrices:
    the rigid engine and the modal body, harmonic, damped-mode and static s, keeping the
    retained coordinates or only the rigid body; and a model assembled without networks."""
    from network_oracle import dense_condense

    from powertrain.assembly import AssembledSystem, assemble
    from powertrain.physics.condensation import condense
    for name in ("default.toml", "default-modal-body.toml"):
        eng = read_engine(DEFAULT_ENGINE_PATH.parent / name)
        b = eng.body
        system = assemble(b.mass, b.cg, b.inertia, eng.mounts, eng.chassis)
        for keep in (system.retained, np.arange(6)):
            for s in (0.0, 2j * np.pi * 37.0, -4.0 + 2j * np.pi * 11.0):
                got, ref = condense(system, keep, s), dense_condense(system, keep, s)
                assert np.max(np.abs(got - ref)) <= EXACT * np.max(np.abs(ref))
    bare = AssembledSystem(system.M, system.C, system.K, system.channels,
                           system.channel_matrix, system.force_matrix_k, system.force_matrix_d)
    keep = system.retained
    got, ref = condense(bare, keep, 3j), dense_condense(bare, keep, 3j)
    assert np.max(np.abs(got - ref)) <= EXACT * np.max(np.abs(ref))
