"""The one channel spelling: :class:`powertrain.analysis.channel.Channel`."""

from __future__ import annotations

import pytest

from powertrain.analysis.channel import Channel
from powertrain.iotools.channel_map import parse_channel_name


@pytest.mark.parametrize("text, mount, side, label", [
    ("left.z", "left", "active", "left.z"),
    ("left.active.Z", "left", "active", "left.z"),
    ("left.passive.z", "left", "passive", "left.passive.z"),
    ("left/passive.z", "left", "passive", "left.passive.z"),     # the run-up CSV column
    ("seat_rail.y", "seat_rail", "active", "seat_rail.y"),
])
def test_parse_reads_every_spelling_and_labels_one_way(text, mount, side, label):
    ch = Channel.parse(text)
    assert (ch.mount, ch.side, ch.label) == (mount, side, label)
    assert Channel.parse(ch.label) == ch


@pytest.mark.parametrize("text", ["left", "left.w", "left.body.z", "left/active.z", ".z", ""])
def test_parse_rejects_other_text(text):
    with pytest.raises(ValueError, match="cannot read channel"):
        Channel.parse(text)


def test_node_round_trips_the_result_keys():
    for node, d in [("left", "z"), ("left/passive", "x"), ("seat_rail", "y")]:
        assert Channel.of_node(node, d).node == node
    assert Channel.of_node("left/passive", "z").label == "left.passive.z"


def test_raw_file_names_read_through_channel():
    spec = parse_channel_name("left/passive.z [g]")
    assert (spec.mount, spec.side, spec.direction, spec.unit) == ("left", "passive", "z", "g")
    assert parse_channel_name("Time") is None


@pytest.mark.parametrize("name", ["nan", "NaN", "inf", "Infinity", "1left", "", "a b", "a.b"])
def test_mount_names_that_a_csv_reader_takes_for_numbers_or_that_break_the_spelling_are_refused(
        name):
    from powertrain.analysis.channel import is_mount_name
    assert not is_mount_name(name)


@pytest.mark.parametrize("name", ["left", "gearbox", "torque_rod", "m-2", "_x", "nanny"])
def test_ordinary_mount_names_are_accepted(name):
    from powertrain.analysis.channel import is_mount_name
    assert is_mount_name(name)
