"""The FSM engine driven by scripted sensor readings, as a session drives it every control tick."""

import time

import pytest

from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import (
    FsmController,
    FsmDefinition,
    FsmDefinitionError,
    FsmRuntimeError,
    MotorAction,
    MoveAction,
    Parameter,
    ParameterError,
    SensorBindingError,
    SensorNeed,
    SetAction,
    State,
    StopAction,
    TimerAction,
    Transition,
    TransitionDef,
    TurnAction,
    Variable,
    WheelsAction,
    bind_sensors,
    preset_sensors,
    resolve_params,
)
from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.sensors import SensorSpec

DT = 1 / 60
TURN_DONE = frozenset({"turn_done"})
FRONT = SensorNeed("front", "distance", "front", {"unity": 2, "web": 2, "erobotic": 1})


def machine(*states, sensors=(FRONT,), parameters=(), variables=(), initial=None):
    return FsmDefinition(
        name="test-fsm",
        initial=initial or states[0].name,
        states=tuple(states),
        sensors=tuple(sensors),
        parameters=tuple(parameters),
        variables=tuple(variables),
    )


def go(target, when="", **assign):
    return TransitionDef(target, when, tuple(assign.items()))


# -- right-wall, the course's rule list --------------------------------------------------


@pytest.fixture
def right_wall():
    ctl = FsmController(load_algorithm("right-wall"), {}, "erobotic")
    assert ctl.start(0.0) == [MoveAtPower(1.0)]
    return ctl


def test_blocked_front_turns_left_then_drives_on_after_turn_done(right_wall):
    clear = {"front": 300.0, "right": 52.0}
    blocked = {"front": 40.0, "right": 52.0}
    assert right_wall.tick(DT, clear) == []
    assert right_wall.tick(2 * DT, blocked) == [TurnByDegrees(-90)]
    assert right_wall.state == "TurningLeft"
    for i in range(3, 30):
        assert right_wall.tick(i * DT, blocked) == []
    assert right_wall.state == "TurningLeft"
    assert right_wall.tick(30 * DT, clear, TURN_DONE) == [MoveAtPower(1.0)]
    assert right_wall.state == "Forward"


def test_open_right_side_drives_on_for_the_delay_then_turns_right(right_wall):
    opening = {"front": 300.0, "right": 172.0}
    assert right_wall.tick(1.0, opening) == [MoveAtPower(1.0)]
    assert right_wall.state == "BesideOpening"
    assert right_wall.tick(1.49, opening) == []
    assert right_wall.tick(1.5, opening) == [TurnByDegrees(90)]
    assert right_wall.tick(3.0, opening, TURN_DONE) == [MoveAtPower(1.0)]
    assert right_wall.state == "TurnedRight"
    # the corridor just left still reads open, but openings are ignored until a wall shows
    assert right_wall.tick(3.1, {"front": 300.0, "right": 900.0}) == []
    assert right_wall.tick(3.2, {"front": 300.0, "right": 52.0}) == [MoveAtPower(1.0)]
    assert right_wall.state == "Forward"


def test_history_records_the_values_the_guard_read(right_wall):
    right_wall.tick(0.5, {"front": 40.0, "right": 60.0})
    (entry,) = right_wall.history
    assert entry == Transition(
        time=0.5,
        source="Forward",
        target="TurningLeft",
        guard_text="front < front_blocked",
        values={"front": 40.0, "front_blocked": 50.0},
    )


def test_history_keeps_only_the_last_entries():
    ping = machine(
        State("A", (), (go("B"),)),
        State("B", (), (go("A"),)),
        sensors=(),
    )
    ctl = FsmController(ping, {}, "web", history_size=3)
    ctl.start(0)
    for i in range(1, 11):
        ctl.tick(i, {})
    assert [h.time for h in ctl.history] == [8, 9, 10]


# -- engine rules ----------------------------------------------------------------------------


def test_first_matching_transition_wins_and_order_decides():
    def build(first, second):
        return machine(
            State("Start", (), (go(first, "front < 100"), go(second, "front < 50"))),
            State("Near"),
            State("Far"),
        )

    a = FsmController(build("Far", "Near"), {}, "unity")
    a.start(0)
    a.tick(DT, {"front": 10})
    assert a.state == "Far"
    b = FsmController(build("Near", "Far"), {}, "unity")
    b.start(0)
    b.tick(DT, {"front": 10})
    assert b.state == "Near"


def test_at_most_one_transition_per_tick():
    chain = machine(
        State("A", (), (go("B"),)),
        State("B", (MoveAction("0.5"),), (go("C"),)),
        State("C", (StopAction(),)),
        sensors=(),
    )
    ctl = FsmController(chain, {}, "web")
    ctl.start(0)
    assert ctl.tick(1, {}) == [MoveAtPower(0.5)] and ctl.state == "B"
    assert ctl.tick(2, {}) == [Stop()] and ctl.state == "C"
    assert ctl.tick(3, {}) == [] and ctl.state == "C"


