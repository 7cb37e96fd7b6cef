"""Where a vibration channel sits: mount (or body point), side and direction.

Labels are ``MOUNT.DIRECTION`` (engine side) and ``MOUNT.passive.DIRECTION`` (body side),
e.g. ``left.z``, ``left.passive.z``. Run-up results key curves by a *node* (``left``,
``left/passive``, a body point) and a direction: :meth:`Channel.of_node`, :attr:`Channel.node`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

SIDES = ("active", "passive")
DIRECTIONS = ("x", "y", "z")
#: Suffix of the node of a mount's body side: ``left/passive``.
PASSIVE = "/passive"

_TEXT = re.compile(r"^\s*([A-Za-z_][\w\-]*)(?:/(passive)|\.(active|passive))?\.([xyzXYZ])\s*$")
_MOUNT = re.compile(r"^[A-Za-z_][\w\-]*$")


def is_mount_name(name: str) -> bool:
    """True for a ``name`` the channel spelling can carry: a letter or ``_``, then letters,
    digits, ``_``, ``-``; not ``nan``, ``inf``, ``infinity`` (a CSV reader's numbers)."""
    return bool(_MOUNT.match(name)) and name.lower() not in ("nan", "inf", "infinity")


def passive_name(mount: str) -> str:
    """Node of the body side of ``mount`` (``left`` -> ``left/passive``)."""
    return f"{mount}{PASSIVE}"


def split_side(name: str):
    """``("left", "passive")`` for the node ``left/passive``, ``(name, "active")`` otherwise."""
    if name.endswith(PASSIVE):
        return name[:-len(PASSIVE)], "passive"
    return name, "active"


@dataclass(frozen=True)
class Channel:
    """A measurement direction at a mount side or body point.

    Attributes
    ----------
    mount : str
        Mount (or body point) name.
    side : str
        ``active`` (engine side) or ``passive`` (body side).
    direction : str
        ``x``, ``y`` or ``z`` (engine axes).
    """

    mount: str
    side: str
    direction: str

    @classmethod
    def parse(cls, text: str) -> Channel:
        """Channel of ``text``: ``left.z``, ``left.active.z``, ``left.passive.z`` or
        ``left/passive.z``; ValueError otherwise."""
        m = _TEXT.match(text) if isinstance(text, str) else None
        if not m:
            raise ValueError(f"cannot read channel {text!r} (expected MOUNT.DIRECTION or "
                             "MOUNT.passive.DIRECTION, e.g. left.z, left.passive.z)")
        mount, slash, side, direction = m.groups()
        return cls(mount, slash or side or "active", direction.lower())

    @classmethod
    def of_node(cls, node: str, direction: str) -> Channel:
        """Channel of a result's ``node`` and ``direction`` (``"left/passive", "z"``)."""
        mount, side = split_side(node)
        return cls(mount, side, direction)

    @property
    def label(self) -> str:
        """``mount.direction`` (active side) or ``mount.passive.direction``."""
        mid = "" if self.side == "active" else f".{self.side}"
        return f"{self.mount}{mid}.{self.direction}"

    @property
    def node(self) -> str:
        """Node of a run-up result: ``left``, ``left/passive`` or a body point's name."""
        return passive_name(self.mount) if self.side == "passive" else self.mount

    def __str__(self) -> str:
        return self.label


class ChannelFields:
    """Mixin of a record with ``mount``, ``side`` and ``direction`` fields: its
    :class:`Channel` and label."""

    @property
    def channel(self) -> Channel:
        """Where the channel was measured."""
        return Channel(self.mount, self.side, self.direction)

    @property
    def label(self) -> str:
        """``mount.direction`` (active side) or ``mount.passive.direction``."""
        return self.channel.label
