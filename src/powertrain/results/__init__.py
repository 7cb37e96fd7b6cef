"""Result objects: what a workflow returns (run-up, continuous run-up, tracked orders, modes,
excitation), with their text, plots and file writers."""
