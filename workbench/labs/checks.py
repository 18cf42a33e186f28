"""The automatic checks of a lab exercise, read from the live station and its runs.

Each objective gives a :class:`Check`: passed or not, a one-line reason the app shows next to
✓ or ✗, and the evidence a sign-off keeps (the run, its metrics and its record's digest).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from workbench.control.algorithms import ALGORITHM_DIR
from workbench.control.manual import KEY_NAMES
from workbench.control.station import LabStation, RunEntry
from workbench.sim.profiles import get_profile
from workbench.sim.record import file_sha256

from .model import Exercise, LabMaze, Objective, Setup

ROLE_NAMES = {"tcp": "TCP (the Unity simulator's role)", "ws": "WebSocket (the Web Simulator's)"}


@dataclass(frozen=True)
class Check:
    passed: bool
    reason: str
    evidence: dict[str, Any] = field(default_factory=dict)


@dataclass
class ObjectiveState:
    kind: str
    text: str
    passed: bool
    reason: str
    evidence: dict[str, Any] = field(default_factory=dict)


#: the longest answer kept, in characters (an answer is a number or a choice: a few words),
#: and the most answers one exercise keeps
MAX_ANSWER = 200
MAX_ANSWERS = 100


def capped_answers(answers: Mapping[Any, Any]) -> tuple[dict[str, str], tuple[str, ...]]:
    """The answers as kept: at most :data:`MAX_ANSWERS`, each cut to :data:`MAX_ANSWER`
    characters; and the questions whose answers were cut (or dropped)."""
    kept: dict[str, str] = {}
    cut: list[str] = []
    for key, value in answers.items():
        name, text = str(key)[:MAX_ANSWER], str(value)
        if len(kept) >= MAX_ANSWERS:
            cut.append(name)
            continue
        if len(text) > MAX_ANSWER:
            cut.append(name)
            text = text[:MAX_ANSWER]
        kept[name] = text
    return kept, tuple(cut)


@dataclass
class ExerciseProgress:
    """Where one exercise stands: every objective's state (and the answers given)."""

    lab: str
    exercise: str
    objectives: list[ObjectiveState]
    answers: dict[str, str] = field(default_factory=dict)
    #: questions whose answers, as read back, were longer than is kept and were cut
    cut: tuple[str, ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        self.answers, cut = capped_answers(self.answers)
        self.cut = (*self.cut, *cut)

    @property
    def passed(self) -> bool:
        return all(o.passed for o in self.objectives)

    def to_json(self) -> str:
        data = {k: v for k, v in asdict(self).items() if k != "cut"}
        return json.dumps({**data, "passed": self.passed}, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> ExerciseProgress:
        return cls.from_dict(json.loads(text))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ExerciseProgress:
        """Progress as saved (:meth:`to_json`); ValueError when it is not in that shape."""
        try:
            objectives = [ObjectiveState(**o) for o in data["objectives"]]
            answers = dict(data.get("answers") or {})
            return cls(str(data["lab"]), str(data["exercise"]), objectives, answers)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"saved progress is not in the expected shape: {exc}") from None

    def evidence_digest(self) -> str:
        """sha256 of the objectives' states and evidence, in a canonical JSON form."""
        states = [asdict(o) for o in self.objectives]
        text = json.dumps(states, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


KEPT = "passed earlier: "


def keep_passed(saved: ExerciseProgress | None, live: ExerciseProgress) -> ExerciseProgress:
    """``live`` with every objective that passed in ``saved`` still passed, with its evidence.

    What was checked once is not lost: after a restart (or a new robot, a new maze) the station
    no longer shows the run that passed, but the saved progress does. Objectives are matched
    by kind and text, so a changed lab file does not carry over a different objective. The
    questions follow the answers as they stand (those are saved and shown again).
    """
    if saved is None:
        return live
    earlier = {(o.kind, o.text): o for o in saved.objectives if o.passed and o.kind != "questions"}
    objectives = []
    for o in live.objectives:
        before = earlier.get((o.kind, o.text))
        if o.passed or before is None:
            objectives.append(o)
        else:
            reason = before.reason if before.reason.startswith(KEPT) else KEPT + before.reason
            objectives.append(ObjectiveState(o.kind, o.text, True, reason, before.evidence))
    return ExerciseProgress(live.lab, live.exercise, objectives, live.answers)


# -- set-up --------------------------------------------------------------------------------
@dataclass(frozen=True)
class SetupChanges:
    """What a set-up changed on the station besides its profile, maze and sensors: each a
    ``(before, after)`` pair, or None when it stayed as it was."""

    speed: tuple[float | None, float | None] | None = None
    #: the algorithm's name (None: no algorithm; the keys drive)
    algorithm: tuple[str | None, str | None] | None = None
    #: parameters the student had changed, back at the algorithm's values for the profile
    params_reset: bool = False
    #: the VIPLE program file that was chosen to drive (no longer chosen)
    program_dropped: str | None = None


def apply_setup(station: LabStation, setup: Setup) -> SetupChanges:
    """The exercise's one-key set-up: profile, maze, sensors, speed and the controller to use
    (the maze and starter as they were when the lab was loaded), and nothing kept from before:
    an exercise without an algorithm has none, and the parameters are the algorithm's own
    values for the profile. Returns what changed beyond the profile, maze and sensors."""
    speed_before = station.pacer.speed
    algorithm_before = station.algorithm.name if station.algorithm is not None else None
    params_before = bool(station.overrides)
    program_before = station.program.name if station.program is not None else None
    station.profile = setup.profile
    station.load_maze(setup.maze.maze)
    station.apply_sensors(setup.sensors or get_profile(setup.profile).sensors)
    controller = setup.controller
    if controller.starter is not None:
        station.use_algorithm(controller.starter)
    elif controller.kind == "algorithm":
        station.select_algorithm(controller.value)
    else:
        station.clear_algorithm()
    station.program = None
    station.pacer.set_speed(setup.speed)
    station.pause(False)
    station.start_exercise()
    algorithm_after = station.algorithm.name if station.algorithm is not None else None
    same_algorithm = algorithm_before == algorithm_after
    return SetupChanges(
        speed=None if speed_before == setup.speed else (speed_before, setup.speed),
        algorithm=None if same_algorithm else (algorithm_before, algorithm_after),
        params_reset=params_before and algorithm_after is not None and same_algorithm,
        program_dropped=program_before,
    )


# -- evidence ------------------------------------------------------------------------------
def record_digest(path: str | None) -> str | None:
    """sha256 of a run record file, or None when the run was not recorded (or is gone)."""
    if not path:
        return None
    try:
        return file_sha256(path)
    except OSError:
        return None


def run_evidence(run: RunEntry) -> dict[str, Any]:
    program = {"program_sha256": run.driver.digest} if run.driver.digest else {}
    return {
        "run": run.number,
        "driver": str(run.driver),
        **program,
        "maze": run.maze,
        "maze_digest": run.maze_digest,
        "profile": run.profile,
        "ended": run.ended,
        "metrics": run.metrics.as_dict(),
        "record": run.record,
        "record_sha256": record_digest(run.record),
    }


def driver_kinds(run: RunEntry) -> set[str]:
    """What kinds of driver an ``exit`` objective would see in ``run``."""
    kinds = {"any"}
    if run.driver.kind == "viple":
        kinds.add("viple")
    elif run.driver.kind == "program" and run.driver.digest:
        kinds.update(("viple", "program"))  # the student's VIPLE program file, run here
    elif run.driver.kind == "algorithm" and run.source:
        if Path(run.source).resolve().parent == ALGORITHM_DIR:
            kinds.add(f"algorithm {run.driver.name}")
        else:
            kinds.add("fsm")
    return kinds


# -- the objective kinds -------------------------------------------------------------------
def check_keys(obj: Objective, station: LabStation) -> Check:
    """The drive keys pressed on the station, or (with ``role``) the same motions asked for by a
    VIPLE program over that role: its own key bindings turned into commands."""
    missing = [k for k in obj.keys if k not in station.keys_used]
    evidence: dict[str, Any] = {"keys_used": sorted(station.keys_used)}
    if not missing:
        return Check(True, f"used {', '.join(obj.keys)}", evidence)
    if obj.role:
        wanted = [KEY_NAMES[k] for k in obj.keys]
        for c in reversed([c for c in station.viple if c.role == obj.role]):
            if all(m in c.motions for m in wanted):
                evidence = {"role": c.role, "peer": c.peer, "motions": sorted(c.motions)}
                reason = f"VIPLE {c.role} program asked for {', '.join(wanted)}"
                return Check(True, reason, evidence)
        motions = set().union(*(c.motions for c in station.viple if c.role == obj.role))
        if motions:
            lacking = [m for m in wanted if m not in motions]
            return Check(False, f"VIPLE has not asked for {', '.join(lacking)} yet", evidence)
    return Check(False, f"not used yet: {', '.join(missing)}", evidence)


def check_sensors(obj: Objective, station: LabStation) -> Check:
    have = {str(s) for s in station.sensors}
    want = {str(s) for s in obj.sensors}
    evidence = {"sensors": sorted(have)}
    if have == want:
        return Check(True, f"sensors are {', '.join(sorted(want)) or 'none'}", evidence)
    parts = []
    if want - have:
        parts.append(f"missing {', '.join(sorted(want - have))}")
    if have - want:
        parts.append(f"not wanted {', '.join(sorted(have - want))}")
    return Check(False, "; ".join(parts), evidence)


def check_viple(obj: Objective, station: LabStation) -> Check:
    mine = [c for c in station.viple if c.role == obj.role]
    drove = [c for c in mine if c.drove]
    if drove:
        c = drove[-1]
        evidence = {"role": c.role, "peer": c.peer, "distance": round(c.distance, 4),
                    "turn_degrees": round(c.turn_degrees, 4)}  # fmt: skip
        return Check(True, f"VIPLE {c.role} program at {c.peer} drove the robot", evidence)
    if mine:
        return Check(False, f"VIPLE {obj.role} program connected but has not moved the robot")
    others = sorted({c.role for c in station.viple})
    if others:
        return Check(
            False,
            f"VIPLE connected over {', '.join(others)}; this exercise needs {ROLE_NAMES[obj.role]}",
        )
    return Check(False, f"no VIPLE program has connected over {ROLE_NAMES[obj.role]} yet")


def _limits(obj: Objective, run: RunEntry) -> str | None:
    """What limit ``run`` breaks, or None."""
    m = run.metrics
    took = m.exit_time if m.exit_time is not None else m.sim_time
    # measured to a thousandth, so that a 90.0000001° quarter turn meets a 90° limit
    if obj.max_time is not None and round(took, 3) > obj.max_time:
        return f"took {took:.1f} s, over the {obj.max_time:g} s limit"
    if obj.max_turn_degrees is not None and round(m.turn_degrees, 3) > obj.max_turn_degrees:
        return f"turned {m.turn_degrees:.0f}°, over the {obj.max_turn_degrees:g}° limit"
    if obj.max_collisions is not None and m.collisions > obj.max_collisions:
        return f"hit a wall {m.collisions} times, over the limit of {obj.max_collisions}"
    return None


def _exits(station: LabStation, maze: LabMaze, profile: str) -> list[RunEntry]:
    """Runs that reached the exit of exactly the lab's ``maze`` (same layout) on ``profile``."""
    return [
        r
        for r in station.runs
        if r.ended == "exit" and r.maze_digest == maze.digest and r.profile == profile
    ]


def _not_the_lab_maze(station: LabStation, maze: LabMaze, profile: str) -> RunEntry | None:
    """The last run that got out of a maze of the same name as the lab's but not its layout."""
    others = [
        r
        for r in station.runs
        if r.ended == "exit" and r.maze == maze.name and r.profile == profile
        and r.maze_digest != maze.digest
    ]  # fmt: skip
    return others[-1] if others else None


def check_exit(obj: Objective, exercise: Exercise, station: LabStation) -> Check:
    assert obj.maze is not None
    maze = obj.maze
    profile = exercise.setup.profile
    wanted = set(obj.drivers)
    runs = [r for r in _exits(station, maze, profile) if driver_kinds(r) & wanted]
    drivers = " or ".join(obj.drivers)
    if not runs:
        other = _not_the_lab_maze(station, maze, profile)
        if other is not None:
            return Check(
                False,
                f"run {other.number} got out of a changed copy of {maze.name!r}, not the lab's "
                "maze: set the exercise up again (a) and drive the maze as it is given",
            )
        return Check(
            False, f"no run by {drivers} has reached the exit of {maze.name!r} ({profile}) yet"
        )
    for run in runs:
        if _limits(obj, run) is None:
            m = run.metrics
            reason = (
                f"run {run.number} ({run.driver}) got out in {m.exit_time:.1f} s, "
                f"{m.turn_degrees:.0f}° turned, {m.collisions} collisions"
            )
            return Check(True, reason, run_evidence(run))
    last = runs[-1]
    return Check(False, f"run {last.number} ({last.driver}) {_limits(obj, last)}", {})


def check_maze_edited(exercise: Exercise, station: LabStation) -> Check:
    original = exercise.setup.maze.maze
    evidence = {"maze_digest": station.maze.digest(), "original_digest": original.digest()}
    if station.maze.same_layout(original):
        return Check(False, f"the maze is still {original.name!r} as set up: add or remove a block")
    problems = station.maze.validate()
    if problems:
        first = problems[0]
        return Check(
            False, f"the edited maze has {len(problems)} problem(s): {first.message}", evidence
        )
    return Check(True, "the maze was edited and is valid", evidence)


def check_compare(obj: Objective, exercise: Exercise, station: LabStation) -> Check:
    table: list[dict[str, Any]] = []
    missing = []
    for maze in obj.mazes:
        for name in obj.algorithms:
            runs = [
                r
                for r in _exits(station, maze, exercise.setup.profile)
                if f"algorithm {name}" in driver_kinds(r)
            ]
            if runs:
                table.append({"algorithm": name, **run_evidence(runs[-1])})
            else:
                missing.append(f"{name} on {maze.name!r} ({exercise.setup.profile})")
    if missing:
        more = f" (+{len(missing) - 1} more)" if len(missing) > 1 else ""
        return Check(False, f"no run to the exit yet: {missing[0]}{more}", {"runs": table})
    return Check(True, f"{len(table)} runs to compare", {"runs": table})


def check_questions(exercise: Exercise, answers: Mapping[str, str]) -> Check:
    answers, _ = capped_answers(answers)
    unanswered = [q.id for q in exercise.questions if not str(answers.get(q.id, "")).strip()]
    wrong = [q.id for q in exercise.questions if q.id not in unanswered
             and not q.check(answers[q.id])[0]]  # fmt: skip
    total = len(exercise.questions)
    evidence = {"correct": total - len(unanswered) - len(wrong), "of": total}
    if unanswered:
        return Check(False, f"not answered yet: {', '.join(unanswered)}", evidence)
    if wrong:
        return Check(False, f"{len(wrong)} of {total} not right yet: {', '.join(wrong)}", evidence)
    return Check(True, f"all {total} answered correctly", evidence)


def check_objective(
    obj: Objective,
    exercise: Exercise,
    station: LabStation,
    answers: Mapping[str, str] | None = None,
) -> Check:
    by_kind: dict[str, Callable[[], Check]] = {
        "keys": lambda: check_keys(obj, station),
        "sensors": lambda: check_sensors(obj, station),
        "viple": lambda: check_viple(obj, station),
        "exit": lambda: check_exit(obj, exercise, station),
        "maze-edited": lambda: check_maze_edited(exercise, station),
        "compare": lambda: check_compare(obj, exercise, station),
        "questions": lambda: check_questions(exercise, answers or {}),
    }
    return by_kind[obj.kind]()


def evaluate(
    lab_id: str, exercise: Exercise, station: LabStation, answers: Mapping[str, str] | None = None
) -> ExerciseProgress:
    """Every objective of ``exercise`` checked against the station now."""
    states = []
    for obj in exercise.objectives:
        check = check_objective(obj, exercise, station, answers)
        states.append(
            ObjectiveState(obj.kind, obj.text, check.passed, check.reason, check.evidence)
        )
    return ExerciseProgress(lab_id, exercise.id, states, dict(answers or {}))
