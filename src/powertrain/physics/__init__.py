"""Pure physics functions over plain SI floats and arrays (no I/O, no plotting)."""
