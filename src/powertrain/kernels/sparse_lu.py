r"""Sparse LU factors of a small matrix in a fixed elimination order, their solve, and sparse
matrix–vector products.

The Newmark matrix :math:`\mathbf S = \mathbf M + \tfrac h2\mathbf C + \tfrac{h^2}{4}\mathbf K`
of a body on mount networks is an arrow; with the networks eliminated first its factors fill
in only the body's rows. For passive mounts S is symmetric positive definite and needs no
pivoting (Golub & Van Loan, *Matrix Computations*, 4th ed., 2013, §4.2); :func:`factor`
swaps rows only where a pivot is small against its column (threshold pivoting, ibid. §3.4;
Duff, Erisman & Reid, *Direct Methods for Sparse Matrices*, 2nd ed., 2017, §5.4).
:func:`lu_pattern` finds the factors' pattern once (symbolic factorization, ibid. §10.2),
:func:`factor_on_pattern` computes the values on it.
"""

import numpy as np
from numba import njit

#: A pivot below this share of its column's largest entry is swapped for that entry's row.
PIVOT_THRESHOLD = 0.01


@njit(cache=True, nogil=True)
def factor(M, C, K, c, k, perm):
    """``(ok, B, rows)``: the LU factors of S = ``M + c C + k K`` (n, n), columns in the order
    ``perm`` (int64, n), in ``B`` (unit-diagonal L below the diagonal, U on and above), and
    the rows' order ``rows``: ``perm`` with a row swapped in where a pivot is below
    :data:`PIVOT_THRESHOLD` of its column's largest entry; ``ok`` False if S is singular."""
    n = M.shape[0]
    B, rows = np.empty((n, n)), perm.copy()
    for i in range(n):
        for j in range(n):
            a, b = perm[i], perm[j]
            B[i, j] = M[a, b] + c * C[a, b] + k * K[a, b]
    for col in range(n):
        p, big = col, 0.0
        for i in range(col, n):
            big = max(big, abs(B[i, col]))
        if not big > 0.0:
            return False, B, rows
        if abs(B[col, col]) < PIVOT_THRESHOLD * big:
            for i in range(col, n):
                if abs(B[i, col]) == big:
                    p = i
                    break
            for j in range(n):
                B[col, j], B[p, j] = B[p, j], B[col, j]
            rows[col], rows[p] = rows[p], rows[col]
        pivot = B[col, col]
        for i in range(col + 1, n):
            f = B[i, col]
            if f == 0.0:
                continue
            f /= pivot
            B[i, col] = f
            for j in range(col + 1, n):
                u = B[col, j]
                if u != 0.0:
                    B[i, j] -= f * u
    return True, B, rows


def csr_pattern(mask):
    """``(starts, columns)`` (int64, :func:`compressed`'s layout) of the boolean ``mask`` (m, n)."""
    rows, columns = np.nonzero(mask)
    starts = np.zeros(mask.shape[0] + 1, np.int64)
    np.cumsum(np.bincount(rows, minlength=mask.shape[0]), out=starts[1:])
    return starts, columns.astype(np.int64)


def lu_pattern(mask):
    """``(L rows, L columns, U rows)``, each ``(starts, indices)`` (:func:`csr_pattern`): the
    entries, fill-in included, of the LU factors without row swaps of a matrix whose nonzeros
    are ``mask`` (n, n), in elimination order."""
    P = np.array(mask, bool)
    _fill_in(P)
    lower = np.tril(P, -1)
    return csr_pattern(lower), csr_pattern(lower.T), csr_pattern(np.triu(P, 1))


@njit(cache=True, nogil=True)
def _fill_in(P):
    """Mark in ``P`` (n, n) the entries elimination without row swaps fills in."""
    n = P.shape[0]
    for col in range(n):
        for i in range(col + 1, n):
            if P[i, col]:
                for j in range(col + 1, n):
                    if P[col, j]:
                        P[i, j] = True


@njit(cache=True, nogil=True)
def factor_on_pattern(terms, where, pattern, B, factors):
    """The LU factors of S = Σ coefficient × A over ``terms`` (``(A compressed, coefficient)``
    pairs), coordinate i at position ``where[i]``, into ``factors`` (:func:`sparse_factors`'
    layout on :func:`lu_pattern`'s ``pattern``); ``B`` (n, n) work space. False where a pivot
    needs a swap or a column is zero (then :func:`factor` decides); else the same arithmetic
    as :func:`factor`."""
    (lower_p, lower_i), (col_p, col_i), (upper_p, upper_i) = pattern
    (_, _, lower_x), (_, _, upper_x), inv_d = factors
    n = B.shape[0]
    B[:, :] = 0.0
    for A, coefficient in terms:
        starts, columns, values = A
        for i in range(n):
            for k in range(starts[i], starts[i + 1]):
                B[where[i], where[columns[k]]] += coefficient * values[k]
    for col in range(n):
        pivot = B[col, col]
        big = abs(pivot)
        for t in range(col_p[col], col_p[col + 1]):
            big = max(big, abs(B[col_i[t], col]))
        if not big > 0.0 or abs(pivot) < PIVOT_THRESHOLD * big:
            return False
        for t in range(col_p[col], col_p[col + 1]):
            i = col_i[t]
            f = B[i, col]
            if f == 0.0:
                continue
            f /= pivot
            B[i, col] = f
            for s in range(upper_p[col], upper_p[col + 1]):
                j = upper_i[s]
                B[i, j] -= f * B[col, j]
    for i in range(n):
        for k in range(lower_p[i], lower_p[i + 1]):
            lower_x[k] = B[i, lower_i[k]]
        for k in range(upper_p[i], upper_p[i + 1]):
            upper_x[k] = B[i, upper_i[k]]
        inv_d[i] = 1.0 / B[i, i]
    return True


