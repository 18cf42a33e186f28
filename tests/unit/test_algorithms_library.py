"""The built-in algorithms: they load, carry the course's numbers per profile, behave as the
course describes, find the way out of a maze, and are listed by `workbench algorithms`."""

import json

import pytest

from workbench.cli import main
from workbench.fsm.algorithms import list_algorithms, load_algorithm
from workbench.fsm.machine import PROFILES, FsmController, bind_sensors, preset_sensors
from workbench.fsm.yaml_file import FsmFileError
from workbench.sim.commands import MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.mazefile import parse_maze
from workbench.sim.session import Session

COURSE = [
    "right-wall",
    "farthest-distance",
    "one-distance-first",
    "first-working-solution",
    "two-distance-local-best",
    "self-adjusting-wall",
    "web-wall-following",
    "web-two-distance",
]
DONE = frozenset({"turn_done"})


def controller(name, profile, **params):
    ctl = FsmController(load_algorithm(name), params, profile)
    first = ctl.start(0.0)
    return ctl, first


def defaults(name, profile):
    return FsmController(load_algorithm(name), {}, profile).params


def test_all_course_algorithms_are_listed_in_course_order():
    assert list_algorithms() == COURSE


@pytest.mark.parametrize("name", COURSE)
def test_each_builtin_is_complete_for_every_profile(name):
    defn = load_algorithm(name)
    assert defn.name == name
    assert len(defn.description) > 150
    assert defn.sensors
    for p in defn.parameters:
        assert set(p.defaults) == set(PROFILES), p.name
        assert p.description, p.name
    for profile in PROFILES:
        ctl = FsmController(defn, {}, profile)
        assert ctl.start(0.0), f"{name} does nothing when it starts on {profile}"
        specs = preset_sensors(defn, profile)
        assert set(bind_sensors(defn, specs, profile)) == {s.name for s in defn.sensors}


def test_rule_list_thresholds_are_the_courses_per_profile():
    rw = {p: defaults("right-wall", p) for p in PROFILES}
    assert (rw["erobotic"]["open_right"], rw["erobotic"]["front_blocked"]) == (100, 50)
    assert (rw["unity"]["open_right"], rw["unity"]["front_blocked"]) == (1.0, 0.9)
    assert (rw["web"]["open_right"], rw["web"]["front_blocked"]) == (75, 25)
    assert rw["unity"]["turn_wait"] == 5
    assert defaults("farthest-distance", "erobotic")["front_open"] == 50
    assert defaults("two-distance-local-best", "unity")["front_blocked"] == 1.0
    assert defaults("two-distance-local-best", "unity")["stop_wait"] == 3


def test_web_programs_use_the_courses_powers_and_times():
    web = defaults("web-wall-following", "web")
    assert web["base_distance"] == 25 and web["open_margin"] == 50
    assert web["forward_power"] == 0.5 and web["backward_power"] == -0.3
    assert web["backward_time"] == 0.5 and web["turn_power"] == 0.2
    assert web["turn90_time"] == 1.5 and web["pause_time"] == 3.0
    two = defaults("web-two-distance", "web")
    assert two["front_blocked"] == 25 and two["turn180_time"] == 3.0
    assert preset_sensors(load_algorithm("web-two-distance"), "web")[0].port == 3


def test_physical_robot_numbers_say_they_are_scaled():
    for name in ("first-working-solution", "two-distance-local-best", "self-adjusting-wall"):
        text = " ".join(p.description for p in load_algorithm(name).parameters)
        assert "physical robot" in text and "scaled" in text, name


def test_farthest_distance_states_and_applies_its_tie_rule():
    assert "Tie rule" in load_algorithm("farthest-distance").description
    ctl, _ = controller("farthest-distance", "erobotic")
    assert ctl.tick(0.1, {"front": 40, "left": 52, "right": 52}) == [TurnByDegrees(90)]
    ctl, _ = controller("farthest-distance", "erobotic")
    assert ctl.tick(0.1, {"front": 40, "left": 172, "right": 52}) == [TurnByDegrees(-90)]
    ctl, _ = controller("farthest-distance", "erobotic")
    assert ctl.tick(0.1, {"front": 60, "left": 172, "right": 52}) == []


