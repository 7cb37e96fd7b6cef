"""Workflows: the steps a study takes (run-up, effect runs, sweeps, what-if, retune, variants,
comparison, tracking, mount fitting, modes, excitation), each returning a result object."""
