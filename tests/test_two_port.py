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


def test_several_networks_in_one_call_equal_one_call_each():
    """``laplace_two_ports`` (one kernel call over networks of different sizes, factors per
    entry and network) against ``laplace_two_port`` of each network alone."""
    from powertrain.physics.mount_network import laplace_two_ports
    rng = np.random.default_rng(3)
    nets = _networks()
    nets = nets + [(np.zeros(0), np.array([[0, GROUND]]), np.array([2e5]), np.array([80.0]))]
    s = 1j * np.geomspace(5.0, 2000.0, 12).reshape(3, 4)
    ks = rng.uniform(0.3, 3.0, s.shape + (len(nets),))
    ds = rng.uniform(0.3, 3.0, s.shape + (len(nets),))
    got = laplace_two_ports(s, nets, ks, ds)
    for k, net in enumerate(nets):
        ref = laplace_two_port(s, *net, ks[..., k], ds[..., k])
        for x, y in zip(got, ref):
            assert x[..., k].shape == y.shape
            assert np.max(np.abs(x[..., k] - y)) <= EXACT * np.max(np.abs(y))


@pytest.mark.parametrize("grounded", [True, False])
def test_condensed_matrix_equals_the_dense_sum(grounded):
    """``condensed_matrix`` (the one assembly of the condensed model) against the dense
    sum of the frame and every network's outer products, written out in NumPy."""
    from powertrain.physics.condensation import condensed_matrix
    rng = np.random.default_rng(11)
    n, n_net = 9, 5
    frame = [rng.normal(size=(n, n)) for _ in range(3)]
    E, B = rng.normal(size=(n_net, n)), rng.normal(size=(n_net, n))
    E[:, 6:], B[:, :6] = 0.0, 0.0                 # engine side on the body, base on modes
    s = 1j * rng.uniform(1, 500, (4, 3))
    abc = [rng.normal(size=s.shape + (n_net,)) + 1j * rng.normal(size=s.shape + (n_net,))
           for _ in range(3)]
    ref = (s ** 2)[..., None, None] * frame[0] + s[..., None, None] * frame[1] + frame[2]
    ref = ref + np.einsum("...n,ni,nj->...ij", abc[0], E, E)
    if not grounded:
        ref = ref + np.einsum("...n,ni,nj->...ij", abc[1], E, B) \
            + np.einsum("...n,ni,nj->...ij", abc[1], B, E) \
            + np.einsum("...n,ni,nj->...ij", abc[2], B, B)
    got = condensed_matrix(frame, E, None if grounded else B, abc, s)
    assert got.shape == ref.shape
    assert np.max(np.abs(got - ref)) <= EXACT * np.max(np.abs(ref))


def test_several_networks_follow_arrays_changed_in_place():
    """Packed networks are reused only for read-only arrays: a caller that changes its
    writable arrays in place between calls gets the new values."""
    from powertrain.physics.mount_network import laplace_two_ports
    masses, en, c, d = (np.array(x) for x in _networks()[0])
    s = 1j * np.array([50.0, 500.0])
    first = laplace_two_ports(s, [(masses, en, c, d)], 1.0, 1.0)[0][..., 0]
    c *= 2.0
    d *= 2.0
    again = laplace_two_ports(s, [(masses, en, c, d)], 1.0, 1.0)[0][..., 0]
    ref = laplace_two_port(s, masses, en, c, d)[0]
    assert np.max(np.abs(again - ref)) <= EXACT * np.max(np.abs(ref))
    assert np.max(np.abs(again - first)) > 0.1 * np.max(np.abs(first))
