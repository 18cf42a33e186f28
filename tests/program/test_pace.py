"""The pace of a VIPLE program: sensor reports at the simulator's period, Timers at their own
times (between physics steps offline, between control ticks over the protocol)."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import pytest

from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.control.headless import RunSpec, prepare, run
from workbench.control.station import LabStation
from workbench.program.choice import program_choice
from workbench.program.compiled import compile_program
from workbench.program.interp import ProgramController
from workbench.program.loader import load_program, load_program_text
from workbench.program.pilot import ProgramPilot, load_compiled
from workbench.program.remote import RemoteProgram
from workbench.sim.clock import Pacer
from workbench.sim.mazeio import load_maze
from workbench.sim.world import WorldError

CORRIDOR = """\
---
name: Long corridor
profile: web
---
#########
#.......#
#^#######
#########
"""


def maze(tmp_path) -> str:
    path = tmp_path / "corridor.txt"
    path.write_text(CORRIDOR)
    return str(path)


def deciding(tmp_path) -> str:
    """A robot in a "deciding" state starts a turn on the report it gets, and leaves that state
    only when the turn is over, 400 ms later (as PhysicalRobot-like programs do)."""
    b = ProgramBuilder()
    b.var("mode", "System.String")
    main_ = b.panel("Main")
    b.robot(main_)
    main_.chain(main_.add(3, '"deciding"'), main_.add(1, "mode"))
    sensor = main_.add(23, "Robot/IoT Controller 0", "1")
    decide = main_.add(6, 'state.mode == "deciding"')
    turn = main_.add(20, "0.2", "-0.2", "Robot/IoT Controller 0", "3", "5")
    said = main_.add(2, '"turn"')
    show = main_.add(28, "")
    wait = main_.add(3, "400")
    timer = main_.add(15, "")
    done = main_.add(3, '"done"')
    main_.chain(sensor, decide, turn, said, show, wait, timer, done, main_.add(1, "mode"))
    return b.write(tmp_path / "deciding.viple")


def turns_started(tmp_path, report_ms: int | None) -> list[float]:
    spec = RunSpec(
        maze(tmp_path),
        ProgramPilot(deciding(tmp_path), report_ms=report_ms),
        profile="web",
        max_time=2.0,
    )
    printed = run(spec).as_dict()["printed"]
    return [p["time"] for p in printed if p["text"] == "turn"]


def test_a_deciding_state_starts_one_turn_per_report_at_the_simulator_pace(tmp_path):
    # the program starts at the first control tick (0.05 s); reports come 250 ms apart from
    # there, so the 400 ms turn sees one more report before it is over
    assert turns_started(tmp_path, None) == pytest.approx([0.3, 0.55])
    # at 20 reports a second the same program starts eight overlapping turns
    assert len(turns_started(tmp_path, 50)) == 8


def ticking(tmp_path, wait_ms: str) -> str:
    """Prints its message every ``wait_ms`` milliseconds, forever."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    start = main_.add(3, wait_ms)
    merge = main_.add(5, "")
    timer = main_.add(15, "")
    show = main_.add(28, "")
    main_.chain(start, merge, timer, show)
    b.link(show, merge)
    return b.write(tmp_path / "ticking.viple")


def test_a_10_ms_timer_takes_10_ms_of_simulated_time(tmp_path):
    ready = prepare(RunSpec(maze(tmp_path), ProgramPilot(ticking(tmp_path, "10")), profile="web"))
    ready.session.run(1.05, stop_at_exit=False)
    controller = ready.driving.controller
    assert isinstance(controller, ProgramController)
    times = [p.time for p in controller.printed]
    assert len(times) == 100  # from 0.06 s to 1.05 s, not 20 (one a control tick)
    gaps = {round(b - a, 9) for a, b in itertools.pairwise(times)}
    assert gaps == {0.01}


