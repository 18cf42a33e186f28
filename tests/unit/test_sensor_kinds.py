"""The table of sensor kinds: each kind is carried, read, shown on the panel and reported to
VIPLE as its entry says, and nothing else decides how a kind behaves."""

from __future__ import annotations

import json

import pytest

from workbench.control.station import LabStation, SensorRow
from workbench.sim.mazefile import parse_maze
from workbench.sim.profiles import get_profile
from workbench.sim.sensor_kinds import KINDS, PANEL_KINDS, SENSOR_KINDS, sensor_kind
from workbench.sim.sensors import SensorConfigError, SensorSpec
from workbench.sim.world import World
from workbench.tui.widgets.text import reading
from workbench.viple.codec import encode_report, parse_report

ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")
MOUNTED = [(kind, mount) for kind in SENSOR_KINDS for mount in kind.mounts]


def _id(item) -> str:
    kind, mount = item
    return f"{kind.name}-{mount}"


@pytest.mark.parametrize("item", MOUNTED, ids=_id)
def test_every_kind_is_read_on_every_mount_it_allows_and_reported_under_its_name(item):
    kind, mount = item
    world = World(ROOM, "web", sensors=[SensorSpec(kind.name, 4, mount)], noise="off")
    value = world.read_sensors()[4]
    report = json.loads(encode_report({4: value}, {4: kind.name}))
    (entry,) = report["sensors"]
    assert entry["name"] == kind.report.name and entry["id"] == 4
    if kind.report.binary:
        assert entry["value"] in (0, 1)
    else:
        assert entry["value"] == pytest.approx(value, abs=10**-kind.report.places)
    assert parse_report(json.dumps(report)) == {4: float(entry["value"])}


@pytest.mark.parametrize("kind", SENSOR_KINDS, ids=lambda k: k.name)
def test_the_panel_shows_a_reading_as_its_kind_says(kind):
    web = get_profile("web")
    spec = SensorSpec(kind.name, 1, kind.mounts[0])
    shown = reading(spec, 1, web.unit, web.no_echo)
    if kind.panel.states is not None:
        assert shown == kind.panel.states[1]
        assert reading(spec, 0, "px", 1000) == kind.panel.states[0]
    else:
        assert shown == "1"
        if kind.panel.echo:
            assert reading(spec, 1000, "px", 1000) == "no echo (1000)"


def test_distance_and_touch_read_and_show_as_the_course_simulators_do():
    assert KINDS == ("distance", "touch")
    assert sensor_kind("distance").panel.mark == "ray"
    assert sensor_kind("touch").panel.mark == "contact"
    assert reading(SensorSpec("distance", 1, "front"), 1.234, "units", 1000) == "1.23"
    assert reading(SensorSpec("touch", 2, "front"), 1, "px", 1000) == "pressed"
    assert encode_report({1: 2.5, 2: True}, {1: "distance", 2: "touch"}) == (
        '{"sensors":[{"name":"distance","id":1,"value":2.5},{"name":"touch","id":2,"value":1}]}'
    )


def test_the_port_panel_offers_the_rows_the_table_asks_for():
    station = LabStation.open(ROOM, "web", noise="off", sensors=[])
    rows = station.sensor_rows()
    assert [r.kind for r in rows] == list(PANEL_KINDS) == ["distance", "distance", "touch"]
    assert all(r.mount is None for r in rows)
    assert [r.port for r in rows] == ["1", "2", "3"]


def test_a_kind_the_table_lacks_is_refused_naming_the_kinds_there_are():
    with pytest.raises(SensorConfigError, match="unknown sensor kind 'radar': use one of "
                       "distance, touch"):  # fmt: skip
        SensorSpec.parse("radar:1:front")
    station = LabStation.open(ROOM, "web", noise="off")
    assert station.apply_sensor_rows([SensorRow("radar", "1", "front")]) == {
        0: "unknown kind 'radar'"
    }


def test_the_world_reads_kinds_in_the_tables_order_and_draws_noise_the_same_each_run():
    sensors = [
        SensorSpec("touch", 1, "front"),
        SensorSpec("distance", 2, "right"),
        SensorSpec("distance", 3, "front"),
    ]
    runs = []
    for _ in range(2):
        world = World(ROOM, "web", sensors=sensors, noise="realistic", seed=7)
        readings = []
        for _ in range(20):
            world.step()
            readings.append(list(world.read_sensors().items()))
        runs.append(readings)
    assert runs[0] == runs[1]
    assert [port for port, _ in runs[0][0]] == [2, 3, 1]
