"""Solvers: public wrappers around the kernels, and the frequency-domain solvers."""
