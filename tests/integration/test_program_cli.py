"""`workbench viple check`, `show` and `run` as a user runs them, and the real VIPLE programs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.sim.driver import Driver
from workbench.sim.record import read_record, recorded_driver

REAL = Path(__file__).resolve().parents[3] / "shared" / "viple-programs"
WEB_MAZE = str(Path(__file__).resolve().parents[2] / "mazes" / "web.txt")


def forward_program(tmp_path) -> str:
    b = ProgramBuilder()
    main_panel = b.panel("Main")
    b.robot(main_panel)
    key = main_panel.add(13, "22")
    drive = main_panel.add(20, "0.5", "0.5", "Robot/IoT Controller 0", "3", "5")
    text = main_panel.add(3, '"going"')
    show = main_panel.add(28, "")
    main_panel.chain(key, drive, text, show)
    return b.write(tmp_path / "forward.viple")


def test_check_exit_codes_and_problem_lines(tmp_path, capsys):
    good = forward_program(tmp_path)
    bad = tmp_path / "bad.viple"
    bad.write_bytes(b"<Program><Version>4.0</Version>")
    assert main(["viple", "check", good]) == 0
    assert "ok (VIPLE 4.0.0.1, 5 activities" in capsys.readouterr().out
    assert main(["viple", "check", good, str(bad)]) == 1
    out = capsys.readouterr().out
    assert f"{bad}: line 1, column 32: the XML is not well formed" in out
    with pytest.raises(SystemExit) as info:
        main(["viple", "check"])
    assert info.value.code == 2


def test_run_prints_measures_prints_and_events(tmp_path, capsys):
    path = forward_program(tmp_path)
    code = main(["viple", "run", path, "--maze", WEB_MAZE, "--keys", "w@0.5", "--max-time", "3"])
    out = capsys.readouterr().out
    assert code == 1  # the maze has an exit the robot did not reach
    assert "forward.viple on" in out and "distance travelled" in out and "turning degrees" in out
    assert "0.50 s  going" in out and "0.50 s  key w" in out


def test_a_run_without_the_key_the_program_starts_on_says_which_key_to_press(tmp_path, capsys):
    path = forward_program(tmp_path)
    hint = 'no key event fired: the program answers w (Key Press); press one with --keys "w@0.5"'
    main(["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "2"])
    out = capsys.readouterr().out
    assert "distance travelled  0.0 px" in out and hint in out
    main(["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "2", "--keys", "a@0.5"])
    assert hint in capsys.readouterr().out  # a key the program does not answer: the same
    main(["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "2", "--keys", "w@0.5"])
    assert "no key event fired" not in capsys.readouterr().out


def test_run_json_is_deterministic(tmp_path, capsys):
    path = forward_program(tmp_path)
    args = ["viple", "run", path, "--maze", WEB_MAZE, "--keys", "w@0.2", "--max-time", "4"]
    outs = []
    for _ in range(2):
        main([*args, "--json", "--seed", "3", "--noise", "realistic"])
        outs.append(capsys.readouterr().out)
    assert outs[0] == outs[1]
    data = json.loads(outs[0])
    assert data["distance"] > 0 and data["printed"] == [{"time": 0.2, "text": "going"}]
    assert len(data["program_sha256"]) == 64


def test_a_run_record_says_the_program_drove_as_the_app_s_records_do(tmp_path, capsys):
    path = forward_program(tmp_path)
    record = tmp_path / "run.jsonl"
    args = ["viple", "run", path, "--maze", WEB_MAZE, "--keys", "w@0.2", "--max-time", "2"]
    main([*args, "--record", str(record), "--json"])
    digest = json.loads(capsys.readouterr().out)["program_sha256"]
    header = read_record(record).header
    assert recorded_driver(header) == Driver.program("forward.viple", digest)
    assert (header["program"], header["program_sha256"]) == ("forward.viple", digest)
    assert header["algorithm"] == "VIPLE program forward.viple" and header["params"] == {}


def test_missing_sensor_is_an_error_before_the_run(tmp_path, capsys):
    b = ProgramBuilder()
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, "Robot/IoT Controller 0", "7")
    path = b.write(tmp_path / "s.viple")
    assert main(["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "1"]) == 2
    err = capsys.readouterr().err
    assert f"activity {sensor} (kind 23, Robot Distance Sensor): it reads port 7" in err
    assert "add --sensor distance:7:MOUNT" in err


@pytest.mark.skipif(not REAL.is_dir(), reason="the real VIPLE programs (../shared) are not here")
class TestRealPrograms:
    def test_each_real_program_loads(self, capsys):
        files = sorted(str(p) for p in REAL.iterdir() if p.suffix in (".viple", ".xml"))
        assert files and main(["viple", "check", *files]) == 0

    @pytest.mark.parametrize(
        ("key", "powers"),
        [("w", (0.5, 0.5)), ("a", (-1.0, 1.0)), ("d", (1.0, -1.0)), ("s", (-0.5, -0.5))],
    )
    def test_drive_by_wire_answers_its_keys(self, key, powers):
        from workbench.program.interp import ProgramController
        from workbench.program.keys import parse_key_script
        from workbench.program.pilot import load_compiled

        compiled = load_compiled(str(REAL / "DriveByWire.viple"))
        c = ProgramController(compiled, parse_key_script(f"{key}@0.1 release@0.2"))
        c.start(0.0)
        commands = [cmd for t in (0.1, 0.2) for cmd in c.tick(t, {}, frozenset())]
        assert [(cmd.left, cmd.right) for cmd in commands] == [powers, (0.0, 0.0)]

    def test_servo_control_arrow_keys(self):
        from workbench.program.interp import ProgramController
        from workbench.program.keys import parse_key_script
        from workbench.program.pilot import load_compiled

        compiled = load_compiled(str(REAL / "servo-control.xml"))
        script = (
            "up@0.1 release@0.15 left@0.2 release@0.25 right@0.3 release@0.35 down@0.4 space@0.5"
        )
        c = ProgramController(compiled, parse_key_script(script))
        c.start(0.0)
        commands = [cmd for i in range(1, 11) for cmd in c.tick(i * 0.05, {}, frozenset())]
        assert [(cmd.left, cmd.right) for cmd in commands] == [
            (1, 1),
            (-1, 1),
            (1, -1),
            (-1, -1),
            (0, 0),
        ]

    def test_wall_follower_follows_a_wall(self, capsys):
        args = [
            "viple",
            "run",
            str(REAL / "WallFollower.viple"),
            "--maze",
            WEB_MAZE,
            "--sensor",
            "touch:1:front",
            "--sensor",
            "distance:3:right",
            "--keys",
            "a@0.2",
            "--max-time",
            "30",
            # written for a robot measuring in cm, in this maze the program pins itself
            # against a wall within 8 s at the simulator's pace of 250 ms; 20 reports a
            # second let it follow the wall for the whole run
            "--report-ms",
            "50",
            "--json",
        ]
        main(args)
        data = json.loads(capsys.readouterr().out)
        assert data["distance_cells"] > 10 and data["turns"] >= 4 and not data["errors"]
        assert data["events"][0]["event"] == "key a"
        assert len(data["printed"]) > 500  # every distance report is printed


def test_the_shipped_example_leaves_the_web_maze(capsys):
    example = str(Path(WEB_MAZE).parents[1] / "programs" / "right-wall.viple")
    assert main(["viple", "run", example, "--maze", WEB_MAZE, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["reached_exit"] and not data["errors"]


def test_show_prints_panels_activities_and_links_in_80_columns(tmp_path, capsys):
    path = forward_program(tmp_path)
    assert main(["viple", "show", path]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(path[:60])  # a long path is cut at 80 columns
    assert any(line.startswith("panel Main") for line in out)
    assert any(" -> " in line for line in out)  # the links, from each activity's outputs
    assert max(len(line) for line in out) <= 80
    bad = tmp_path / "bad.viple"
    bad.write_text("<not a program")
    assert main(["viple", "show", str(bad)]) == 1
    assert "bad.viple" in capsys.readouterr().err


def test_eval_ranks_programs_beside_algorithms(tmp_path, capsys):
    example = str(Path(WEB_MAZE).parents[1] / "programs" / "right-wall.viple")
    maze = str(Path(WEB_MAZE).parent / "rank-wall-wins.txt")
    args = ["eval", "--maze", maze, "--algorithm", "right-wall", "--program", example]
    assert main([*args, "--profile", "web", "--seeds", "2", "--jobs", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    cells = {c["algorithm"]: c for c in data["cells"]}
    assert set(cells) == {"right-wall", "right-wall.viple"}
    assert cells["right-wall.viple"]["runs"] == 2 and cells["right-wall.viple"]["reached"] == 2
    assert sorted(data["ranking"][maze]) == ["right-wall", "right-wall.viple"]
    assert main(["eval", "--maze", maze, "--program", example, example]) == 2
    assert "right-wall.viple: give each once" in capsys.readouterr().err
    assert main(["eval", "--maze", maze]) == 2
    assert "give --algorithm" in capsys.readouterr().err


def test_run_typed_keys_are_released_as_in_the_app(tmp_path, capsys):
    b = ProgramBuilder()
    panel = b.panel("Main")
    b.robot(panel)
    panel.chain(panel.add(13, "22"), panel.add(20, "0.5", "0.5", "R", "3", "5"))
    panel.chain(panel.add(29, ""), panel.add(20, "0", "0", "R", "3", "5"))
    path = b.write(tmp_path / "wire.viple")
    args = ["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "3", "--json"]
    main([*args, "--typed", "w@0.5 w@0.9 w@1.3"])
    data = json.loads(capsys.readouterr().out)
    events = [(e["time"], e["event"]) for e in data["events"]]
    # the repeats keep w held; 0.75 s after the last one it is released (at the next tick)
    assert events == [(0.5, "key w"), (2.05, "key release")]