def test_timers_run_on_simulated_time_not_wall_time():
    waiting = machine(
        State("Wait", (TimerAction("2.5"),), (go("Done", "timer_done"),)),
        State("Done", (StopAction(),)),
        sensors=(),
    )
    ctl = FsmController(waiting, {}, "unity")
    ctl.start(10.0)
    time.sleep(0.05)
    assert ctl.tick(10.0, {}) == []
    assert ctl.timer_remaining(11.0) == pytest.approx(1.5)
    # 149 control ticks at 60 Hz: just short of 2.5 simulated seconds
    for i in range(1, 150):
        assert ctl.tick(10.0 + i * DT, {}) == [], i
    assert ctl.tick(10.0 + 150 * DT, {}) == [Stop()]
    assert ctl.history[-1].values == {"timer_done": True}


def test_a_timer_belongs_to_its_state():
    defn = machine(
        State("A", (TimerAction("1"),), (go("B", "front < 1"),)),
        State("B", (), (go("C", "timer_done"),)),
        State("C"),
    )
    ctl = FsmController(defn, {}, "unity")
    ctl.start(0)
    ctl.tick(0.5, {"front": 0.5})
    assert ctl.state == "B"
    ctl.tick(1.5, {"front": 0.5})
    assert ctl.state == "B", "A's timer must not fire in B"


def test_turn_done_is_forgotten_when_a_state_is_entered():
    defn = machine(
        State("Turning", (TurnAction("90"),), (go("Wait", "front > 0"),)),
        State("Wait", (), (go("Done", "turn_done"),)),
        State("Done"),
    )
    ctl = FsmController(defn, {}, "unity")
    ctl.start(0)
    ctl.tick(DT, {"front": 1}, TURN_DONE)
    assert ctl.state == "Wait"
    ctl.tick(2 * DT, {"front": 1})
    assert ctl.state == "Wait"
    ctl.tick(3 * DT, {"front": 1}, TURN_DONE)
    assert ctl.state == "Done"


def test_transition_set_runs_before_the_targets_on_enter():
    defn = machine(
        State("A", (), (go("B", "front > 0", speed="front / 10"),)),
        State("B", (MoveAction("speed"), SetAction((("count", "count + 1"),)))),
        variables=(Variable("speed", "0"), Variable("count", "start_count")),
        parameters=(Parameter("start_count", {"unity": 5, "web": 5, "erobotic": 5}),),
    )
    ctl = FsmController(defn, {}, "unity")
    ctl.start(0)
    assert ctl.variables == {"speed": 0, "count": 5.0}
    assert ctl.tick(1, {"front": 4}) == [MoveAtPower(0.4)]
    assert ctl.variables == {"speed": 0.4, "count": 6.0}


def test_every_action_makes_its_command_with_powers_clamped():
    defn = machine(
        State(
            "All",
            (
                WheelsAction("p", "-p"),
                MotorAction("left", "2 * p"),
                MoveAction("-5"),
                TurnAction("-(90 + 90)"),
                StopAction(),
            ),
        ),
        sensors=(),
        parameters=(Parameter("p", {"unity": 0.2, "web": 0.2, "erobotic": 0.2}),),
    )
    assert FsmController(defn, {}, "web").start(0) == [
        WheelPowers(0.2, -0.2),
        MotorPower("left", 0.4),
        MoveAtPower(-1.0),
        TurnByDegrees(-180.0),
        Stop(),
    ]


def test_reset_returns_to_the_initial_state_with_fresh_variables():
    ctl = FsmController(load_algorithm("two-distance-local-best"), {}, "erobotic")
    ctl.start(0)
    ctl.tick(1, {"front": 10})
    ctl.tick(2, {"front": 300}, TURN_DONE)
    ctl.tick(3, {"front": 300})
    assert ctl.variables["RightDistance"] == 300
    ctl.reset()
    assert ctl.state == "Forward"
    assert ctl.variables == {"RightDistance": 0}
    assert not ctl.history and not ctl.started
    assert ctl.start(4) == [MoveAtPower(1.0)]


# -- parameters ---------------------------------------------------------------------------


def test_parameter_overrides_change_behaviour():
    ctl = FsmController(load_algorithm("right-wall"), {"front_blocked": 30}, "erobotic")
    ctl.start(0)
    assert ctl.tick(DT, {"front": 40.0, "right": 52.0}) == []
    assert ctl.tick(2 * DT, {"front": 29.0, "right": 52.0}) == [TurnByDegrees(-90)]


def test_parameter_problems_are_all_reported():
    defn = load_algorithm("right-wall")
    with pytest.raises(ParameterError) as info:
        resolve_params(defn, "web", {"front_blokced": 3, "open_right": -1, "turn_wait": "x"})
    text = str(info.value)
    assert "no parameter 'front_blokced' (did you mean 'front_blocked'?)" in text
    assert "open_right=-1 is below its minimum 0" in text
    assert "turn_wait: 'x' is not a number" in text


def test_a_missing_profile_default_names_the_option_to_set_it():
    defn = machine(State("A"), parameters=(Parameter("gap", {"web": 25}),))
    assert FsmController(defn, {}, "web").params == {"gap": 25.0}
    with pytest.raises(ParameterError, match=r"no default for the unity profile.*--param gap="):
        FsmController(defn, {}, "unity")
    assert FsmController(defn, {"gap": 1.0}, "unity").params == {"gap": 1.0}


