"""Hostile programs are bounded: each one ends with a message naming what it did and where,
in the interpreter, in ``viple check`` and ``viple run``, and in the run record."""

from __future__ import annotations

import json

import pytest

from tests.program import hostile
from tests.program.builder import ProgramBuilder
from tests.program.ticking import run
from workbench.cli import main
from workbench.program.compiled import compile_program
from workbench.program.interp import Limits, ProgramController
from workbench.program.loader import MAX_LOOP_STEPS, load_program, resolve_partner
from workbench.program.problems import ProgramError
from workbench.program.viple_expr import MAX_MESSAGE_DEPTH, JoinMessage, show
from workbench.sim.commands import Stop
from workbench.sim.record import read_record

WEB_MAZE = "mazes/web.txt"


def controller(text: str, tmp_path, limits: Limits | None = None) -> ProgramController:
    path = tmp_path / "hostile.viple"
    path.write_text(text)
    return ProgramController(compile_program(load_program(path)), limits=limits or Limits())


def problems(text: str, tmp_path) -> list[str]:
    path = tmp_path / "hostile.viple"
    path.write_text(text)
    with pytest.raises(ProgramError) as info:
        compile_program(load_program(path))
    return [str(p) for p in info.value.problems]


def live_flows(c: ProgramController) -> int:
    return len(c.running(limit=10_000))


# -- messages that grow --------------------------------------------------------------------------


@pytest.mark.timeout(60)
def test_a_join_message_nesting_forever_is_refused_at_the_join(tmp_path):
    c = controller(hostile.join_nesting(), tmp_path)
    run(c, 2.0)
    assert len(c.errors) == 1
    error = c.errors[0]
    assert (error.activity, error.label) == (4, "Join")
    assert f"Joins {MAX_MESSAGE_DEPTH + 1} deep (at most {MAX_MESSAGE_DEPTH})" in error.message
    assert c.stopped == error and c.state == "stopped"
    assert live_flows(c) == 0  # the program stopped there: nothing more is held


@pytest.mark.timeout(60)
def test_a_join_fed_twice_from_one_merge_and_printed_is_refused_not_written_out(tmp_path):
    c = controller(hostile.join_doubling(), tmp_path)
    run(c, 2.0)
    assert [(e.activity, e.label) for e in c.errors] == [(3, "Join")]
    assert "parts written out (at most 20,000)" in c.errors[0].message
    assert c.stopped == c.errors[0]
    assert c.printed and max(len(p.text) for p in c.printed) <= 1000


def test_a_deeply_nested_message_prints_without_recursion_and_cut_short():
    message: object = 1
    for _ in range(50_000):
        inner = JoinMessage(a=message, b=2)
        message = inner
    text = show(message, limit=500)
    assert text.startswith("{a = {a = {a = ") and text.endswith("...")
    assert len(text) == 503
    shared = JoinMessage(x=1)
    for _ in range(200):  # each level holds the one below twice: 2**200 parts written out
        shared = JoinMessage(left=shared, right=shared)
    assert len(show(shared, limit=2_000)) == 2_003


# -- numbers -------------------------------------------------------------------------------------


