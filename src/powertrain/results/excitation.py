"""What drives the powertrain at one speed (``powertrain excitation``): the
:class:`~powertrain.models.engine.Excitation` over one engine cycle, as text, CSV and figure."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.text_table import format_table
from powertrain.outputs import write_csv
from powertrain.plotting import plot_excitation
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result

#: Leading CSV columns: total load on the powertrain about its CG, engine axes.
LOAD_COLUMNS = ["crank_angle_deg", "fx_n", "fy_n", "fz_n", "mx_nm", "my_nm", "mz_nm"]


@dataclass(frozen=True, eq=False)
class ExcitationResult(Result):
    """Pressures, forces, torques and the total load over one engine cycle.

    Attributes
    ----------
    excitation : Excitation
        Sampled at equally spaced cylinder-1 crank angles on [0, 4π).
    engine : Engine
        The engine as it ran (balancers on or off).
    """

    excitation: object
    engine: object

    def to_text(self) -> str:
        """What ``powertrain excitation`` prints: peak pressures, IMEP, torque, load orders."""
        exc, engine = self.excitation, self.engine
        lines = [f"engine: {engine.name}",
                 f"speed {exc.rpm:g} rpm, balancer shafts "
                 f"{'on' if engine.balancer.enabled else 'off'}"]
        info = exc.info
        if np.isfinite(info.get("p_intake", np.nan)):
            lines.append(f"intake pressure {info['p_intake'] / 1e5:.3f} bar, exhaust "
                         f"{info['p_exhaust'] / 1e5:.3f} bar")
        rows = []
        for i in range(exc.pressure.shape[1]):
            k = int(np.argmax(exc.pressure[:, i]))
            local = np.degrees(engine.local_angles(exc.crank_angle[k])[0, i])
            rows.append([i + 1, float(exc.pressure[k, i] / 1e5), float(local),
                         float(exc.imep[i] / 1e5), float(exc.torque[:, i].mean())])
        lines += ["", format_table(["cyl", "p_max [bar]", "at [deg aTDC]", "IMEP [bar]",
                                    "mean torque [N*m]"], rows, "{:.2f}")]
        indicated = exc.imep.mean() * engine.crank.displacement / (4 * np.pi)
        lines.append(f"mean crank torque {exc.torque.sum(axis=1).mean():.1f} N*m "
                     f"(= IMEP*V_d/(4*pi) = {indicated:.1f} N*m, indicated)")
        orders, amp = exc.order_spectrum(8.0)
        rows = [[f"{o:g}"] + [float(abs(a)) for a in amp[j]] for j, o in enumerate(orders)]
        rows[0] = ["mean"] + [float(a.real) for a in amp[0]]
        lines += ["", "load on the powertrain about its CG, engine axes: mean and order "
                  "amplitudes",
                  format_table(["order", "Fx [N]", "Fy [N]", "Fz [N]", "Mx [N*m]", "My [N*m]",
                                "Mz [N*m]"], rows, "{:.1f}")]
        return "\n".join(lines)

    def csv_text(self) -> str:
        """One row per crank angle: the total load, then per cylinder pressure [bar], gas
        and inertia force [N] and crank torque [N·m]."""
        exc = self.excitation
        header = list(LOAD_COLUMNS)
        cols = [np.degrees(exc.crank_angle)] + [exc.load[:, j] for j in range(6)]
        for i in range(exc.pressure.shape[1]):
            header += [f"p{i + 1}_bar", f"gas_force{i + 1}_n", f"inertia_force{i + 1}_n",
                       f"torque{i + 1}_nm"]
            cols += [exc.pressure[:, i] / 1e5, exc.gas_force[:, i], exc.inertia_force[:, i],
                     exc.torque[:, i]]
        rows = [",".join(f"{v:.9g}" for v in row) for row in np.column_stack(cols)]
        return "\n".join([",".join(header)] + rows) + "\n"

    def to_csv(self, path) -> None:
        """Write :meth:`csv_text` atomically."""
        write_csv(path, self.csv_text())

    def writers(self) -> dict:
        """``.csv``, ``.png``."""
        return {".csv": self.to_csv, **super().writers()}

    def plot(self, ax=None, *, path=None, provenance=None):
        """Six-panel summary figure (:func:`powertrain.plotting.plot_excitation`); ``ax``:
        None, a Figure or SubFigure; returns the figure."""
        ax, path = target_and_path(ax, path)
        return plot_excitation(self.excitation, path, ax=ax, provenance=provenance)