def test_one_distance_first_turns_right_when_open_else_left():
    ctl, _ = controller("one-distance-first", "erobotic")
    assert ctl.tick(0.1, {"front": 200, "right": 172}) == [], "front clear: keep going"
    assert ctl.tick(0.2, {"front": 40, "right": 172}) == [TurnByDegrees(90)]
    ctl, _ = controller("one-distance-first", "erobotic")
    assert ctl.tick(0.1, {"front": 40, "right": 52}) == [TurnByDegrees(-90)]
    ctl, _ = controller("one-distance-first", "erobotic", right_blocked=50)
    assert ctl.tick(0.1, {"front": 40, "right": 52}) == [], "the course's gap, on request"


def test_first_working_solution_looks_left_then_spins_when_it_is_closed():
    ctl, first = controller("first-working-solution", "erobotic")
    assert first == [MoveAtPower(1.0)]
    assert ctl.tick(1, {"front": 40}) == [TurnByDegrees(-90)]
    assert ctl.tick(2, {"front": 52}, DONE) == []
    assert ctl.state == "TurnedLeft"
    assert ctl.tick(3, {"front": 52}) == [TurnByDegrees(180)]
    assert ctl.tick(4, {"front": 400}, DONE) == [MoveAtPower(1.0)]
    ctl, _ = controller("first-working-solution", "erobotic")
    ctl.tick(1, {"front": 40})
    ctl.tick(2, {"front": 172}, DONE)
    assert ctl.tick(3, {"front": 172}) == [MoveAtPower(1.0)], "open enough: go left"


def test_two_distance_local_best_remembers_the_right_and_compares():
    ctl, _ = controller("two-distance-local-best", "erobotic")
    assert ctl.tick(1, {"front": 40}) == [TurnByDegrees(90)]
    assert ctl.tick(2, {"front": 300}, DONE) == [Stop()]
    assert ctl.tick(3, {"front": 300}) == [TurnByDegrees(-180)]
    assert ctl.variables["RightDistance"] == 300
    assert ctl.tick(4, {"front": 100}, DONE) == [Stop()]
    assert ctl.tick(5, {"front": 100}) == [TurnByDegrees(180)], "right was farther"
    assert ctl.tick(6, {"front": 300}, DONE) == [MoveAtPower(1.0)]


def test_unity_turns_wait_like_the_courses_unity_program():
    ctl, _ = controller("two-distance-local-best", "unity")
    ctl.tick(1, {"front": 0.5})
    assert ctl.tick(3.6, {"front": 3.0}, DONE) == [], "turn done but the 5 s wait is not"
    assert ctl.tick(6.0, {"front": 3.0}) == [Stop()]


def test_self_adjusting_wall_corrects_by_one_degree():
    ctl, _ = controller("self-adjusting-wall", "web")
    assert ctl.tick(0.1, {"front": 300, "right": 25}) == []
    assert ctl.tick(0.2, {"front": 300, "right": 31}) == [TurnByDegrees(1)]
    ctl, _ = controller("self-adjusting-wall", "web")
    assert ctl.tick(0.1, {"front": 300, "right": 19}) == [TurnByDegrees(-1)]
    ctl, _ = controller("self-adjusting-wall", "web")
    assert ctl.tick(0.1, {"front": 300, "right": 95}) == [MoveAtPower(0.5)]
    assert ctl.state == "BesideOpening"


