r"""Compiled kernel: the LU factors of a small sparse matrix in a fixed elimination order,
kept sparse, and their solve; and a sparse matrix–vector product.

The Newmark matrix :math:`\mathbf S = \mathbf M + \tfrac h2\mathbf C + \tfrac{h^2}{4}\mathbf K`
of a body on mount networks is an arrow: each network's internal coordinates couple only
to each other and to the body's. Eliminated networks first and the body last (the order
of fewest nonzeros first, :mod:`powertrain.solvers.transient_model` computes it once), its
factors have no fill-in but the body's rows, so a solve costs about the number of nonzeros
of S instead of :math:`n^2`, and a factorization a few of the networks' small blocks
instead of :math:`n^3`.

S is symmetric positive definite for passive mounts (every massless node held by a spring
or damper), where elimination needs no pivoting (Golub & Van Loan, *Matrix Computations*,
4th ed., 2013, §4.2). :func:`factor` swaps a row in only where a pivot is small against
its column (threshold pivoting, ibid. §3.4 and Duff, Erisman & Reid, *Direct Methods for
Sparse Matrices*, 2nd ed., 2017, §5.4): never for such an S, so its factors stay sparse;
any other regular S is still solved, with fill-in.

S's pattern is the same at every factorization of a run (only the values of C and K
change), so :func:`lu_pattern` finds its factors' pattern once (symbolic factorization,
Duff, Erisman & Reid §10.2) and :func:`factor_on_pattern` computes the values on it: work
about the factors' nonzeros. Where a pivot would need a swap it says so, and the caller
falls back to :func:`factor`.
"""

import numpy as np
from numba import njit

#: A pivot below this share of its column's largest entry is swapped for that entry's row.
PIVOT_THRESHOLD = 0.01


@njit(cache=True, nogil=True)
def factor(M, C, K, c, k, perm):
    """``(ok, B, rows)``: the LU factors of S = ``M + c C + k K`` (n, n) with its columns
    in the order ``perm`` (int64, n) in one array ``B`` (L strictly below the diagonal with
    a unit diagonal, U on and above) and the order of its rows ``rows``: ``perm`` but where
    a pivot is below :data:`PIVOT_THRESHOLD` of its column's largest entry, whose row is
    swapped in (threshold pivoting: none for a positive definite S, whose factors keep its
    sparsity); ``ok`` False where a column has no nonzero entry left (S singular)."""
    n = M.shape[0]
    B = np.empty((n, n))
    rows = perm.copy()
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
    """``(starts, columns)`` (int64) of the rows of the boolean ``mask`` (m, n): its
    ``True`` entries row by row, columns ascending (:func:`compressed`'s layout)."""
    rows, columns = np.nonzero(mask)
    starts = np.zeros(mask.shape[0] + 1, np.int64)
    np.cumsum(np.bincount(rows, minlength=mask.shape[0]), out=starts[1:])
    return starts, columns.astype(np.int64)


def lu_pattern(mask):
    """``(L rows, L columns, U rows)``, each ``(starts, indices)`` (:func:`csr_pattern`):
    the entries of the LU factors, without row swaps, of a matrix whose nonzeros are
    ``mask`` (n, n), already in its elimination order: its own and the fill-in
    (symbolic elimination)."""
    P = np.array(mask, bool)
    _fill_in(P)
    lower = np.tril(P, -1)
    return csr_pattern(lower), csr_pattern(lower.T), csr_pattern(np.triu(P, 1))


@njit(cache=True, nogil=True)
def _fill_in(P):
    """Mark in the boolean ``P`` (n, n), in place, the entries elimination without row
    swaps fills in: row ``i`` takes row ``col``'s pattern right of ``col`` wherever
    ``P[i, col]``."""
    n = P.shape[0]
    for col in range(n):
        for i in range(col + 1, n):
            if P[i, col]:
                for j in range(col + 1, n):
                    if P[col, j]:
                        P[i, j] = True


@njit(cache=True, nogil=True)
def factor_on_pattern(terms, where, pattern, B, factors):
    """The LU factors of S = Σ coefficient × A over ``terms`` (a tuple of ``(A compressed,
    coefficient)``, :func:`compressed`) in the order whose position of each coordinate is
    ``where`` (int64, n), into ``factors`` (:func:`sparse_factors`' layout on
    :func:`lu_pattern`'s ``pattern``); ``B`` (n, n) work space. False, leaving ``factors``
    unfinished, where a pivot is below :data:`PIVOT_THRESHOLD` of its column's largest
    entry or a column is zero: :func:`factor` then decides (a row swap, or S singular).
    Without a swap, the same arithmetic as :func:`factor`."""
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
    """``(starts, columns, values)``: the rows of ``A`` (m, n) compressed (CSR), the
    entries below the diagonal where ``lower``, above it where ``upper``, the diagonal where
    both; zeros left out."""
    m, n = A.shape
    starts, columns, values = np.zeros(m + 1, np.int64), np.empty(m * n, np.int64), \
        np.empty(m * n)
    k = 0
    for i in range(m):
        for j in range(n):
            if A[i, j] != 0.0 and ((j < i and lower) or (j > i and upper)
                                   or (j == i and lower and upper)):
                columns[k] = j
                values[k] = A[i, j]
                k += 1
        starts[i + 1] = k
    return starts, columns[:k].copy(), values[:k].copy()


@njit(cache=True, nogil=True)
def sparse_factors(B):
    """``(L, U, inverse diagonal)`` of :func:`factor`'s ``B``: the strict triangles
    compressed (:func:`compressed`) and the reciprocals of U's diagonal."""
    inv_d = np.empty(B.shape[0])
    for i in range(B.shape[0]):
        inv_d[i] = 1.0 / B[i, i]
    return compressed(B, True, False), compressed(B, False, True), inv_d


@njit(cache=True, nogil=True)
def lu_solve(factors, rows, perm, b, y, out):
    """``out`` = S^-1 ``b`` (n,) from :func:`sparse_factors`' ``factors`` of S, its rows in
    the order ``rows`` and its columns in the order ``perm`` (:func:`factor`); ``y`` (n,)
    is work space."""
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
    """``out[:, e]`` = S^-1 ``B[e]`` for every row of ``B`` (m, n) at once, as
    :func:`lu_solve` does each (the same arithmetic, bit for bit), the factors read once;
    ``Y`` (n, m) is work space and ``out`` (n, m)."""
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
    """``out -= C v`` then ``-= K x`` row by row, ``C`` and ``K`` compressed on one pattern
    (:func:`compressed`'s layout; the same sums as :func:`subtract_product` twice, in one
    pass over the pattern)."""
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
