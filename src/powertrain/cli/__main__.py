"""``python -m powertrain.cli``: same as the ``powertrain`` console script."""
from powertrain.cli.group import main

main()
