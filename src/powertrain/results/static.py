"""The static operating point per speed (``powertrain static``; physics in
:mod:`powertrain.solvers.operating_point`), as text, JSON (docs/reference/json.md) and figure."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.text_table import format_table
from powertrain.plotting.body import plot_static
from powertrain.plotting.style import target_and_path
from powertrain.results.base import JsonResult
from powertrain.units import from_si


@dataclass(frozen=True)
class StaticResult(JsonResult):
    """Operating points (:class:`~powertrain.solvers.operating_point.OperatingPoint`, one
    per speed) of the engine's ``mounts`` (names, in order)."""

    points: list
    mounts: list
    engine: str = ""

    @property
    def rpm(self) -> np.ndarray:
        return np.array([p.rpm for p in self.points])

    def stack(self, name) -> np.ndarray:
        """Attribute ``name`` of every operating point, stacked along a first speed axis."""
        return np.array([getattr(p, name) for p in self.points])

    def to_dict(self) -> dict:
        """The JSON document (docs/reference/json.md)."""
        body = self.stack("body")
        mounts = {}
        for m, name in enumerate(self.mounts):
            mounts[name] = {
                "deflection_mm": from_si(self.stack("deflection")[:, m], "mm").tolist(),
                "force_n": self.stack("force")[:, m].tolist(),
                "tangent_stiffness_n_per_mm": from_si(self.stack("tangent_stiffness")[:, m],
                                                      "N/mm").tolist(),
                "static_factor": self.stack("static_factor")[:, 3 * m:3 * m + 3].tolist()}
        return {"rpm": self.rpm.tolist(),
                "mean_torque_nm": self.stack("mean_torque").tolist(),
                "gear_ratio": float(self.points[0].gear_ratio) if self.points else 1.0,
                "body": {"displacement_mm": from_si(body[:, :3], "mm").tolist(),
                         "rotation_deg": np.rad2deg(body[:, 3:]).tolist()},
                "mounts": mounts}

    def plot(self, ax=None, *, path=None, provenance=None):
        """Static deflection [mm] of every mount direction against speed in one panel;
        returns the figure (:func:`powertrain.plotting.body.plot_static`)."""
        ax, path = target_and_path(ax, path)
        return plot_static(self, path, ax=ax, provenance=provenance)

    def to_text(self) -> str:
        """Per speed: body displacement [mm] and rotation [deg] at the CG, then each mount's
        deflection [mm], force [N] and tangent stiffness [N/mm] per local direction."""
        blocks = [f"static operating point{f' of {self.engine}' if self.engine else ''}: "
                  "weight and mean drive-torque reaction on the mounts' static curves"]
        for p in self.points:
            u, th = from_si(p.body[:3], "mm"), np.rad2deg(p.body[3:])
            head = (f"{p.rpm:g} rpm: mean torque {p.mean_torque:.1f} N*m x gear ratio "
                    f"{p.gear_ratio:g}; body at CG u = [{', '.join(f'{v:.3f}' for v in u)}]"
                    f" mm, rotation = [{', '.join(f'{v:.4f}' for v in th)}] deg")
            rows = [[f"{name}.{a}", float(from_si(p.deflection[m, k], "mm")),
                     float(p.force[m, k]), float(from_si(p.tangent_stiffness[m, k], "N/mm")),
                     float(p.static_factor[3 * m + k])]
                    for m, name in enumerate(self.mounts) for k, a in enumerate("xyz")]
            blocks.append(head + "\n" + format_table(
                ["mount.dir", "deflection [mm]", "force [N]", "tangent [N/mm]",
                 "static factor"], rows))
        return "\n\n".join(blocks)
