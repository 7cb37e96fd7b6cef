"""Numba kernels over plain SI floats and arrays.

This subpackage imports only numpy and numba: no I/O, plotting, CLI or model objects
(``tests/test_architecture.py`` checks the contract). Public wrappers that validate and
allocate live in :mod:`powertrain.solvers`.
"""
