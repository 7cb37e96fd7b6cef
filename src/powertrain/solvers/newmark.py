r"""Newmark average-acceleration integrators and the periodic steady state.

:func:`newmark` wraps :func:`powertrain.kernels.newmark.newmark_kernel`; :func:`newmark_ports`
adds nonlinear port laws (:mod:`powertrain.physics.mount_elements`), Newton per step.
:func:`periodic_state` finds the exactly periodic state of the discrete recurrence under a
periodic load by shooting: the one-period map :math:`z \mapsto \Phi z + g` is affine, so
:math:`z_0 = (I-\Phi)^{-1} g`. :class:`ModalNewmark` and :class:`ModalPortNewmark` run the
same recurrence in modal coordinates.
"""

from __future__ import annotations

import copy
import threading

import numpy as np

from powertrain.kernels.newmark import modal_trapezoid_kernel, newmark_kernel
from powertrain.kernels.port_forces import modal_port_kernel, newmark_port_kernel


def _prepare(M, C, K, h):
    M = np.ascontiguousarray(M, dtype=float)
    C = np.ascontiguousarray(C, dtype=float)
    K = np.ascontiguousarray(K, dtype=float)
    n = M.shape[0]
    if M.shape != (n, n) or C.shape != (n, n) or K.shape != (n, n):
        raise ValueError("M, C, K must be square and of equal size")
    if not (np.isfinite(h) and h > 0):
        raise ValueError("time step must be positive")
    S = M + 0.5 * h * C + 0.25 * h * h * K
    Sinv = np.linalg.inv(S)
    return Sinv, np.ascontiguousarray(Sinv @ C), np.ascontiguousarray(Sinv @ K)


