"""The transient kernel's amplitude laws and stretch motion (kernels/transient.py) against
the laws' own ``scales`` and NumPy's mean and standard deviation."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from powertrain.kernels.load_table import table_load
from powertrain.kernels.sparse_lu import compressed
from powertrain.kernels.transient import amplitude_scales, stretch_motion
from powertrain.physics.mount_laws import PowerLaw, TableLaw
from powertrain.solvers.transient_model import amplitude_laws


class _Element:
    def __init__(self, law):
        self.amplitude_law = law


amplitude = st.floats(0.0, 1e-2) | st.sampled_from([0.0, 1e-300, 1e-12])


@settings(max_examples=60, deadline=None)
@given(st.floats(1e-6, 1e-3), st.floats(-1.0, 1.0), st.floats(0.05, 1.0), st.floats(1.0, 20.0),
       st.sampled_from([1.0, 0.0, 0.5]), st.lists(st.floats(1e-6, 1e-2), min_size=2,
                                                     max_size=6, unique=True),
       st.lists(amplitude, min_size=3, max_size=3))
def test_the_kernels_amplitude_laws_are_the_laws_own(reference, exponent, lo, hi, gamma,
                                                    points, amplitudes):
    points = sorted(points)
    rng = np.random.default_rng(len(points))
    table = TableLaw(tuple(points), tuple(rng.uniform(0.5, 2.0, len(points))),
                     tuple(rng.uniform(0.5, 2.0, len(points))))
    laws = [PowerLaw(reference, exponent, (lo, hi), gamma), table, None]
    law = np.empty((3, 2))
    amplitude_scales(amplitude_laws([_Element(x) for x in laws]), np.array(amplitudes), law)
    for r, x in enumerate(laws):
        want = (1.0, 1.0) if x is None else tuple(float(v) for v in x.scales(amplitudes[r]))
        np.testing.assert_allclose(law[r], want, rtol=1e-12, atol=0.0)


def test_stretch_motion_is_root_two_times_the_std_and_the_mean():
    rng = np.random.default_rng(7)
    X = rng.standard_normal((50, 8))
    P = rng.standard_normal((3, 8)) * (rng.random((3, 8)) < 0.5)
    R = rng.standard_normal((4, 8))
    amplitudes, centres = np.zeros(5), np.empty(4)
    network = np.array([4, 0, 2])
    stretch_motion((compressed(P, True, True), compressed(R, True, True)), network, X, 10, 40,
                   amplitudes, centres)
    want = np.zeros(5)
    want[network] = np.sqrt(2.0) * np.std(X[10:40] @ P.T, axis=0)
    np.testing.assert_allclose(amplitudes, want, rtol=1e-12)
    np.testing.assert_allclose(centres, (X[10:40] @ R.T).mean(0), rtol=1e-12)


def test_the_load_kernel_is_trilinear_in_its_tables():
    """kernels/load_table.table_load against the same interpolation written with NumPy:
    trilinear in level, speed and angle for the gas table, linear in the angle for the
    patterns, at random points including both ends of every axis."""
    rng = np.random.default_rng(3)
    gas = rng.standard_normal((3, 4, 9, 6))
    gas[:, :, -1] = gas[:, :, 0]
    inertia, acceleration = rng.standard_normal((2, 9, 6))
    n = 40
    s0 = rng.integers(0, 2, n).astype(float)
    fs = rng.uniform(0.0, 1.0, n)
    v0 = rng.integers(0, 3, n).astype(float)
    fv = rng.uniform(0.0, 1.0, n)
    angle = rng.uniform(0.0, 8.0, n)
    s0[:2], fs[:2], v0[:2], fv[:2], angle[:2] = (0, 1), (0, 1), (0, 2), (0, 1), (0, 8 - 1e-12)
    fade, omega2, alpha = rng.uniform(0.0, 1.0, n), rng.uniform(0, 1e5, n), rng.normal(0, 1e3, n)
    out = np.empty((n, 6))
    table_load(gas, inertia, acceleration, np.column_stack([s0, fs]),
               np.column_stack([v0, fv]), angle, fade, omega2, alpha, out)
    u = np.minimum(angle.astype(int), 7)
    fu = (angle - u)[:, None]
    i, j = s0.astype(int), v0.astype(int)

    def at(table, *index):
        return table[(*index, u)] * (1 - fu) + table[(*index, u + 1)] * fu

    ws, wv = fs[:, None], fv[:, None]
    g = ((at(gas, i, j) * (1 - wv) + at(gas, i, np.minimum(j + 1, 3)) * wv) * (1 - ws)
         + (at(gas, np.minimum(i + 1, 2), j) * (1 - wv)
            + at(gas, np.minimum(i + 1, 2), np.minimum(j + 1, 3)) * wv) * ws)
    want = fade[:, None] * g + omega2[:, None] * at(inertia) + alpha[:, None] * at(acceleration)
    np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
