"""All figures. matplotlib is imported lazily in this package and nowhere else in the library.

Every plot function takes ``ax=None`` (a new figure with constrained layout; or the user's
Axes, Figure or SubFigure), returns the figure, writes a PNG atomically when given ``path``,
and never switches the matplotlib backend (the CLI picks Agg). Shared helpers (provenance
line, plain-number log axes, colour bars with ``extend``, one legend per figure) are in
:mod:`powertrain.plotting.style`; the figures are described in ``docs/reference/figures.md``.
"""

from powertrain.plotting.compare import plot_comparison
from powertrain.plotting.diagnosis import plot_diagnosis_overlay, plot_gap_frequency, plot_gap_map
from powertrain.plotting.excitation import plot_excitation
from powertrain.plotting.runup import plot_runup, plot_whatif
from powertrain.plotting.stiffness import plot_mount_fit, plot_retune, plot_stiffness
from powertrain.plotting.style import SIGNAL_UNITS, save_figure

__all__ = ["SIGNAL_UNITS", "plot_comparison", "plot_diagnosis_overlay", "plot_excitation",
           "plot_gap_frequency", "plot_gap_map", "plot_mount_fit", "plot_retune", "plot_runup",
           "plot_stiffness", "plot_whatif", "save_figure"]