@pytest.mark.timeout(60)
def test_doubling_a_global_is_refused_at_the_calculate_and_recorded_without_a_traceback(
    tmp_path, capsys
):
    path = tmp_path / "double.viple"
    path.write_text(hostile.number_doubling())
    record = tmp_path / "run.jsonl"
    args = ["viple", "run", str(path), "--maze", WEB_MAZE, "--max-time", "2"]
    assert main([*args, "--record", str(record), "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert len(data["errors"]) == 1 and data["stopped"] == data["errors"][0]
    assert (
        "activity 4 (Calculate): column 9: the number grew past the range of a 64-bit"
        in (data["errors"][0])
    )
    kept = read_record(record)
    assert kept.summary is not None
    assert all(abs(t["vars"]["n"]) < 1 << 63 for t in kept.ticks if "vars" in t)


# -- run records ---------------------------------------------------------------------------------


@pytest.mark.timeout(60)
def test_a_program_writing_huge_records_stops_the_record_and_the_run_goes_on(tmp_path, capsys):
    path = tmp_path / "flood.viple"
    path.write_text(hostile.record_flood())
    record = tmp_path / "run.jsonl"
    args = ["viple", "run", str(path), "--maze", WEB_MAZE, "--max-time", "5"]
    main([*args, "--record", str(record)])
    out = capsys.readouterr().out
    assert "simulated time      5.0 s" in out
    assert (
        "run record          stopped after 0.0 s: it grew by more than 500,000 bytes in one "
        "simulated second; the run went on unrecorded"
    ) in out
    assert record.stat().st_size < 10_000
    kept = read_record(record)
    assert kept.summary is not None and kept.summary["sim_time"] == 5.0
    assert kept.summary["record_capped"] == {"bytes_per_second": 500_000, "t": 0.0}


# -- work and memory -----------------------------------------------------------------------------


@pytest.mark.timeout(60)
def test_a_merge_feeding_itself_is_stopped_by_the_work_budget(tmp_path):
    c = controller(hostile.merge_spin(), tmp_path)
    commands = run(c, 3.0)
    stopped = c.stopped
    assert stopped is not None and stopped.time <= 1.0
    assert stopped.activity in (2, 3) and stopped.label in ("Merge", "Calculate")
    assert "ran 50,000 activities in one simulated second (at most 50,000)" in stopped.message
    assert "a loop that never waits?" in stopped.message
    assert commands[-1] == Stop() and c.state == "stopped"
    steps = c.steps
    assert c.tick(3.05, {}, frozenset()) == [] and c.steps == steps
    assert live_flows(c) == 0


def test_the_work_budget_is_counted_per_simulated_second_and_per_tick(tmp_path):
    c = controller(hostile.merge_spin(), tmp_path, Limits(tick=300, second=100_000))
    run(c, 2.0)
    assert c.stopped is None  # 300 a tick is 6,000 a second, within the budget
    assert c.steps == 41 * 300


@pytest.mark.timeout(60)
def test_long_texts_piling_up_at_joins_are_stopped_by_the_memory_cap(tmp_path):
    b = ProgramBuilder()
    main_panel = b.panel("Main")
    text = main_panel.add(3, '"' + "x" * 9_000 + '"')
    longer = main_panel.add(2, " + ".join(["value"] * 10))  # 90,000 characters: 901 parts
    merge = main_panel.add(5)
    joins = [main_panel.add(4, "a", "b") for _ in range(2)]  # their second inputs never come
    b.link(text, longer)
    b.link(longer, merge)
    for join in joins:
        b.link(merge, join)
    b.link(merge, merge)
    c = controller(b.xml(), tmp_path)
    run(c, 1.0)
    stopped = c.stopped
    assert stopped is not None and stopped.time == 0.0
    assert stopped.activity in joins and stopped.label == "Join"
    assert "the program holds values of 1," in stopped.message
    assert "parts written out (at most 1,000,000; " in stopped.message
    assert "of them in messages on their way to this activity or waiting at it" in stopped.message
    assert live_flows(c) == 0


# -- files made to be slow to check -------------------------------------------------------------


@pytest.mark.timeout(30)
def test_a_long_robot_name_is_refused_quickly(tmp_path):
    found = problems(hostile.long_robot_name(), tmp_path)
    assert any("Values[0] is 60,001 characters long; at most 10,000" in p for p in found)
    assert resolve_partner("1" * 1_000_000 + "x", 2) is None
    assert resolve_partner("Robot/IoT Controller " + "0" * 100_000 + "1", 2) == 1


@pytest.mark.timeout(30)
def test_a_long_comment_is_refused(tmp_path):
    found = problems(hostile.long_comment(), tmp_path)
    assert found == [
        f"{tmp_path / 'hostile.viple'}: panel Main: activity 1: Values[0] is 190,000 characters "
        "long; at most 10,000 (shorten it (a long text can be built by a Calculate))"
    ]


@pytest.mark.timeout(30)
def test_a_lattice_of_whiles_is_refused_within_the_loop_budget(tmp_path):
    found = problems(hostile.while_lattice(), tmp_path)
    tangled = [p for p in found if "too tangled" in p]
    assert len(tangled) == 1
    assert f"took more than {MAX_LOOP_STEPS:,} steps" in tangled[0]


@pytest.mark.timeout(30)
def test_two_thousand_loops_one_after_another_check_ok(tmp_path):
    path = tmp_path / "loops.viple"
    path.write_text(hostile.many_whiles())
    assert len(compile_program(load_program(path)).program.loop_end) == 2_000


@pytest.mark.timeout(30)
def test_hundreds_of_thousands_of_attributes_or_elements_are_refused_before_building(tmp_path):
    found = problems(hostile.many_attributes(), tmp_path)
    assert found == [
        f"{tmp_path / 'hostile.viple'}: the file has about 340,001 attributes; a VIPLE program "
        "has at most 50,000 (check that this is a VIPLE program file)"
    ]
    found = problems(hostile.many_elements(), tmp_path)
    assert found == [
        f"{tmp_path / 'hostile.viple'}: the file has 399,005 tags; a VIPLE program has at most "
        "150,000 elements (check that this is a VIPLE program file)"
    ]


# -- where programs run --------------------------------------------------------------------------


@pytest.mark.timeout(60)
def test_the_station_stops_a_runaway_program_and_says_where(tmp_path):
    from workbench.control.station import PROGRAM_STOPPED, LabStation
    from workbench.program.choice import choose_program
    from workbench.sim.mazefile import parse_maze

    path = tmp_path / "spin.viple"
    path.write_text(hostile.merge_spin())
    room = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")
    station = LabStation.open(room, "unity", noise="off")
    choose_program(station, str(path))
    station.start()
    for _ in range(3 * 60):
        station.step()
        if station.notice is not None:
            break
    notice = station.notice
    assert notice is not None and notice.kind == PROGRAM_STOPPED
    assert "panel Main: activity 3 (Calculate): the program ran 50,000 activities" in notice.detail
    assert station.driving is None and station.paused
    assert station.runs[-1].ended == "error"


@pytest.mark.timeout(120)
def test_eval_ranks_hostile_programs_each_on_its_own_row(tmp_path, capsys):
    paths = []
    for name in ("merge_spin", "join_doubling", "number_doubling"):
        path = tmp_path / f"{name}.viple"
        path.write_text(getattr(hostile, name)())
        paths.append(str(path))
    args = ["eval", "--maze", WEB_MAZE, "--program", *paths, "--algorithm", "right-wall"]
    assert main([*args, "--max-time", "5", "--seeds", "1", "--jobs", "1", "--json"]) == 0
    cells = {c["algorithm"]: c for c in json.loads(capsys.readouterr().out)["cells"]}
    assert set(cells) == {"right-wall", "merge_spin.viple", "join_doubling.viple",
                          "number_doubling.viple"}  # fmt: skip
    assert all(cell["runs"] == 1 for cell in cells.values())


def test_long_names_and_crowded_elements_are_refused(tmp_path):
    b = ProgramBuilder()
    main_panel = b.panel("Main")
    main_panel.add(3, "1", name="n" * 5_000)
    b.var("v" * 300)
    found = problems(b.xml(), tmp_path)
    assert any("activity 1: its Name is 5,000 characters; at most 200" in p for p in found)
    assert any("a variable's name is 300 characters; at most 200" in p for p in found)
    crowded = ProgramBuilder()
    crowded.panel("Main").add(3, "1")
    text = crowded.xml().replace(
        "<Version>", "<Version " + " ".join(f"a{k}=''" for k in range(40)) + ">"
    )
    assert problems(text, tmp_path) == [
        f"{tmp_path / 'hostile.viple'}: an element has 40 attributes; a VIPLE program has at most "
        "16 on one (check that this is a VIPLE program file)"
    ]