def stop_after(tmp_path, wait_ms: str) -> str:
    """Forward at half power, then stop ``wait_ms`` milliseconds later."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    b.robot(main_)
    go = main_.add(20, "0.5", "0.5", "Robot/IoT Controller 0", "3", "5")
    wait = main_.add(3, wait_ms)
    stop = main_.add(20, "0", "0", "Robot/IoT Controller 0", "3", "5")
    main_.chain(main_.add(3, "1"), go, wait, main_.add(15, ""), stop)
    return b.write(tmp_path / "stop.viple")


def test_a_timer_between_physics_steps_stops_the_robot_at_its_own_time(tmp_path):
    pilot = ProgramPilot(stop_after(tmp_path, "1234"))
    ready = prepare(RunSpec(maze(tmp_path), pilot, profile="web", noise="off"))
    ready.session.run(3.0, stop_at_exit=False)
    # 70 px/s at half power for exactly 1.234 s (a physics step is 1/60 s, a control tick 50 ms)
    assert ready.session.metrics().distance == pytest.approx(70 * 1.234, abs=1e-6)


def test_the_run_is_the_same_at_any_display_speed(tmp_path):
    spec = RunSpec(maze(tmp_path), ProgramPilot(stop_after(tmp_path, "1234")), profile="web")
    poses = []
    for wall in (1 / 60, 0.25, 1.0):
        session = prepare(spec).session
        pacer = Pacer(session)
        pacer.set_speed(None)  # as fast as it goes: many steps per frame
        for _ in range(round(3.0 / wall)):
            pacer.single_step(max(1, round(wall * 60)))
        poses.append((session.world.time, session.world.pose))
    assert poses[0] == poses[1] == poses[2]


def test_step_to_stays_inside_the_current_step(tmp_path):
    session = prepare(
        RunSpec(maze(tmp_path), ProgramPilot(stop_after(tmp_path, "1")), profile="web")
    ).session
    world = session.world
    with pytest.raises(WorldError, match="inside the current step"):
        world.step_to(world.dt * 1.5)
    world.step_to(world.dt / 4)
    world.step()
    assert world.time == world.dt


def remote(tmp_path, wait_ms: str) -> RemoteProgram:
    path = ticking(tmp_path, wait_ms)
    return RemoteProgram(compile_program(load_program(path)))


def test_over_the_protocol_a_timer_ends_at_its_own_time_not_the_next_control_tick(tmp_path):
    program = remote(tmp_path, "10")
    clock = 0.0
    program.start(clock)
    while clock < 0.5:
        clock = program.next_tick()  # the client sleeps until then (a simulated clock here)
        program.tick(clock)
    times = [p.time for p in program.controller.printed]
    assert times[:3] == pytest.approx([0.01, 0.02, 0.03])
    assert len(times) == 50


def test_a_late_wake_up_delays_only_that_timer(tmp_path):
    program = remote(tmp_path, "30")
    program.start(0.0)
    assert program.next_tick() == pytest.approx(0.03)
    program.tick(0.034)  # the loop woke 4 ms late
    assert [p.time for p in program.controller.printed] == [0.034]
    assert program.next_tick() == pytest.approx(0.064)  # the next wait starts from then


def test_a_remote_program_fires_every_report_it_is_given():
    b = ProgramBuilder()
    panel = b.panel("Main")
    b.robot(panel)
    panel.chain(panel.add(23, "R", "2"), panel.add(28, ""))
    program = RemoteProgram(compile_program(load_program_text(b.xml(), "t.viple")))
    program.start(0.0)
    for i in range(1, 6):
        program.report(i * 0.01, {2: i})
    assert [p.text for p in program.controller.printed] == ["1", "2", "3", "4", "5"]


def test_report_ms_out_of_range_is_refused_naming_the_option(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["viple", "run", deciding(tmp_path), "--maze", maze(tmp_path), "--report-ms", "20"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "--report-ms" in err and "use 50 to 1000 ms" in err


def reporter(tmp_path) -> str:
    """Prints every distance report (port 1)."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    b.robot(main_)
    main_.chain(main_.add(23, "Robot/IoT Controller 0", "1"), main_.add(28, ""))
    return b.write(tmp_path / "reporter.viple")


def test_the_lab_station_reports_at_the_profile_period_or_its_own(tmp_path):
    station = LabStation.open(load_maze(maze(tmp_path)), "web", noise="off")
    station.use_program(program_choice(load_compiled(reporter(tmp_path)), "reporter.viple"))
    counts = []
    for report_ms in (None, 100):
        station.report_ms = report_ms
        station.start()
        station.step(120)  # 2 simulated seconds
        controller = station.driving.controller
        assert isinstance(controller, ProgramController)
        counts.append(len(controller.printed))
    # the program starts at 0.05 s: reports at 0.30, 0.55, ... 1.80, or 0.15, 0.25, ... 1.95
    assert counts == [7, 19]


def test_the_shipped_web_wall_following_program_leaves_the_web_maze(capsys):
    root = Path(__file__).resolve().parents[2]
    program = str(root / "programs" / "web-wall-following.viple")
    assert main(["viple", "run", program, "--maze", str(root / "mazes" / "web.txt"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["reached_exit"] and not data["errors"]


def test_timers_end_on_whole_milliseconds_and_a_wait_of_ages_does_not_wake(tmp_path):
    b = ProgramBuilder()
    main_ = b.panel("Main")
    for wait in ("0.25", "1e300", "2.5"):  # (an endless wait is no number: it stops the program)
        main_.chain(main_.add(2, wait), main_.add(15, ""), main_.add(2, '"after " + value'))
    c = ProgramController(compile_program(load_program(b.write(tmp_path / "w.viple"))))
    c.start(0.0)
    assert c.next_due() == pytest.approx(0.001)  # 0.25 ms waits the shortest wait, 1 ms
    c.tick(0.001, {}, frozenset())
    assert c.next_due() == pytest.approx(0.003)  # 2.5 ms ends on the next whole millisecond
    c.tick(0.003, {}, frozenset())
    assert c.next_due() == pytest.approx(1e297) and not c.errors and c.stopped is None
    assert [what for _, _, what in c.running()] == ["sleeping"]
