r"""Newmark average-acceleration kernels (β = 1/4, γ = 1/2) in acceleration form.

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

No inverse of :math:`\mathbf M` is needed: massless nodes with a spring or damper are
allowed. Unconditionally stable, no numerical damping, period error :math:`(\omega h)^2/12`.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def newmark_kernel(G, H, Fs, h, x0, v0, a0, X, V, A):
    """Integrate ``Fs.shape[0] - 1`` steps into X, V, A (rows = time steps).

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
    n, ns, hh, hv = x0.shape[0], Fs.shape[0], 0.25 * h * h, 0.5 * h
    xt, vt = np.empty(n), np.empty(n)
    for j in range(n):
        X[0, j], V[0, j], A[0, j] = x0[j], v0[j], a0[j]
    for k in range(1, ns):
        for j in range(n):
            xt[j] = X[k - 1, j] + h * V[k - 1, j] + hh * A[k - 1, j]
            vt[j] = V[k - 1, j] + hv * A[k - 1, j]
        for i in range(n):
            s = Fs[k, i]
            Gi, Hi = G[i], H[i]            # row views: 2-D indexing in the inner loop is slower
            for j in range(n):
                s -= Gi[j] * vt[j] + Hi[j] * xt[j]
            A[k, i] = s
        for j in range(n):
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]


@njit(cache=True, nogil=True)
def modal_trapezoid_kernel(lam_d, gain, G, n_steps, eta0, keep_from, out_re, out_im):
    r"""Newmark average acceleration (the trapezoidal rule) in the modal coordinates of
    :math:`\dot{\mathbf z} = \mathbf A\mathbf z + \mathbf b(t)`,
    :math:`\mathbf A = \boldsymbol\Psi\boldsymbol\Lambda\boldsymbol\Psi^{-1}`:

    .. math:: \eta_{k} = \lambda_d\,\eta_{k-1} + \gamma\,(g_{k-1} + g_k),\qquad
              \lambda_d = \frac{1 + h\lambda/2}{1 - h\lambda/2},\quad
              \gamma = \frac{h/2}{1 - h\lambda/2}.

    Parameters
    ----------
    lam_d, gain : ndarray complex (m,)
        :math:`\lambda_d` and :math:`\gamma` of each mode.
    G : ndarray complex (N, m)
        Modal loads :math:`\boldsymbol\Psi^{-1}\mathbf b(t_k)` over one load period;
        step k uses row ``k % N``.
    n_steps : int
        Steps to integrate.
    eta0 : ndarray complex (m,)
        Initial modal coordinates.
    keep_from : int
        First time index written to the outputs.
    out_re, out_im : ndarray float (n_steps + 1 - keep_from, m)
        Real and imaginary parts of the modal coordinates.
    """
    m, N = eta0.shape[0], G.shape[0]
    eta = eta0.copy()
    if keep_from == 0:
        for j in range(m):
            out_re[0, j], out_im[0, j] = eta[j].real, eta[j].imag
    for k in range(1, n_steps + 1):
        kp, kc = (k - 1) % N, k % N
        for j in range(m):
            eta[j] = lam_d[j] * eta[j] + gain[j] * (G[kp, j] + G[kc, j])
        if k >= keep_from:
            for j in range(m):
                out_re[k - keep_from, j], out_im[k - keep_from, j] = eta[j].real, eta[j].imag
