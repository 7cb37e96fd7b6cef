"""Numba kernels over plain SI floats and arrays.

Imports only numpy, numba, math and its own modules (``tests/test_architecture.py`` checks
it); the wrappers that validate and allocate live in :mod:`powertrain.solvers`.
"""

import numpy as np


def kernel_input(x, dtype=np.float64):
    """``x`` as a C-contiguous, read-only view of ``dtype`` (copied only where layout or type
    differ). An array's writeable flag is part of its Numba type: read-only inputs compile once.
    """
    a = np.ascontiguousarray(x, dtype).view()
    a.flags.writeable = False
    return a