def newmark(M, C, K, F, h, x0=None, v0=None, a0=None):
    """Integrate M x'' + C x' + K x = f(t) with constant step ``h`` [s].

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m] (or consistent generalized units).
    F : ndarray (n_steps + 1, n)
        Load at every time point t_k = k h [N].
    h : float
        Time step [s].
    x0, v0, a0 : ndarray (n,), optional
        Initial state; zeros by default, ``a0`` from the equation of motion when M is regular.

    Returns
    -------
    X, V, A : ndarray (n_steps + 1, n)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    Fs, x0, v0, a0 = _start(M, C, K, F, Sinv, x0, v0, a0)
    X, V, A = (np.empty_like(Fs) for _ in range(3))
    newmark_kernel(G, H, Fs, float(h), x0, v0, a0, X, V, A)
    return X, V, A


def _start(M, C, K, F, Sinv, x0, v0, a0, port_force=None):
    """Pre-multiplied loads and the initial state (``a0`` consistent with ``port_force``)."""
    F = np.asarray(F, dtype=float)
    n = Sinv.shape[0]
    if F.ndim != 2 or F.shape[1] != n:
        raise ValueError("F must have shape (n_steps + 1, n)")
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float).copy()
    v0 = np.zeros(n) if v0 is None else np.asarray(v0, float).copy()
    if a0 is None:
        inner = 0.0 if port_force is None else port_force
        try:
            a0 = np.linalg.solve(M, F[0] - C @ v0 - K @ x0 - inner)
        except np.linalg.LinAlgError:
            a0 = np.zeros(n)
    return np.ascontiguousarray(F @ Sinv.T), x0, v0, np.asarray(a0, float).copy()


#: Newton tolerance of the port laws per step (relative to 1 + the largest port force [N])
#: and its iteration limit.
PORT_TOL = 1e-10
PORT_MAX_ITER = 50


def newmark_ports(M, C, K, F, h, ports, x0=None, v0=None, a0=None, z0=None, state=None):
    """:func:`newmark` (same ``M, C, K, F, h, x0, v0, a0``) with the port laws ``ports``
    (:class:`~powertrain.physics.mount_elements.PortForces`) in parallel, Newton per step.
    The laws start from ``state`` (m, n_state), updated in place, or else from the state
    carrying the forces ``z0`` (m,) [N] (default: unloaded).

    Returns
    -------
    X, V, A : ndarray (n_steps + 1, n)
    Z : ndarray (n_steps + 1, m)
        Port forces [N] (positive: pushing the base along the port row).

    Raises
    ------
    FloatingPointError
        Newton did not converge at some step (the names of the port laws are given).
    """
    Sinv, G, H = _prepare(M, C, K, h)
    P = np.ascontiguousarray(ports.rows, float)
    x0 = np.zeros(P.shape[1]) if x0 is None else x0
    v0 = np.zeros(P.shape[1]) if v0 is None else v0
    state = ports.initial_state(x0, z0) if state is None else state
    z0 = ports.forces(P @ x0, P @ v0, state)
    Fs, x0, v0, a0 = _start(M, C, K, F, Sinv, x0, v0, a0, P.T @ z0)
    W = np.ascontiguousarray(Sinv @ P.T)
    X, V, A = (np.empty_like(Fs) for _ in range(3))
    Z = np.empty((Fs.shape[0], P.shape[0]))
    failed = newmark_port_kernel(G, H, Fs, float(h), x0, v0, a0, W, P,
                                 np.ascontiguousarray(P @ W), ports.kinds, ports.parameters,
                                 state, X, V, A, Z, PORT_TOL, PORT_MAX_ITER)
    if failed:
        raise FloatingPointError(f"port laws {', '.join(ports.names)}: Newton did not converge "
                                 f"at {failed} of {Fs.shape[0] - 1} steps")
    return X, V, A, Z


def periodic_state(M, C, K, F_period, h):
    """Initial state (x0, v0, a0) of the periodic steady state of the Newmark recurrence.

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m].
    F_period : ndarray (N + 1, n)
        Load over exactly one period, ``F_period[N] == F_period[0]``.
    h : float
        Time step [s]; N h is the period.

    Returns
    -------
    x0, v0, a0 : ndarray (n,)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    F_period = np.asarray(F_period, float)
    n = G.shape[0]
    N = F_period.shape[0] - 1
    zero = np.zeros((N + 1, n))
    Fs = np.ascontiguousarray(F_period @ Sinv.T)
    X, V, A = (np.empty_like(Fs) for _ in range(3))
    newmark_kernel(G, H, Fs, float(h), np.zeros(n), np.zeros(n), np.zeros(n), X, V, A)
    g = np.concatenate([X[-1], V[-1], A[-1]])
    Phi = np.empty((3 * n, 3 * n))
    e = np.zeros(3 * n)
    for col in range(3 * n):
        e[:] = 0.0
        e[col] = 1.0
        newmark_kernel(G, H, zero, float(h), e[:n].copy(), e[n:2 * n].copy(), e[2 * n:].copy(), X, V, A)
        Phi[:, col] = np.concatenate([X[-1], V[-1], A[-1]])
    z0 = np.linalg.lstsq(np.eye(3 * n) - Phi, g, rcond=None)[0]
    return z0[:n], z0[n:2 * n], z0[2 * n:]


