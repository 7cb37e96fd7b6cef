"""The sparse LU of the transient's Newmark matrix (kernels/sparse_lu.py) against
numpy.linalg.solve, its factorization on a fixed pattern against the general one, and the
transient piece, with and without row swaps, against a Newmark step written out here."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from powertrain.kernels.sparse_lu import (
    compressed,
    factor,
    factor_on_pattern,
    lu_pattern,
    lu_solve,
    lu_solve_rows,
    sparse_factors,
    subtract_product,
    subtract_products,
)
from powertrain.kernels.transient import NEEDS_PIVOTING, _piece, _scaled
from powertrain.solvers.transient_model import _elimination_order, kernel_model


def arrow(rng, networks, inner, body=6):
    """A symmetric positive definite matrix of a body (``body`` coordinates first) on
    ``networks`` networks of ``inner`` internal coordinates each, coupled to the body and
    within each network only; the spread of its entries as S's (mass and h²/4 K)."""
    n = body + networks * inner
    A = np.zeros((n, n))
    B = rng.standard_normal((body, body))
    A[:body, :body] = B @ B.T + body * np.eye(body)
    for k in range(networks):
        i = slice(body + k * inner, body + (k + 1) * inner)
        R = rng.standard_normal((body + inner, body + inner)) * 10.0 ** rng.uniform(-3, 3)
        block = np.zeros((n, n))
        idx = np.r_[np.arange(body), np.arange(n)[i]]
        block[np.ix_(idx, idx)] = R @ R.T
        A += block
    return A


def solve(S, perm, b):
    """S^-1 b by the sparse factors, and the factors' array."""
    zero = np.zeros_like(S)
    ok, B, rows = factor(S, zero, zero, 0.0, 0.0, perm)
    assert ok
    out = np.empty(b.size)
    lu_solve(sparse_factors(B), rows, perm, b, np.empty(b.size), out)
    return out, B, rows


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 9), st.integers(1, 4), st.integers(0, 2**32 - 1))
def test_the_sparse_solve_is_numpys_and_fills_only_the_body_rows(networks, inner, seed):
    rng = np.random.default_rng(seed)
    S = arrow(rng, networks, inner)
    b = rng.standard_normal(S.shape[0])
    perm = _elimination_order(S)
    x, B, rows = solve(S, perm, b)
    ref = np.linalg.solve(S, b)
    assert np.array_equal(rows, perm)                     # positive definite: no swap
    np.testing.assert_allclose(x, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    # the body's coordinates are eliminated last and no network's row gains an entry of
    # another network: the factors are as sparse as S
    if networks > 1:                            # with one, every row is full
        assert set(perm[-6:]) == set(range(6))
    fill = (B != 0) & (S[np.ix_(perm, perm)] == 0)
    assert not fill[:-6, :-6].any()


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 9), st.integers(1, 4), st.integers(1, 9), st.booleans(),
       st.integers(0, 2**32 - 1))
def test_many_right_hand_sides_and_a_joint_pattern_are_the_single_ones_bit_for_bit(
        networks, inner, m, swap, seed):
    """lu_solve_rows is lu_solve on each row (also with row swaps); subtract_products on one
    pattern (explicit zeros where only the other matrix has an entry) is subtract_product
    twice."""
    rng = np.random.default_rng(seed)
    S = arrow(rng, networks, inner)
    n = S.shape[0]
    perm = _elimination_order(S)
    if swap:                                   # a zero pivot: factor() swaps a row in
        S[perm[0], perm[0]] = 0.0
    zero = np.zeros_like(S)
    ok, B, rows = factor(S, zero, zero, 0.0, 0.0, perm)
    assert ok
    factors = sparse_factors(B)
    P = rng.standard_normal((m, n)) * (rng.random((m, n)) < 0.4)
    W = np.empty((n, m))
    lu_solve_rows(factors, rows, perm, P, np.empty((n, m)), W)
    for e in range(m):
        one = np.empty(n)
        lu_solve(factors, rows, perm, P[e], np.empty(n), one)
        assert np.array_equal(W[:, e], one)
    C, K = (A * (rng.random(A.shape) < 0.5) for A in (arrow(rng, networks, inner),) * 2)
    joint = (C != 0) | (K != 0)
    starts, columns, _ = compressed(joint.astype(float), True, True)
    on_joint = [(starts, columns, A[joint]) for A in (C, K)]
    v, x, out = rng.standard_normal((3, n))
    want = out.copy()
    subtract_product(compressed(C, True, True), v, want)
    subtract_product(compressed(K, True, True), x, want)
    subtract_products(*on_joint[:1], v, on_joint[1], x, out)
    assert np.array_equal(out, want)


