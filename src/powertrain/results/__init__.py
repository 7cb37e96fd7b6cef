"""Result objects: what a workflow returns (run-up, tracked orders), with their text, plots
and file writers."""
