r"""Many small dense complex systems :math:`\mathbf D_k\mathbf x_k = \mathbf b_k` at once
(e.g. the harmonic model's 6×6 systems, one per speed and harmonic), by Gaussian elimination
with partial pivoting on the largest :math:`|\Re|+|\Im|` of the column, as LAPACK's ``zgesv``.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def batched_solve_kernel(D, b, x):
    """Fill ``x`` (m, n) complex with the solutions of ``D[k] x[k] = b[k]``.

    Parameters
    ----------
    D : ndarray (m, n, n) complex
        The matrices (unchanged).
    b : ndarray (m, n) complex
        The right-hand sides.
    x : ndarray (m, n) complex
        Filled with the solutions.

    Returns
    -------
    int
        0, or 1 when some matrix has an exactly zero pivot (its solution NaN).
    """
    m, n = b.shape
    A, status = np.empty((n, n), np.complex128), 0
    for k in range(m):
        for i in range(n):
            x[k, i] = b[k, i]
            for j in range(n):
                A[i, j] = D[k, i, j]
        singular = False
        for col in range(n):
            p = col
            best = abs(A[col, col].real) + abs(A[col, col].imag)
            for i in range(col + 1, n):
                v = abs(A[i, col].real) + abs(A[i, col].imag)
                if v > best:
                    best, p = v, i
            if best == 0.0:
                singular = True
                break
            if p != col:
                for j in range(n):
                    A[col, j], A[p, j] = A[p, j], A[col, j]
                x[k, col], x[k, p] = x[k, p], x[k, col]
            inv = 1.0 / A[col, col]
            for i in range(col + 1, n):
                f = A[i, col] * inv
                if f != 0.0:
                    for j in range(col + 1, n):
                        A[i, j] -= f * A[col, j]
                    x[k, i] -= f * x[k, col]
        if singular:
            status = 1
            for i in range(n):
                x[k, i] = np.nan
            continue
        for i in range(n - 1, -1, -1):
            acc = x[k, i]
            for j in range(i + 1, n):
                acc -= A[i, j] * x[k, j]
            x[k, i] = acc / A[i, i]
    return status