def on_pattern(M, C, K, c, k, perm):
    """``(ok, factors)`` of :func:`factor_on_pattern` on S = M + c C + k K's own pattern."""
    where = np.empty_like(perm)
    where[perm] = np.arange(perm.size)
    mask = ((M != 0) | (C != 0) | (K != 0))[np.ix_(perm, perm)]
    (lp, li), _, (up, ui) = pattern = lu_pattern(mask)
    n = M.shape[0]
    factors = ((lp, li, np.empty(li.size)), (up, ui, np.empty(ui.size)), np.empty(n))
    terms = tuple((compressed(A, True, True), coefficient)
                  for A, coefficient in ((M, 1.0), (C, c), (K, k)))
    return factor_on_pattern(terms, where, pattern, np.empty((n, n)), factors), factors


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 9), st.integers(1, 4), st.integers(0, 2**32 - 1))
def test_factors_on_a_fixed_pattern_are_the_general_ones_bit_for_bit(networks, inner, seed):
    rng = np.random.default_rng(seed)
    M, C, K = (arrow(rng, networks, inner) for _ in range(3))
    gone = rng.random(C.shape[0]) < 0.3           # C's pattern smaller than S's, C still
    C[gone, :] = C[:, gone] = 0.0                   # positive semidefinite
    perm = _elimination_order(M, C, K)
    ok, factors = on_pattern(M, C, K, 0.5e-3, 0.25e-6, perm)
    assert ok
    B = factor(M, C, K, 0.5e-3, 0.25e-6, perm)[1]
    for (starts, columns, values), want in zip(factors[:2], (np.tril(B, -1), np.triu(B, 1)),
                                               strict=True):
        got = np.zeros_like(B)
        got[np.repeat(np.arange(B.shape[0]), np.diff(starts)), columns] = values
        assert np.array_equal(got, want)
    assert np.array_equal(factors[2], 1.0 / np.diag(B))
    # a pivot that needs a row swap: the fixed pattern says so and leaves it to factor()
    K_zero = K.copy()
    K_zero[perm[0], perm[0]] = -(M[perm[0], perm[0]] + 0.5e-3 * C[perm[0], perm[0]]) / 0.25e-6
    assert not on_pattern(M, C, K_zero, 0.5e-3, 0.25e-6, perm)[0]


def test_a_small_pivot_is_swapped_and_a_singular_matrix_refused():
    rng = np.random.default_rng(3)
    S = rng.standard_normal((7, 7))
    S[0, 0] = S[3, 3] = 0.0                       # no elimination without a row swap
    b = rng.standard_normal(7)
    x, _, rows = solve(S, np.arange(7), b)
    assert not np.array_equal(rows, np.arange(7))
    np.testing.assert_allclose(S @ x, b, atol=1e-12 * np.abs(b).max() * np.linalg.cond(S))
    S[:, 4] = 0.0
    zero = np.zeros_like(S)
    assert not factor(S, zero, zero, 0.0, 0.0, np.arange(7))[0]


def work(model):
    """The piece's work space (as transient_stretch_kernel makes it)."""
    (lp, li), _, (up, ui) = model[8]
    n = model[0].shape[0]
    return np.empty((n, n)), ((lp, li, np.empty(li.size)), (up, ui, np.empty(ui.size)),
                              np.empty(n))


def newmark(M, C, K, F, h, x, v):
    """Average-acceleration Newmark written out (numpy, dense): the states (k + 1, n)."""
    X, V, A = [x], [v], [np.linalg.solve(M, F[0] - C @ v - K @ x)]
    S = M + h / 2 * C + h * h / 4 * K
    for f in F[1:]:
        xt = X[-1] + h * V[-1] + h * h / 4 * A[-1]
        vt = V[-1] + h / 2 * A[-1]
        a = np.linalg.solve(S, f - C @ vt - K @ xt)
        X.append(xt + h * h / 4 * a)
        V.append(vt + h / 2 * a)
        A.append(a)
    return np.array(X), np.array(V), np.array(A)


def test_a_piece_is_newmarks_with_and_without_row_swaps():
    rng = np.random.default_rng(1)
    M = np.diag(rng.uniform(1, 5, 8))
    C = arrow(rng, 2, 1) * 1e-2
    K = arrow(rng, 2, 1) * 1e3
    h, steps = 1e-3, 50
    F = rng.standard_normal((steps + 1, 8))
    x, v = rng.standard_normal(8) * 1e-3, rng.standard_normal(8) * 1e-2
    ref = newmark(M, C, K, F, h, x, v)
    perm = _elimination_order(M, C, K)
    first = perm[0]
    K_zero = K.copy()                   # S's first pivot 0: the elimination swaps rows
    K_zero[first, first] = -(M[first, first] + h / 2 * C[first, first]) * 4 / h ** 2
    for K_used in (K, K_zero):
        rows = factor(M, C, K_used, h / 2, h * h / 4, perm)[2]
        assert np.array_equal(rows, perm) == (K_used is K)
        ref = newmark(M, C, K_used, F, h, x, v)
        none = np.zeros((0, 8, 8))
        X, V, A = (np.empty((steps + 1, 8)) for _ in range(3))
        for pivoting in (False, True):
            model = kernel_model(M, C, K_used, none, none, np.zeros((0, 2)), pivoting)
            failed = _piece(model, None, h, _scaled(model[3], np.zeros(0)),
                            _scaled(model[4], np.zeros(0)), F, np.zeros(8), x, v, np.empty(0),
                            X, V, A, np.empty((steps + 1, 0)), 1e-12, 10, work(model),
                            model[9])
            # without pivoting compiled in, a swap is asked for instead of made
            assert failed == (NEEDS_PIVOTING if K_used is K_zero and not pivoting else 0)
        for got, want in zip((X, V, A), ref, strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
