"""Who drives: the driver's text as screens show it, and run records old and new."""

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.control.station import LabStation
from workbench.sim.driver import BY_KEYS, NOBODY, Driver
from workbench.sim.mazefile import parse_maze
from workbench.sim.record import FORMAT, read_record, recorded_driver
from workbench.sim.replay import load_replay
from workbench.viple.link import Link

BEND = parse_maze("#######\n#S....#\n#####.#\n#E....#\n#######\n", source="bend.txt")
MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'


def test_the_text_of_each_kind_of_driver():
    assert [str(d) for d in (BY_KEYS, NOBODY)] == ["keys", "nobody"]
    assert str(Driver.algorithm("right-wall")) == "algorithm right-wall"
    assert str(Driver.viple("tcp", "127.0.0.1:50312")) == "VIPLE tcp 127.0.0.1:50312"
    assert str(Driver.viple()) == "VIPLE"
    assert str(Driver.program("a script")) == "a script"


def test_a_table_of_runs_names_an_algorithm_by_its_own_name():
    assert Driver.algorithm("right-wall").short == "right-wall"
    assert BY_KEYS.short == "keys"
    assert Driver.viple("ws", "ws://localhost:8124/").short == "VIPLE ws ws://localhost:8124/"


def test_an_unknown_kind_is_refused_with_the_kinds_allowed():
    with pytest.raises(ValueError, match="unknown driver kind 'robot': use one of keys, algorithm"):
        Driver("robot")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "driver"),
    [
        ("right-wall", Driver.algorithm("right-wall")),
        ("keys", BY_KEYS),
        ("VIPLE tcp 127.0.0.1:50312", Driver.viple("tcp", "127.0.0.1:50312")),
        ("VIPLE ws ws://localhost:8124/", Driver.viple("ws", "ws://localhost:8124/")),
    ],
)
def test_a_record_written_before_drivers_were_typed_reads_its_driver_from_the_text(text, driver):
    assert recorded_driver({"type": "header", "algorithm": text}) == driver


def test_older_headless_and_driverless_records_read_as_viple_and_keys():
    assert recorded_driver({"driver": "VIPLE"}) == Driver.viple()
    assert recorded_driver({}) == BY_KEYS
    assert recorded_driver({"algorithm": 7}) == BY_KEYS


def test_a_station_record_holds_the_driver_both_ways(tmp_path):
    b = LabStation.open(BEND, "erobotic", noise="off", record_dir=str(tmp_path))
    link = Link(b, "tcp")
    assert link.connect("127.0.0.1:50312")
    assert link.apply(MOVE)
    b.step(30)
    link.disconnect()
    b.step(1)
    b.select_algorithm("right-wall")
    b.start()
    b.step(30)
    b.close()
    viple, algorithm = (read_record(run.record).header for run in b.runs)
    # the text older readers take, and the typed driver
    assert viple["algorithm"] == "VIPLE tcp 127.0.0.1:50312"
    assert viple["driven_by"] == {"kind": "viple", "role": "tcp", "peer": "127.0.0.1:50312"}
    assert algorithm["algorithm"] == "right-wall"
    assert recorded_driver(algorithm) == Driver.algorithm("right-wall") == b.runs[1].driver
    replay = load_replay(b.runs[0].record)
    assert replay.driver == b.runs[0].driver
    assert replay.title.startswith("VIPLE tcp 127.0.0.1:50312 on ")


def test_a_typed_driver_in_a_record_wins_over_the_text(tmp_path):
    header = {
        "type": "header",
        "format": FORMAT,
        "algorithm": "keys",
        "driven_by": {"kind": "algorithm", "name": "left-wall"},
    }
    path = tmp_path / "r.jsonl"
    path.write_text(json.dumps(header) + "\n")
    assert recorded_driver(read_record(path).header) == Driver.algorithm("left-wall")


@given(
    st.one_of(
        st.none(),
        st.text(max_size=20),
        st.dictionaries(st.text(max_size=8), st.one_of(st.text(max_size=8), st.integers())),
    ),
    st.one_of(st.none(), st.text(max_size=30), st.integers()),
)
def test_any_header_gives_some_driver_and_never_raises(driver, algorithm):
    got = recorded_driver({"driven_by": driver, "driver": driver, "algorithm": algorithm})
    assert isinstance(got, Driver) and str(got)
