"""The transient kernel's model (:func:`~powertrain.kernels.transient.transient_kernel`) from
the assembled system: compressed matrices, elimination order and LU pattern
(:mod:`powertrain.kernels.sparse_lu`), amplitude laws and the rows amplitudes are read on."""

import numpy as np

from powertrain.kernels.sparse_lu import compressed, csr_pattern, lu_pattern
from powertrain.kernels.transient import NO_LAW


def stretch_kernel_model(system, scaling, pivoting=False):
    """The kernel's ``model`` tuple of ``system`` and its ``scaling`` (:func:`kernel_model`)."""
    return kernel_model(*(np.array(A, float) for A in (system.M, system.C, system.K)),
                        scaling.C_parts, scaling.K_parts, np.array(scaling.assembled, float),
                        pivoting)


def kernel_model(M, C, K, C_parts, K_parts, assembled, pivoting=False):
    """The kernel's ``model`` tuple of the assembled ``M``, ``C``, ``K`` (n, n), the networks'
    ``C_parts``, ``K_parts`` (n_net, n, n) and the ``assembled`` scales (n_net, 2); without
    ``pivoting`` the kernel returns :data:`~powertrain.kernels.transient.NEEDS_PIVOTING`
    where a pivot needs a row swap."""
    try:
        M_inv = np.linalg.inv(M)
    except np.linalg.LinAlgError:          # massless nodes: the start acceleration is 0
        M_inv = np.zeros_like(M)
    perm = _elimination_order(M, C, K, C_parts, K_parts)
    where = np.empty_like(perm)
    where[perm] = np.arange(perm.size)
    joint = _mask(C, C_parts) | _mask(K, K_parts)
    mask = (M != 0) | joint
    return (M, compressed(M, True, True), compressed(M_inv, True, True),
            _with_parts(C, C_parts, joint), _with_parts(K, K_parts, joint), assembled, perm,
            where, lu_pattern(mask[np.ix_(perm, perm)]), np.empty(0) if pivoting else None)


def _elimination_order(*matrices):
    """Coordinates ordered by fewest nonzeros in any of ``matrices`` (least fill-in)."""
    pattern = sum((np.abs(m).reshape(-1, *m.shape[-2:]).sum(0) != 0) for m in matrices)
    return np.argsort((pattern != 0).sum(1), kind="stable").astype(np.int64)


def _mask(A, parts):
    """Where ``A`` (n, n) or any of its networks' ``parts`` (n_net, n, n) is nonzero."""
    return (A != 0) | (parts != 0).any(0)


def _with_parts(A, parts, mask):
    """``A`` compressed on ``mask``, and each of ``parts``' nonzeros with its value position."""
    starts, columns = csr_pattern(mask)
    rows = np.repeat(np.arange(A.shape[0]), np.diff(starts))
    position = np.full(A.shape, -1, np.int64)
    position[rows, columns] = np.arange(columns.size)
    net, i, j = np.nonzero(parts)
    return (starts, columns, np.ascontiguousarray(A[rows, columns], float),
            (net.astype(np.int64), position[i, j], np.array(parts[net, i, j], float)))


def motion_model(system, scaling, ports):
    """The kernel's ``motion`` tuple of ``system``, ``scaling`` and ``ports``: amplitude laws,
    compressed port and network rows, each port's network and whether a law varies."""
    rows = (compressed(np.array(ports.rows, float), True, True),
            compressed(np.array(system.port_rows, float), True, True))
    return (amplitude_laws(scaling.elements), rows, np.array(ports.index, np.int64), bool(scaling.varying))


def amplitude_laws(elements):
    """``(kind, power, table, count)`` of :func:`~powertrain.kernels.transient.amplitude_scales`
    from the amplitude laws of ``elements``."""
    rows = [(NO_LAW, (0.0,) * 5, ()) if el.amplitude_law is None else
            el.amplitude_law.kernel_law() for el in elements]
    size = max([len(table[0]) for *_, table in rows if table], default=1)
    table = np.zeros((len(rows), 3, size))
    count = np.ones(len(rows), np.int64)
    for r, (_, _, points) in enumerate(rows):
        if points:
            count[r] = len(points[0])
            table[r, :, :count[r]] = np.array(points, float)
    return (np.array([kind for kind, *_ in rows], np.int64),
            np.array([p for _, p, _ in rows], float), table, count)
