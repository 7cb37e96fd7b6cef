"""Channel names of raw time data -> mount, side, direction, quantity: the convention
``MOUNT[.SIDE].DIRECTION [UNIT]`` (the unit decides the quantity) or a channel map (TOML);
both in docs/reference/raw-data.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from powertrain.analysis.channel import DIRECTIONS, SIDES, Channel, is_mount_name
from powertrain.errors import InputError
from powertrain.iotools.tomlfile import get, read_toml
from powertrain.models.recording import QUANTITIES, QUANTITY_OF_DIMENSION
from powertrain.units import dimension_of

_UNIT_IN_NAME = re.compile(r"^\s*(.*?)\s*\[\s*([^\]]*?)\s*\]\s*$")
ENTRY_KEYS = ("mount", "side", "direction", "quantity", "unit")


@dataclass
class ChannelSpec:
    """Where a channel was measured and in what unit (unit '' = take the file's)."""

    mount: str
    side: str
    direction: str
    quantity: str | None
    unit: str = ""


@dataclass
class ChannelMap:
    """A parsed channel map (docs/reference/raw-data.md)."""

    channels: dict = field(default_factory=dict)    # file name -> ChannelSpec
    time: str | None = None
    rpm: str | None = None
    tacho: str | None = None
    source: str = ""


def split_unit(name: str):
    """``'left.z [m/s^2]'`` -> ``('left.z', 'm/s^2')``; no bracket -> ``(name, '')``."""
    m = _UNIT_IN_NAME.match(name)
    return (m.group(1), m.group(2)) if m else (name.strip(), "")


def parse_channel_name(name: str) -> ChannelSpec | None:
    """Spec from the ``MOUNT[.SIDE].DIRECTION [UNIT]`` convention, or None."""
    text, unit = split_unit(name)
    try:
        ch = Channel.parse(text)
    except ValueError:
        return None
    return ChannelSpec(ch.mount, ch.side, ch.direction, None, unit)


def quantity_of_unit(unit: str, file=None, key=None) -> str:
    """Quantity measured in ``unit`` (``g`` is an acceleration here)."""
    dim = dimension_of(unit, ("acceleration", "velocity", "length", "force"))
    if dim not in QUANTITY_OF_DIMENSION:
        what = "unknown unit" if dim is None else f"unit of {dim}"
        raise InputError(f"{what} {unit!r}: a channel needs a unit of acceleration (m/s^2, "
                         "g), velocity (m/s, mm/s), displacement (m, mm) or force (N)", file=file, key=key)
    return QUANTITY_OF_DIMENSION[dim]


def read_channel_map(path) -> ChannelMap:
    """Read a channel-map TOML file (docs/reference/raw-data.md)."""
    path = str(path)
    data = read_toml(path)
    for key in data:
        if key not in ("time", "rpm", "tacho", "channels"):
            raise InputError("unknown key (expected time, rpm, tacho, [channels])", file=path, key=key)
    cmap = ChannelMap(source=path)
    for key in ("time", "rpm", "tacho"):
        setattr(cmap, key, get(data, key, path, default=None, types=(str, type(None))))
    table = get(data, "channels", path, types=dict)
    if not table:
        raise InputError("no channel listed", file=path, key="channels")
    for name, entry in table.items():
        prefix = f"channels.{name}"
        if not isinstance(entry, dict):
            raise InputError("expected a table {mount=..., direction=..., quantity=...}",
                             file=path, key=prefix)
        unknown = [k for k in entry if k not in ENTRY_KEYS]
        if unknown:
            raise InputError(f"unknown key (expected {', '.join(ENTRY_KEYS)})", file=path,
                             key=f"{prefix}.{unknown[0]}")
        mount = get(entry, "mount", path, prefix, types=str)
        side = get(entry, "side", path, prefix, default="active", types=str).lower()
        direction = get(entry, "direction", path, prefix, types=str).lower()
        quantity = get(entry, "quantity", path, prefix, default=None, types=str)
        unit = get(entry, "unit", path, prefix, default="", types=str)
        if not mount.strip():
            raise InputError("empty mount name", file=path, key=f"{prefix}.mount")
        if not is_mount_name(mount.strip()):
            raise InputError(f"mount name {mount.strip()!r}: a letter or _ first, then letters, "
                             "digits, _ or -; not nan or inf", file=path, key=f"{prefix}.mount")
        if side not in SIDES:
            raise InputError(f"unknown side {side!r} (expected active or passive)",
                             file=path, key=f"{prefix}.side")
        if direction not in DIRECTIONS:
            raise InputError(f"unknown direction {direction!r} (expected x, y or z)",
                             file=path, key=f"{prefix}.direction")
        if quantity is not None and quantity not in QUANTITIES:
            raise InputError(f"unknown quantity {quantity!r} (expected "
                             f"{', '.join(QUANTITIES)})", file=path, key=f"{prefix}.quantity")
        cmap.channels[name] = ChannelSpec(mount.strip(), side, direction, quantity, unit)
    return cmap