class ModalNewmark:
    r"""Newmark average acceleration for a linear time-invariant model, in modal coordinates.

    Average acceleration (β = 1/4, γ = 1/2) is the trapezoidal rule on
    :math:`\dot{\mathbf z} = \mathbf A\mathbf z + \mathbf b`, :math:`\mathbf z = (\mathbf x,
    \dot{\mathbf x})`, :math:`\mathbf A = \begin{bmatrix}0 & I\\ -M^{-1}K & -M^{-1}C
    \end{bmatrix}`, whose propagator shares the eigenvectors of :math:`\mathbf A`: one
    eigendecomposition makes every step a diagonal recurrence
    (:func:`~powertrain.kernels.newmark.modal_trapezoid_kernel`) equal to :func:`newmark` to
    round-off (tests/test_runup.py). Needs a regular mass matrix.

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m].
    load_dofs : int
        The load acts on the first ``load_dofs`` coordinates (6: the rigid body).
    """

    def __init__(self, M, C, K, load_dofs=None):
        M = np.asarray(M, float)
        n = M.shape[0]
        Minv = np.linalg.inv(M)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -Minv @ K
        A[n:, n:] = -Minv @ np.asarray(C, float)
        lam, Psi = np.linalg.eig(A)
        self.n, self.lam, self.Psi, self.Psi_inv = n, lam, Psi, np.linalg.inv(Psi)
        nl = n if load_dofs is None else int(load_dofs)
        self.load_dofs = nl
        self.M, self.C, self.K, self.Minv = M, np.asarray(C, float), np.asarray(K, float), Minv
        err = np.linalg.norm(Psi @ np.diag(lam) @ self.Psi_inv - A) / np.linalg.norm(A)
        if not err < 1e-8:
            raise np.linalg.LinAlgError(f"state matrix not safely diagonalisable ({err:.1e})")
        #: modal load per unit generalized load: Psi^-1 [0; M^-1 B]
        self.load_map = self.Psi_inv[:, n:] @ Minv[:, :nl]
        # a conjugate pair's modal coordinates are conjugate: step one, count it twice
        scale = np.abs(lam).max()
        real_mode = np.abs(lam.imag) <= 1e-12 * scale
        keep = real_mode | (lam.imag > 0)
        if not np.isclose(2 * np.count_nonzero(lam.imag > 0) + np.count_nonzero(real_mode), lam.size):
            raise np.linalg.LinAlgError("eigenvalues not in conjugate pairs")
        order = np.r_[np.flatnonzero(keep & ~real_mode), np.flatnonzero(real_mode)]
        #: kept modes with a complex eigenvalue (the first ones)
        self.n_complex = int(np.count_nonzero(keep & ~real_mode))
        weight = np.where(real_mode[order], 1.0, 2.0)
        self._work = threading.local()   # per-thread output buffers, see run_outputs
        self.lam_r = lam[order]
        self.Psi_r = Psi[:, order] * weight[None, :]
        self.Psi_inv_r = self.Psi_inv[order]
        self.load_map_r = self.load_map[order]

    def real_form(self, a) -> np.ndarray:
        """``a`` (..., kept modes) in the kernels' real form: real parts, then the imaginary
        parts of the complex modes. A row ``r`` read as ``Re(r eta)`` is ``real_form(conj(r))``."""
        a = np.asarray(a)
        return np.ascontiguousarray(np.concatenate([a.real, a.imag[..., :self.n_complex]], axis=-1))

    def run(self, F, h, x0, v0, keep_from=0):
        """Integrate with the load ``F`` (n_steps + 1, load_dofs) [N] at step ``h`` [s] from
        ``x0``, ``v0``.

        Returns
        -------
        X, V, A : ndarray (n_steps + 1 - keep_from, n)
            States from time index ``keep_from`` on (A from the equation of motion).
        """
        F = np.asarray(F, float)
        lam_d = (1 + 0.5 * h * self.lam) / (1 - 0.5 * h * self.lam)
        gain = (0.5 * h) / (1 - 0.5 * h * self.lam)
        G = np.ascontiguousarray(F @ self.load_map.T)
        eta0 = self.Psi_inv @ np.concatenate([x0, v0]).astype(complex)
        shape = (F.shape[0] - keep_from, self.lam.size)
        out_re, out_im = np.empty(shape), np.empty(shape)
        modal_trapezoid_kernel(lam_d, gain, G, F.shape[0] - 1, eta0, int(keep_from), out_re, out_im)
        Z = out_re @ self.Psi.T.real - out_im @ self.Psi.T.imag
        X, V = Z[:, :self.n], Z[:, self.n:]
        f_full = np.zeros((F.shape[0] - keep_from, self.n))
        f_full[:, :self.load_dofs] = F[keep_from:]
        A = (f_full - V @ self.C.T - X @ self.K.T) @ self.Minv.T
        return X, V, A

    def output_map(self, Wx, Wv, Wa=None):
        """``(W_modal, W_load)`` of the outputs ``y = Wx x + Wv v (+ Wa a)`` (rows = outputs):
        ``y = Re(eta @ W_modal.T) + F @ W_load.T``, ``W_modal`` as (Re W^T, Im W^T)."""
        n = self.n
        Wm = np.asarray(Wx, float) @ self.Psi_r[:n] + np.asarray(Wv, float) @ self.Psi_r[n:]
        W_load = np.zeros((Wm.shape[0], self.load_dofs))
        if Wa is not None:
            Wa = np.asarray(Wa, float)
            Wm = Wm + Wa @ (self.Psi_r[n:] * self.lam_r[None, :])
            W_load = Wa @ self.Minv[:, :self.load_dofs]
        return (np.ascontiguousarray(Wm.real.T), np.ascontiguousarray(Wm.imag.T)), W_load

    def harmonic_state(self, load_harmonics, omegas):
        """Steady state (x, v) at t = 0 under ``load_harmonics`` at ``omegas`` [rad/s]:
        eta_j = (Psi^-1 b_j) / (i w_j - lambda), z(0) = Re sum_j Psi eta_j."""
        g = np.asarray(load_harmonics, complex) @ self.load_map.T          # (n_h, m)
        eta = g / (1j * np.asarray(omegas, float)[:, None] - self.lam[None, :])
        z0 = (self.Psi @ eta.sum(axis=0)).real
        return z0[:self.n], z0[self.n:]

    def port_modes(self, rows):
        """``(Pm, Bp, K)`` of the port ``rows`` (m, n): the rows on the modes ``Pm`` (m, 2 n),
        the modal load of a unit force along each row ``Bp`` (2 n, m), and
        ``K`` (2 n, m m) = ``Pm[:, j] Bp[j]``."""
        n = self.n
        Pm, Bp = rows @ self.Psi[:n], self.Psi_inv[:, n:] @ (self.Minv @ rows.T)
        return Pm, Bp, (Pm.T[:, :, None] * Bp[:, None, :]).reshape(Bp.shape[0], -1)

    def port_harmonics(self, modes, load_harmonics, omegas):
        """``(g, ef, uf, Hp)`` per harmonic of ``load_harmonics`` (n_h, load_dofs) [N] at
        ``omegas`` [rad/s]: ``g`` = 1 / (i omega - lambda), the modal amplitudes ``ef``, the
        motions ``uf`` (n_h, m) [m] along the port rows of ``modes`` (:meth:`port_modes`) and
        per unit force along each, ``Hp`` (n_h, m, m) [m/N]; port forces ``z`` give modal
        amplitudes ``ef - g (z Bp^T)``."""
        Pm, _, K = modes
        g = 1.0 / (1j * np.asarray(omegas, float)[:, None] - self.lam[None, :])
        ef = g * (np.asarray(load_harmonics, complex) @ self.load_map.T)
        return g, ef, ef @ Pm.T, (g @ K).reshape(-1, Pm.shape[0], Pm.shape[0])

    def run_outputs(self, F_cycle, cycles, h, x0, v0, keep_from, W_modal, W_load):
        """Outputs ``y`` (:meth:`output_map` ``W_modal``, ``W_load``) from time index
        ``keep_from`` of ``cycles`` repetitions of ``F_cycle`` (N, load_dofs) [N] at step
        ``h`` [s] from ``x0``, ``v0``. The result is a per-thread work buffer, valid until the
        thread's next call."""
        F_cycle = np.asarray(F_cycle, float)
        N = F_cycle.shape[0]
        lam_d = (1 + 0.5 * h * self.lam_r) / (1 - 0.5 * h * self.lam_r)
        gain = (0.5 * h) / (1 - 0.5 * h * self.lam_r)
        rows = cycles * N + 1 - keep_from
        out_re, out_im, Y, tmp, G = self._buffers(rows, W_modal[0].shape[1], N)
        np.matmul(F_cycle, self.load_map_r.T, out=G)
        eta0 = self.Psi_inv_r @ np.concatenate([x0, v0]).astype(complex)
        modal_trapezoid_kernel(lam_d, gain, G, cycles * N, eta0, int(keep_from), out_re, out_im)
        np.matmul(out_re, W_modal[0], out=Y)
        np.matmul(out_im, W_modal[1], out=tmp)
        Y -= tmp
        if np.any(W_load):
            idx = (np.arange(keep_from, cycles * N + 1)) % N
            np.matmul(F_cycle[idx], W_load.T, out=tmp)
            Y += tmp
        return Y

    def _buffers(self, rows, n_out, n_load):
        """Thread-local work arrays."""
        key = (rows, n_out, n_load)
        work = self._work
        if getattr(work, "key", None) != key:
            m = self.lam_r.size
            work.key = key
            work.arrays = (np.empty((rows, m)), np.empty((rows, m)), np.empty((rows, n_out)),
                           np.empty((rows, n_out)), np.empty((n_load, m), dtype=complex))
        return work.arrays