@njit(cache=True, nogil=True)
def compressed(A, lower, upper):
    """``(starts, columns, values)``: the nonzeros of ``A`` (m, n) in CSR, those below the
    diagonal if ``lower``, above it if ``upper``, on it if both."""
    m, n = A.shape
    starts, columns, values = np.zeros(m + 1, np.int64), np.empty(m * n, np.int64), np.empty(m * n)
    k = 0
    for i in range(m):
        for j in range(n):
            if A[i, j] != 0.0 and ((j < i and lower) or (j > i and upper)
                                   or (j == i and lower and upper)):
                columns[k], values[k] = j, A[i, j]
                k += 1
        starts[i + 1] = k
    return starts, columns[:k].copy(), values[:k].copy()


@njit(cache=True, nogil=True)
def sparse_factors(B):
    """``(L, U, 1 / diag U)`` of :func:`factor`'s ``B``, the strict triangles compressed."""
    inv_d = np.empty(B.shape[0])
    for i in range(B.shape[0]):
        inv_d[i] = 1.0 / B[i, i]
    return compressed(B, True, False), compressed(B, False, True), inv_d


@njit(cache=True, nogil=True)
def lu_solve(factors, rows, perm, b, y, out):
    """``out`` = S^-1 ``b`` (n,) from the ``factors`` (:func:`sparse_factors`), ``rows`` and
    ``perm`` (:func:`factor`); ``y`` (n,) work space."""
    (Lp, Li, Lx), (Up, Ui, Ux), inv_d = factors
    n = b.shape[0]
    for i in range(n):
        s = b[rows[i]]
        for k in range(Lp[i], Lp[i + 1]):
            s -= Lx[k] * y[Li[k]]
        y[i] = s
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(Up[i], Up[i + 1]):
            s -= Ux[k] * y[Ui[k]]
        y[i] = s * inv_d[i]
        out[perm[i]] = y[i]


@njit(cache=True, nogil=True)
def lu_solve_rows(factors, rows, perm, B, Y, out):
    """``out[:, e]`` = S^-1 ``B[e]`` for every row of ``B`` (m, n), bit for bit as
    :func:`lu_solve` (``factors``, ``rows``, ``perm`` as there); ``Y`` (n, m) work space."""
    (Lp, Li, Lx), (Up, Ui, Ux), inv_d = factors
    n, m = B.shape[1], B.shape[0]
    for i in range(n):
        for e in range(m):
            Y[i, e] = B[e, rows[i]]
        for k in range(Lp[i], Lp[i + 1]):
            lx, c = Lx[k], Li[k]
            for e in range(m):
                Y[i, e] -= lx * Y[c, e]
    for i in range(n - 1, -1, -1):
        for k in range(Up[i], Up[i + 1]):
            ux, c = Ux[k], Ui[k]
            for e in range(m):
                Y[i, e] -= ux * Y[c, e]
        for e in range(m):
            Y[i, e] *= inv_d[i]
            out[perm[i], e] = Y[i, e]


@njit(cache=True, nogil=True)
def row_product(A, i, x):
    """Row ``i`` of ``A`` (compressed, :func:`compressed`) times ``x``."""
    starts, columns, values = A
    s = 0.0
    for k in range(starts[i], starts[i + 1]):
        s += values[k] * x[columns[k]]
    return s


@njit(cache=True, nogil=True)
def product(A, x, out):
    """``out = A x`` for ``A`` compressed (:func:`compressed`)."""
    for i in range(A[0].shape[0] - 1):
        out[i] = row_product(A, i, x)


@njit(cache=True, nogil=True)
def subtract_product(A, x, out):
    """``out -= A x`` for ``A`` compressed (:func:`compressed`)."""
    for i in range(A[0].shape[0] - 1):
        out[i] -= row_product(A, i, x)


@njit(cache=True, nogil=True)
def subtract_products(C, v, K, x, out):
    """``out -= C v`` then ``-= K x`` row by row, ``C``, ``K`` compressed on one pattern (the
    sums of :func:`subtract_product` twice)."""
    starts, columns, c = C
    k = K[2]
    for i in range(starts.shape[0] - 1):
        sc, sk = 0.0, 0.0
        for t in range(starts[i], starts[i + 1]):
            j = columns[t]
            sc += c[t] * v[j]
            sk += k[t] * x[j]
        out[i] -= sc
        out[i] -= sk
