"""Numba kernels over plain SI floats and arrays.

This subpackage imports only numpy, numba, math and its own modules: no I/O, plotting, CLI
or model objects (``tests/test_architecture.py`` checks the contract). Public wrappers that validate and
allocate live in :mod:`powertrain.solvers`.
"""

import numpy as np


def kernel_input(x, dtype=np.float64):
    """``x`` as a kernel takes an input array: C-contiguous, of ``dtype``, read-only (a view;
    copied only where the layout or type differs).

    Numba compiles a kernel once per argument type, and an array's type includes its
    writeable flag: inputs that are sometimes fresh arrays and sometimes frozen ones (a
    model's, or ``numpy.broadcast_to``'s) made one kernel compile up to eleven times on a
    first run. Handed over read-only, they compile once.
    """
    a = np.ascontiguousarray(x, dtype).view()
    a.flags.writeable = False
    return a