class ModalPortNewmark:
    r""":func:`newmark_ports` in modal coordinates for fixed matrices
    (:func:`powertrain.kernels.port_forces.modal_port_kernel`; equal to :func:`newmark_ports`
    to round-off and the Newton tolerance, tests/test_time_domain_laws.py), the port motions
    read on the coordinates the load and the port rows touch. Outputs ``y = Wx x + Wv v +
    Wa a + Wz z`` (None: no such term).

    Parameters
    ----------
    modal : ModalNewmark
    ports : PortForces
        The port laws (every row with a law; ``ports.select(ports.kinds != NONE)``).
    h : float
        Time step [s].
    Wx, Wv, Wa : ndarray (n_out, n), optional
        Output rows over the coordinates.
    Wz : ndarray (n_out, m), optional
        Output rows over the port forces.
    """

    def __init__(self, modal, ports, h, Wx=None, Wv=None, Wa=None, Wz=None):
        n = modal.n
        self.modal, self.ports = modal, ports
        P = np.asarray(ports.rows, float)
        self.reduced = r = np.union1d(np.arange(modal.load_dofs), np.flatnonzero(np.any(P != 0, 0)))
        #: rows reading the reduced state (x, v, a less M^-1 p) off the modal state
        self._reduced_rows = modal.real_form(np.conj(np.vstack(
            [modal.Psi_r[r], modal.Psi_r[n + r], modal.Psi_r[n + r] * modal.lam_r])))
        self.outputs = self._output_arrays(Wx, Wv, Wa, Wz)
        self.silent = self._output_arrays(np.zeros((0, n)))
        #: step-independent: port rows, modal map of the forces, modes' accelerations and
        #: M^-1 on the reduced coordinates, and where the load sits among them
        self._fixed = (np.ascontiguousarray(P[:, r]), modal.Psi_inv_r[:, n:] @ modal.Minv[:, r],
                       modal.Psi_r[n + r] * modal.lam_r, modal.Minv[np.ix_(r, r)],
                       np.searchsorted(r, np.arange(modal.load_dofs)).astype(np.int64))
        self._set_step(h)

    def at_step(self, h) -> ModalPortNewmark:
        """The same model, port laws and outputs at the time step ``h`` [s]."""
        other = copy.copy(self)
        other._set_step(h)
        return other

    def _set_step(self, h):
        """The kernel's arrays that depend on the time step ``h`` [s]."""
        modal = self.modal
        T, load_map, Pa, Minv_r, load_at = self._fixed
        self.h = float(h)
        lam = modal.lam_r
        lam_d = (1 + 0.5 * h * lam) / (1 - 0.5 * h * lam)
        G = ((0.5 * h) / (1 - 0.5 * h * lam))[:, None] * load_map          # (n_modes, q)
        Da = (Pa @ G).real
        S = Da + Minv_r
        self.modal_arrays = ((lam_d.real.copy(), lam_d.imag[:modal.n_complex].copy()),
                             modal.real_form(G.T), modal.real_form(np.conj(Pa * lam_d)),
                             (np.ascontiguousarray(Da), np.ascontiguousarray(S)), self.h)
        self.port_arrays = (T, load_at, np.ascontiguousarray(0.25 * h * h * (T @ S @ T.T)))

    def _output_arrays(self, Wx=None, Wv=None, Wa=None, Wz=None):
        """``((Wyz, y_cols, z_cols), w_rows, W, Wd)`` of :func:`modal_port_kernel` for the outputs."""
        modal, n, r = self.modal, self.modal.n, self.reduced
        off = np.setdiff1d(np.arange(n), r)
        rows = next(w.shape[0] for w in (Wx, Wv, Wa, Wz) if w is not None)
        W = np.zeros((rows, self.modal.lam_r.size), complex)
        Wd = np.zeros((rows, r.size))
        Wy = np.zeros((rows, 3, r.size))
        for i, (Wk, Psi) in enumerate(((Wx, modal.Psi_r[:n]), (Wv, modal.Psi_r[n:]),
                                       (Wa, modal.Psi_r[n:] * modal.lam_r[None, :]))):
            if Wk is not None:
                Wk = np.asarray(Wk, float)
                Wy[:, i] = Wk[:, r]
                W += Wk[:, off] @ Psi[off]
        if Wa is not None:
            Wd = np.asarray(Wa, float)[:, off] @ modal.Minv[np.ix_(off, r)]
        Wz = np.zeros((rows, self.ports.kinds.size)) if Wz is None else np.asarray(Wz, float)
        w_rows = np.flatnonzero(np.any(W != 0, 1) | np.any(Wd != 0, 1))
        (Wy, y_cols), (Wz, z_cols) = _read_columns(Wy.reshape(rows, 3 * r.size)), _read_columns(Wz)
        return ((np.ascontiguousarray(np.hstack([Wy, Wz])), y_cols, z_cols),
                w_rows.astype(np.int64), modal.real_form(np.conj(W[w_rows])),
                np.ascontiguousarray(Wd[w_rows]))

    def modal_state(self, x, v) -> np.ndarray:
        """Modal coordinates of the state ``(x, v)`` in the kernel's real form."""
        return self.modal.real_form(self.modal.Psi_inv_r @ np.concatenate([x, v]))

    def run(self, F, eta, z, state, outputs=True) -> np.ndarray:
        """Outputs (n_rows, n_out) at steps 0 .. n_rows - 1 of the loads ``F``
        (n_rows + 1, load_dofs) [N] (``outputs`` False: none); the modal state ``eta``, port
        forces ``z`` (m,) [N] and laws' ``state`` are updated in place to step n_rows.

        Raises
        ------
        FloatingPointError
            Newton did not converge at some step (the names of the port laws are given).
        """
        arrays = self.outputs if outputs else self.silent
        out = np.empty((F.shape[0] - 1, arrays[0][0].shape[0]))
        laws = (self.ports.kinds, self.ports.parameters, state)
        F = np.ascontiguousarray(F, float)
        T, load_at = self.port_arrays[:2]
        p = -T.T @ z
        p[load_at] += F[0]
        y = self._reduced_rows @ eta
        y[2 * p.size:] += self._fixed[3] @ p
        failed = modal_port_kernel(self.modal_arrays, arrays, self.port_arrays, laws, F, eta,
                                   y, z, out, PORT_TOL, PORT_MAX_ITER)
        if failed:
            raise FloatingPointError(f"port laws {', '.join(self.ports.names)}: Newton did "
                                     f"not converge at {failed} of {out.shape[0]} steps")
        return out


def _read_columns(W):
    """``(W[:, cols], cols)``: the columns of ``W`` that are not all zero."""
    cols = np.flatnonzero(np.any(W != 0, 0))
    return np.ascontiguousarray(W[:, cols]), cols
