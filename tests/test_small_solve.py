"""The batched small complex solve (kernels/small_solve.py) against numpy.linalg.solve."""

import numpy as np
import pytest

from powertrain.physics.condensation import batched_solve


@pytest.mark.parametrize("n", [1, 6, 9])
def test_agrees_with_numpy(n):
    rng = np.random.default_rng(n)
    D = rng.standard_normal((4, 5, n, n)) + 1j * rng.standard_normal((4, 5, n, n))
    D[0, 0] = np.triu(D[0, 0])                  # zero leading entries: pivoting needed
    D[0, 0, 0, 0] = 0.0
    D[0, 0, -1, 0] = 1.0
    b = rng.standard_normal((4, 5, n)) + 1j * rng.standard_normal((4, 5, n))
    x = batched_solve(D, b)
    ref = np.linalg.solve(D, b[..., None])[..., 0]
    assert x.shape == ref.shape
    np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


def test_singular_raises_like_numpy():
    D = np.zeros((2, 3, 3), complex)
    D[0] = np.eye(3)
    with pytest.raises(np.linalg.LinAlgError):
        batched_solve(D, np.ones((2, 3)))
