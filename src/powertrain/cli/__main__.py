"""``python -m powertrain.cli``: same as the ``powertrain`` console script."""
from powertrain.cli import main

main()
