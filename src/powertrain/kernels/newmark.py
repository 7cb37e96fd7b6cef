r"""Newmark average-acceleration kernel (β = 1/4, γ = 1/2) in acceleration form.

For :math:`\mathbf M\ddot{\mathbf x} + \mathbf C\dot{\mathbf x} + \mathbf K\mathbf x = \mathbf f(t)`
one step of size :math:`h` is

.. math::
    \tilde{\mathbf x} = \mathbf x_n + h\dot{\mathbf x}_n + \tfrac{h^2}{4}\ddot{\mathbf x}_n,\quad
    \tilde{\mathbf v} = \dot{\mathbf x}_n + \tfrac{h}{2}\ddot{\mathbf x}_n,\\
    \mathbf S\,\ddot{\mathbf x}_{n+1} = \mathbf f_{n+1} - \mathbf C\tilde{\mathbf v}
        - \mathbf K\tilde{\mathbf x},\qquad
    \mathbf S = \mathbf M + \tfrac{h}{2}\mathbf C + \tfrac{h^2}{4}\mathbf K,\\
    \mathbf x_{n+1} = \tilde{\mathbf x} + \tfrac{h^2}{4}\ddot{\mathbf x}_{n+1},\quad
    \dot{\mathbf x}_{n+1} = \tilde{\mathbf v} + \tfrac{h}{2}\ddot{\mathbf x}_{n+1}.

The caller passes :math:`\mathbf G = \mathbf S^{-1}\mathbf C`, :math:`\mathbf H = \mathbf S^{-1}\mathbf K`
and the pre-multiplied loads :math:`\mathbf S^{-1}\mathbf f_n`, so a step costs two dense
matrix–vector products. The acceleration form needs no inverse of :math:`\mathbf M` and so
accepts massless nodes (S is regular when every massless node has a spring or damper).
Unconditionally stable, no numerical damping, period error :math:`(\omega h)^2/12`.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def newmark_kernel(G, H, Fs, h, x0, v0, a0, X, V, A):
    """Integrate ``Fs.shape[0] - 1`` steps; write states into X, V, A (rows = time steps).

    Parameters
    ----------
    G, H : ndarray (n, n)
        S^-1 C [1/s] and S^-1 K [1/s^2].
    Fs : ndarray (n_steps + 1, n)
        S^-1 f at every time point [m/s^2].
    h : float
        Time step [s].
    x0, v0, a0 : ndarray (n,)
        Initial state [m, m/s, m/s^2].
    X, V, A : ndarray (n_steps + 1, n)
        Output, row 0 = initial state.
    """
    n = x0.shape[0]
    ns = Fs.shape[0]
    hh = 0.25 * h * h
    hv = 0.5 * h
    xt = np.empty(n)
    vt = np.empty(n)
    for j in range(n):
        X[0, j] = x0[j]
        V[0, j] = v0[j]
        A[0, j] = a0[j]
    for k in range(1, ns):
        for j in range(n):
            xt[j] = X[k - 1, j] + h * V[k - 1, j] + hh * A[k - 1, j]
            vt[j] = V[k - 1, j] + hv * A[k - 1, j]
        for i in range(n):
            s = Fs[k, i]
            Gi = G[i]            # row views: 2-D indexing in the inner loop is slower
            Hi = H[i]
            for j in range(n):
                s -= Gi[j] * vt[j] + Hi[j] * xt[j]
            A[k, i] = s
        for j in range(n):
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]


@njit(cache=True, nogil=True)
def modal_trapezoid_kernel(lam_d, gain, G, n_steps, eta0, keep_from, out_re, out_im):
    r"""Newmark average acceleration in the modal coordinates of the first-order system.

    With :math:`\dot{\mathbf z} = \mathbf A\mathbf z + \mathbf b(t)` and
    :math:`\mathbf A = \boldsymbol\Psi\boldsymbol\Lambda\boldsymbol\Psi^{-1}`, the average
    acceleration rule is the trapezoidal rule, so each mode obeys

    .. math:: \eta_{k} = \lambda_d\,\eta_{k-1} + \gamma\,(g_{k-1} + g_k),\qquad
              \lambda_d = \frac{1 + h\lambda/2}{1 - h\lambda/2},\quad
              \gamma = \frac{h/2}{1 - h\lambda/2}.

    Parameters
    ----------
    lam_d, gain : ndarray complex (m,)
    G : ndarray complex (N, m)
        Modal loads :math:`\boldsymbol\Psi^{-1}\mathbf b(t_k)` over one load period of N
        steps; step k uses row ``k % N``.
    n_steps : int
    eta0 : ndarray complex (m,)
    keep_from : int
        First time index written to the outputs.
    out_re, out_im : ndarray float (n_steps + 1 - keep_from, m)
        Real and imaginary parts of the modal coordinates (separate contiguous arrays, so
        that the output mapping is two plain BLAS products).
    """
    m = eta0.shape[0]
    N = G.shape[0]
    eta = eta0.copy()
    if keep_from == 0:
        for j in range(m):
            out_re[0, j] = eta[j].real
            out_im[0, j] = eta[j].imag
    for k in range(1, n_steps + 1):
        kp = (k - 1) % N
        kc = k % N
        for j in range(m):
            eta[j] = lam_d[j] * eta[j] + gain[j] * (G[kp, j] + G[kc, j])
        if k >= keep_from:
            for j in range(m):
                out_re[k - keep_from, j] = eta[j].real
                out_im[k - keep_from, j] = eta[j].imag