def test_web_wall_following_backs_off_and_spins_on_touch():
    ctl, first = controller("web-wall-following", "web")
    assert first == [WheelPowers(0.5, 0.5)]
    assert ctl.tick(1.0, {"right": 25, "touch": 1}) == [WheelPowers(-0.3, -0.3)]
    assert ctl.tick(1.49, {"right": 25, "touch": 0}) == []
    assert ctl.tick(1.5, {"right": 25, "touch": 0}) == [WheelPowers(-0.2, 0.2)]
    assert ctl.tick(3.0, {"right": 25, "touch": 0}) == [WheelPowers(0, 0)]
    assert ctl.tick(6.0, {"right": 25, "touch": 0}) == [WheelPowers(0.5, 0.5)]


def test_load_by_path_and_unknown_names(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("initial: A\nstates:\n  A:\n    on_enter: [stop]\n")
    assert load_algorithm(str(path)).name == "mine"
    with pytest.raises(FsmFileError, match="did you mean 'right-wall'"):
        load_algorithm("rigth-wall")


# -- in a real session --------------------------------------------------------------------

MAZE = """\
---
name: test maze
---
###############
#.............#
###.#########.#
#...#.......#.E
#.#########.###
#.........#...#
#.#######.###.#
#.#.....#.....#
#.#####.#######
#^............#
###############
"""
HOME = {
    "right-wall": "erobotic",
    "farthest-distance": "erobotic",
    "one-distance-first": "erobotic",
    "first-working-solution": "unity",
    "two-distance-local-best": "unity",
    "self-adjusting-wall": "unity",
    "web-wall-following": "web",
    "web-two-distance": "web",
}


def run(name, profile, noise="off"):
    defn = load_algorithm(name)
    specs = preset_sensors(defn, profile)
    session = Session(parse_maze(MAZE), profile, sensors=specs, noise=noise)
    session.attach(FsmController(defn, {}, profile), bind_sensors(defn, specs, profile), name)
    return session.run(900.0)


@pytest.mark.parametrize("name", COURSE)
def test_every_builtin_gets_out_of_the_maze_on_its_home_profile(name):
    metrics = run(name, HOME[name])
    assert metrics.reached_exit, f"{name} did not reach the exit"


def test_right_wall_takes_longer_than_farthest_distance_as_the_chapter_says():
    wall = run("right-wall", "erobotic")
    farthest = run("farthest-distance", "erobotic")
    assert wall.exit_time > farthest.exit_time
    assert wall.distance > farthest.distance


# -- `workbench algorithms` ------------------------------------------------------------------


def test_cli_lists_every_algorithm_with_sensors_and_defaults(capsys):
    assert main(["algorithms"]) == 0
    out = capsys.readouterr().out
    for name in COURSE:
        assert f"\n{name}\n" in f"\n{out}"
    assert "parameters (defaults for unity / web / erobotic):" in out
    assert "open_right = 1 / 75 / 100" in out
    assert "front: distance sensor mounted front, port 2 / 2 / 1" in out
    assert "touch: touch sensor mounted front, port 2" in out


def test_cli_json_has_defaults_per_profile(capsys):
    assert main(["algorithms", "--json", "right-wall", "web-two-distance"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [d["name"] for d in data] == ["right-wall", "web-two-distance"]
    params = {p["name"]: p for p in data[0]["parameters"]}
    assert params["front_blocked"]["defaults"] == {"unity": 0.9, "web": 25.0, "erobotic": 50.0}
    assert params["front_blocked"]["min"] == 0
    assert data[1]["sensors"] == [
        {"name": "front", "kind": "distance", "mount": "front", "ports": {p: 3 for p in PROFILES}}
    ]


def test_cli_checks_a_student_file(tmp_path, capsys):
    bad = tmp_path / "mine.yaml"
    bad.write_text("initial: A\nstates:\n  A:\n    transitions:\n      - to: B\n")
    assert main(["algorithms", str(bad)]) == 1
    err = capsys.readouterr().err
    assert f"{bad}:5:13: unknown state 'B' in to:" in err


def test_cli_unknown_name_suggests(capsys):
    assert main(["algorithms", "farthest"]) == 1
    assert "built-ins: right-wall" in capsys.readouterr().err
