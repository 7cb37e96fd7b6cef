r"""Compiled kernel: the LU factors of a small sparse matrix in a fixed elimination order,
kept sparse, and their solve; and a sparse matrix–vector product.

The Newmark matrix :math:`\mathbf S = \mathbf M + \tfrac h2\mathbf C + \tfrac{h^2}{4}\mathbf K`
of a body on mount networks is an arrow: each network's internal coordinates couple only
to each other and to the body's. Eliminated networks first and the body last (the order
of fewest nonzeros first, :func:`powertrain.solvers.transient` computes it once), its
factors have no fill-in but the body's rows, so a solve costs about the number of nonzeros
of S instead of :math:`n^2`, and a factorization a few of the networks' small blocks
instead of :math:`n^3`.

S is symmetric positive definite for passive mounts (every massless node held by a spring
or damper), where elimination needs no pivoting (Golub & Van Loan, *Matrix Computations*,
4th ed., 2013, §4.2). :func:`factor` refuses a pivot not above ``tol`` times the largest
diagonal entry; the caller then solves densely with pivoting.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def factor(S, perm, tol):
    """``(ok, B)``: the LU factors of ``S`` (n, n) with rows and columns in the order
    ``perm`` (int64, n) in one array ``B`` (L strictly below the diagonal with a unit
    diagonal, U on and above); ``ok`` False where a pivot is not above ``tol`` times the
    largest diagonal entry of ``S`` (B then incomplete)."""
    n = S.shape[0]
    B = np.empty((n, n))
    big = 0.0
    for i in range(n):
        for j in range(n):
            B[i, j] = S[perm[i], perm[j]]
        big = max(big, abs(B[i, i]))
    for c in range(n):
        p = B[c, c]
        if not p > tol * big:
            return False, B
        for i in range(c + 1, n):
            f = B[i, c]
            if f == 0.0:
                continue
            f /= p
            B[i, c] = f
            for j in range(c + 1, n):
                u = B[c, j]
                if u != 0.0:
                    B[i, j] -= f * u
    return True, B


@njit(cache=True, nogil=True)
def compressed(A, lower, upper):
    """``(starts, columns, values)``: the rows of ``A`` (m, n) compressed (CSR), the
    entries below the diagonal where ``lower``, above it where ``upper``, the diagonal where
    both; zeros left out."""
    m, n = A.shape
    count = 0
    for i in range(m):
        for j in range(n):
            if A[i, j] != 0.0 and ((j < i and lower) or (j > i and upper)
                                   or (j == i and lower and upper)):
                count += 1
    starts, columns, values = np.zeros(m + 1, np.int64), np.empty(count, np.int64), \
        np.empty(count)
    k = 0
    for i in range(m):
        for j in range(n):
            if A[i, j] != 0.0 and ((j < i and lower) or (j > i and upper)
                                   or (j == i and lower and upper)):
                columns[k] = j
                values[k] = A[i, j]
                k += 1
        starts[i + 1] = k
    return starts, columns, values


@njit(cache=True, nogil=True)
def sparse_factors(B):
    """``(L, U, inverse diagonal)`` of :func:`factor`'s ``B``: the strict triangles
    compressed (:func:`compressed`) and the reciprocals of U's diagonal."""
    inv_d = np.empty(B.shape[0])
    for i in range(B.shape[0]):
        inv_d[i] = 1.0 / B[i, i]
    return compressed(B, True, False), compressed(B, False, True), inv_d


@njit(cache=True, nogil=True, inline="always")
def lu_solve(factors, perm, b, y, out):
    """``out`` = S^-1 ``b`` (n,) from :func:`sparse_factors`' ``factors`` of S in the order
    ``perm``; ``y`` (n,) is work space."""
    (Lp, Li, Lx), (Up, Ui, Ux), inv_d = factors
    n = b.shape[0]
    for i in range(n):
        s = b[perm[i]]
        for k in range(Lp[i], Lp[i + 1]):
            s -= Lx[k] * y[Li[k]]
        y[i] = s
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(Up[i], Up[i + 1]):
            s -= Ux[k] * y[Ui[k]]
        y[i] = s * inv_d[i]
        out[perm[i]] = y[i]


@njit(cache=True, nogil=True, inline="always")
def subtract_product(A, x, out):
    """``out -= A x`` for ``A`` compressed (:func:`compressed`)."""
    starts, columns, values = A
    for i in range(starts.shape[0] - 1):
        s = 0.0
        for k in range(starts[i], starts[i + 1]):
            s += values[k] * x[columns[k]]
        out[i] -= s
