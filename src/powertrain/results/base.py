"""The protocol of every result: ``to_text()`` (what its command prints), ``plot(ax=None)``
(a new figure, a Figure or SubFigure, or one Axes for a one-panel figure) and ``save(path)``
(writer chosen by suffix)."""

from __future__ import annotations

from pathlib import Path

from powertrain.errors import InputError
from powertrain.outputs import json_text
from powertrain.plotting.style import close_figure

#: Suffixes of an HDF5 file.
HDF5_SUFFIXES = (".h5", ".hdf5")


class Result:
    """Base of the results: :meth:`save` picks the writer of the path's suffix among
    :meth:`writers` (a subclass adds its own to ``.png``)."""

    def writers(self) -> dict:
        """File suffix (``".csv"``) -> method writing this result to a path."""
        return {".png": self.save_figure}

    def save(self, path) -> Path:
        """Write the result to ``path`` atomically in the format of its suffix; returns
        the path.

        Raises
        ------
        InputError
            A suffix this result has no writer for.
        """
        writers = self.writers()
        suffix = Path(path).suffix.lower()
        if suffix not in writers:
            raise InputError(f"cannot write {suffix or 'a file without a suffix'}: this "
                             f"{type(self).__name__} writes {', '.join(writers)}",
                             file=str(path), key="suffix")
        writers[suffix](path)
        return Path(path)

    def save_figure(self, path) -> None:
        """The figure of ``plot()`` as a PNG at ``path`` (the figure is closed after)."""
        close_figure(self.plot(path=path))


class JsonResult(Result):
    """A result with a JSON document (``to_dict()``), written by :meth:`to_json`."""

    #: Indentation of the JSON text (:func:`powertrain.outputs.json_text`).
    JSON_INDENT = 1

    def to_json(self, path=None) -> str:
        """JSON text of ``to_dict()``; written atomically to ``path`` if given."""
        return json_text(self.to_dict(), path, indent=self.JSON_INDENT)

    def writers(self) -> dict:
        """``.json``, ``.png``."""
        return {".json": self.to_json, **super().writers()}
