"""Post-processing: FFT order analysis and comparisons."""