def test_unknown_profile_is_refused():
    with pytest.raises(ParameterError, match="unknown profile 'lego'"):
        FsmController(load_algorithm("right-wall"), {}, "lego")


# -- errors while running ------------------------------------------------------------------


def test_a_guard_that_fails_names_the_fsm_state_and_expression():
    defn = machine(State("A", (), (go("B", "100 / front > 2"),)), State("B"))
    ctl = FsmController(defn, {}, "web")
    ctl.start(0)
    with pytest.raises(FsmRuntimeError, match=r"test-fsm, state A: guard '100 / front > 2'.*zero"):
        ctl.tick(1, {"front": 0.0})


def test_text_compared_with_a_number_fails_clearly():
    defn = machine(
        State("A", (), (go("B", "mode > front"),)),
        State("B"),
        variables=(Variable("mode", '"fast"'),),
    )
    ctl = FsmController(defn, {}, "web")
    ctl.start(0)
    with pytest.raises(FsmRuntimeError, match="state A: guard 'mode > front' failed"):
        ctl.tick(1, {"front": 1.0})


def test_readings_must_be_keyed_by_sensor_name():
    ctl = FsmController(load_algorithm("right-wall"), {}, "unity")
    ctl.start(0)
    with pytest.raises(FsmRuntimeError, match=r"unknown sensor name\(s\) 1, 2"):
        ctl.tick(DT, {1: 0.5, 2: 3.0})
    ctl.start(0)
    with pytest.raises(FsmRuntimeError, match=r"no reading for sensor\(s\) right"):
        ctl.tick(DT, {"front": 3.0})


def test_tick_before_start_is_an_error():
    ctl = FsmController(load_algorithm("right-wall"), {}, "unity")
    with pytest.raises(FsmRuntimeError, match=r"call start\(\) before tick\(\)"):
        ctl.tick(0, {"front": 1.0, "right": 0.8})


def test_a_broken_definition_lists_every_problem():
    defn = machine(
        State("A", (SetAction((("front", "1"),)),), (go("Nowhere", "frnt < 1"),)),
        initial="Start",
    )
    with pytest.raises(FsmDefinitionError) as info:
        FsmController(defn, {}, "web")
    text = str(info.value)
    assert "the initial state 'Start' is not defined" in text
    assert "unknown state 'Nowhere'" in text
    assert "unknown name 'frnt'" in text
    assert "'front' is not a variable" in text
    assert len(info.value.problems) == 4


# -- sensors --------------------------------------------------------------------------------


def test_preset_sensors_use_each_profiles_default_ports():
    defn = load_algorithm("right-wall")
    assert [str(s) for s in preset_sensors(defn, "unity")] == [
        "distance:1:right",
        "distance:2:front",
    ]
    assert [str(s) for s in preset_sensors(defn, "erobotic")] == [
        "distance:3:right",
        "distance:1:front",
    ]


def test_bind_sensors_matches_by_kind_and_mount_on_any_port():
    defn = load_algorithm("right-wall")
    specs = [SensorSpec("distance", 7, "front"), SensorSpec("distance", 4, "right")]
    assert bind_sensors(defn, specs, "unity") == {"right": 4, "front": 7}


def test_bind_sensors_prefers_the_default_port_when_several_fit():
    defn = load_algorithm("first-working-solution")
    specs = [SensorSpec("distance", 5, "front"), SensorSpec("distance", 2, "front")]
    assert bind_sensors(defn, specs, "unity") == {"front": 2}


def test_a_missing_sensor_names_the_algorithm_what_it_needs_and_an_example():
    defn = load_algorithm("right-wall")
    specs = [SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front")]
    with pytest.raises(SensorBindingError) as info:
        bind_sensors(defn, specs, "web")
    text = str(info.value)
    assert "right-wall needs a distance sensor mounted front (read as 'front')" in text
    assert "--sensor distance:3:front" in text  # port 2, its default, is taken
    assert "the touch sensor touch:2:front cannot stand in for it" in text
    assert "configured sensors: distance:1:right, touch:2:front" in text


def test_every_missing_sensor_is_listed():
    defn = load_algorithm("farthest-distance")
    with pytest.raises(SensorBindingError) as info:
        bind_sensors(defn, [SensorSpec("distance", 2, "front")], "unity")
    text = str(info.value)
    assert "--sensor distance:1:right" in text and "--sensor distance:3:left" in text
    assert "configured sensors: distance:2:front" in text


# -- speed ----------------------------------------------------------------------------------


def test_ticks_without_a_transition_stay_in_the_state_and_command_nothing_new():
    # what such a tick costs (target: under 50 µs): bench/fsm_tick.py
    ctl = FsmController(load_algorithm("self-adjusting-wall"), {}, "web")
    ctl.start(0)
    readings = {"front": 300.0, "right": 25.0}
    none = frozenset()
    ctl.tick(DT, readings, none)
    assert ctl.state == "Forward"
    for i in range(2, 2_000):
        assert ctl.tick(i * DT, readings, none) == [], i
    assert ctl.state == "Forward"
