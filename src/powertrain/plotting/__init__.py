"""All figures; matplotlib is imported lazily here and nowhere else in the library.

Every plot function takes ``ax=None`` (a new figure, or the user's Axes, Figure or
SubFigure), returns the figure, writes a PNG atomically when given ``path`` and never
switches the backend (``docs/reference/figures.md``).
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
