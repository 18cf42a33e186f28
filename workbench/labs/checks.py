"""The automatic checks of a lab exercise, read from the live station and its runs.

Each objective gives a :class:`Check`: passed or not, a one-line reason the app shows next to
✓ or ✗, and the evidence a sign-off keeps (the run, its metrics and its record's digest).

An objective looks only at the exercise's own work: what was done on the station during the
exercise's latest attempt (begun by its set-up, :func:`apply_setup`). Runs, edits, drive keys
and VIPLE programs carry the id of the attempt under way when they happened; work of another
exercise, or from before the set-up, meets nothing. Every pass names its attempt in its
evidence (:data:`ATTEMPT`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from workbench.control.fsm_behaviour import Trial
from workbench.control.manual import KEY_NAMES
from workbench.control.station import UNDER_WAY, Attempt, LabStation, RunEntry
from workbench.fsm.algorithms import ALGORITHM_DIR
from workbench.sim.profiles import get_profile
from workbench.sim.record import file_sha256
from workbench.sim.sensors import SensorSpec

from .behaviour import BehaviourJudge, Task
from .model import Exercise, LabMaze, Objective, Setup
from .store.migrations import REDO_REASON

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
    #: it passed in a workbench that did not keep the work's evidence: it must be done again
    redo: bool = False


#: the evidence key naming the attempt whose work an objective passed on
ATTEMPT = "attempt"
#: the reason shown for a pass kept without its evidence
REDO = REDO_REASON


#: what a pass of these kinds keeps since it rests on the student's own run or hand edit: a
#: pass saved without it was judged by the rules before (the set-up's sensors, a shipped
#: program, Generate) and needs redoing
OWN_WORK_KEYS = {
    "sensors": "run",
    "exit": "sensors",
    "maze-edited": "hand_blocks",
    "fsm-behaviour": "compared",
}


def proven(state: ObjectiveState) -> bool:
    """Whether a passed objective rests on evidence of its exercise's own work (the
    questions rest on the answers kept with the exercise)."""
    if state.kind == "questions":
        return True
    key = OWN_WORK_KEYS.get(state.kind)
    return bool(state.evidence.get(ATTEMPT)) and (key is None or key in state.evidence)


def unproven_to_redo(state: ObjectiveState) -> ObjectiveState:
    """A pass saved without the evidence of its work, as one that needs redoing."""
    if state.passed and not proven(state):
        return ObjectiveState(state.kind, state.text, False, REDO, {}, redo=True)
    return state


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
    #: how many answers each question has been given (every try, right or wrong)
    tries: dict[str, int] = field(default_factory=dict)
    #: questions whose answers, as read back, were longer than is kept and were cut
    cut: tuple[str, ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        self.answers, cut = capped_answers(self.answers)
        self.cut = (*self.cut, *cut)
        self.tries = dict(list(self.tries.items())[:MAX_ANSWERS])

    @property
    def passed(self) -> bool:
        return all(o.passed for o in self.objectives)

    def to_json(self) -> str:
        return json.dumps(self.as_dict(), sort_keys=True)

    def as_dict(self) -> dict[str, Any]:
        """The progress as saved: every objective's state and evidence, the answers, and
        whether all objectives pass."""
        data = {k: v for k, v in asdict(self).items() if k != "cut"}
        return json.loads(json.dumps({**data, "passed": self.passed}))

    @classmethod
    def from_json(cls, text: str) -> ExerciseProgress:
        return cls.from_dict(json.loads(text))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ExerciseProgress:
        """Progress as saved (:meth:`to_json`); ValueError when it is not in that shape."""
        try:
            states = [ObjectiveState(**o) for o in data["objectives"]]
            if not all(isinstance(o.evidence, dict) for o in states):
                raise ValueError("an objective's evidence is not a mapping")
            objectives = [unproven_to_redo(o) for o in states]
            answers = dict(data.get("answers") or {})
            tries = {str(k): max(0, int(v)) for k, v in dict(data.get("tries") or {}).items()}
            return cls(str(data["lab"]), str(data["exercise"]), objectives, answers, tries)
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
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
    no longer shows the run that passed, but the saved progress does. Only a pass that rests
    on the evidence of its exercise's own work is kept; one saved without it stays "needs
    redoing" until the work is done again. Objectives are matched by kind and text, so a
    changed lab file does not carry over a different objective. The questions follow the
    answers as they stand (those are saved and shown again).
    """
    if saved is None:
        return live
    earlier = {(o.kind, o.text): o for o in saved.objectives if o.kind != "questions"}
    objectives = []
    for o in live.objectives:
        before = earlier.get((o.kind, o.text))
        if o.passed or before is None or not (before.passed or before.redo):
            objectives.append(o)
        elif before.redo or not proven(before):
            objectives.append(ObjectiveState(o.kind, o.text, False, REDO, {}, redo=True))
        else:
            reason = before.reason if before.reason.startswith(KEPT) else KEPT + before.reason
            objectives.append(ObjectiveState(o.kind, o.text, True, reason, before.evidence))
    return ExerciseProgress(live.lab, live.exercise, objectives, live.answers, live.tries)


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


def apply_setup(station: LabStation, setup: Setup, *, lab: str, exercise: str) -> SetupChanges:
    """The one-key set-up of exercise ``exercise`` of ``lab``: profile, maze, sensors, speed
    and the controller to use (the maze and starter as they were when the lab was loaded),
    and nothing kept from before: an exercise without an algorithm has none, and the
    parameters are the algorithm's own values for the profile. It begins the exercise's
    attempt: only the work done from here on counts for it. Returns what changed beyond the
    profile, maze and sensors."""
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
    station.set_speed(setup.speed)  # held at 1x while a live VIPLE program drives
    station.pause(False)
    station.begin_attempt(lab, exercise)
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


def sensor_texts(sensors: Iterable[SensorSpec]) -> list[str]:
    """Sensors as evidence keeps them: their text (``distance:1:right``), sorted."""
    return sorted(str(s) for s in sensors)


def run_evidence(run: RunEntry) -> dict[str, Any]:
    """What a pass on ``run`` keeps: the run, who drove it and what with (the sensors it
    carried, the file that drove and its digest), its maze, metrics and record. A run still
    under way keeps no record (its file is still growing)."""
    digest = run.program_sha256 or run.driver.digest
    program = {"program_sha256": digest} if digest else {}
    if run.program_name:
        program["program_name"] = run.program_name
    if run.bundled:  # a built-in a lab asked for (compare, "algorithm NAME"): not a copy hint
        program["bundled"] = run.bundled
    under_way = run.ended == UNDER_WAY
    return {
        ATTEMPT: run.attempt,
        "run": run.number,
        "driver": str(run.driver),
        "person": run.person,
        **program,
        "sensors": sensor_texts(run.sensors),
        "maze": run.maze,
        "maze_digest": run.maze_digest,
        "profile": run.profile,
        "ended": run.ended,
        "metrics": run.metrics.as_dict(),
        "record": None if under_way else run.record,
        "record_sha256": None if under_way else record_digest(run.record),
    }


#: the drivers that stand for the student's own program ("your program" objectives)
OWN_PROGRAM_DRIVERS = frozenset({"viple", "program", "fsm"})


def driver_kinds(run: RunEntry) -> set[str]:
    """What kinds of driver an ``exit`` objective would see in ``run``. A program or FSM
    that is one the workbench ships (:attr:`RunEntry.bundled`) is none of the student's
    kinds (viple, program, fsm)."""
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
    if run.bundled:
        kinds -= OWN_PROGRAM_DRIVERS
    return kinds


# -- the exercise's own work ---------------------------------------------------------------
NOT_SET_UP = "not set up yet: press a to set this exercise up, then do the work"


def attempt_of(station: LabStation, lab: str, exercise: Exercise) -> Attempt | None:
    """The latest attempt of the exercise on the station (None: it was never set up here)."""
    for attempt in reversed(station.attempts):
        if (attempt.lab, attempt.exercise) == (lab, exercise.id):
            return attempt
    return None


def _runs(station: LabStation, attempt: Attempt) -> list[RunEntry]:
    return [r for r in station.runs if r.attempt == attempt.id]


# -- the objective kinds -------------------------------------------------------------------
def check_keys(obj: Objective, station: LabStation, attempt: Attempt) -> Check:
    """The drive keys pressed on the exercise's profile during its attempt, or (with ``role``)
    the same motions asked for by a VIPLE program over that role during the attempt: its own
    key bindings turned into commands."""
    uses = [u for u in station.key_uses if u.attempt == attempt.id and u.profile == attempt.profile]
    pressed = {u.key for u in uses}
    missing = [k for k in obj.keys if k not in pressed]
    evidence: dict[str, Any] = {
        ATTEMPT: attempt.id,
        "profile": attempt.profile,
        "keys_used": sorted(pressed),
        "people": sorted({u.person for u in uses if u.key in obj.keys} - {""}),
    }
    if not missing:
        return Check(True, f"used {', '.join(obj.keys)}", evidence)
    mine = [c for c in station.viple if c.attempt == attempt.id]
    if obj.role:
        wanted = [KEY_NAMES[k] for k in obj.keys]
        for c in reversed([c for c in mine if c.role == obj.role]):
            if all(m in c.motions for m in wanted):
                evidence = {ATTEMPT: attempt.id, "role": c.role, "peer": c.peer,
                            "motions": sorted(c.motions), "person": c.person}  # fmt: skip
                reason = f"VIPLE {c.role} program asked for {', '.join(wanted)}"
                return Check(True, reason, evidence)
        motions = set().union(*(c.motions for c in mine if c.role == obj.role))
        if motions:
            lacking = [m for m in wanted if m not in motions]
            return Check(False, f"VIPLE has not asked for {', '.join(lacking)} yet", {})
    return Check(False, f"not used yet: {', '.join(missing)}", {})


def _sensor_difference(have: set[str], want: set[str]) -> str:
    parts = []
    if want - have:
        parts.append(f"missing {', '.join(sorted(want - have))}")
    if have - want:
        parts.append(f"not wanted {', '.join(sorted(have - want))}")
    return "; ".join(parts)


def attempt_runs(station: LabStation, attempt: Attempt) -> list[RunEntry]:
    """The attempt's runs, oldest first, with the run under way (as it stands) last."""
    runs = _runs(station, attempt)
    now = station.run_so_far()
    if now is not None and now.attempt == attempt.id:
        runs.append(now)
    return runs


def check_sensors(
    obj: Objective, exercise: Exercise, station: LabStation, attempt: Attempt
) -> Check:
    """A run of the attempt, on the exercise's profile, in which the robot moved carrying
    exactly these sensors (the run under way counts as it stands), driven by the student: the
    keys, VIPLE, or a program or FSM of their own. Fitting the sensors is not enough: the
    set-up fits them; the work is a run with them."""
    want = set(sensor_texts(obj.sensors))
    moved = [
        r for r in attempt_runs(station, attempt)
        if r.moved and r.profile == exercise.setup.profile
    ]  # fmt: skip
    with_them = [r for r in moved if set(sensor_texts(r.sensors)) == want]
    shipped = [r for r in with_them if r.bundled]
    with_them = [r for r in with_them if not r.bundled]
    if not with_them and shipped:
        last = shipped[-1]
        return Check(
            False,
            f"run {last.number} was driven by {last.bundled}, which comes with the workbench: "
            "drive a run with these sensors yourself (keys, VIPLE or your own program)",
        )
    if with_them:
        run = with_them[-1]
        evidence = run_evidence(run)
        reason = f"run {run.number} ({run.driver}) carried {', '.join(sorted(want)) or 'none'}"
        return Check(True, reason, evidence)
    have = set(sensor_texts(station.sensors))
    if have != want:
        return Check(
            False,
            f"{_sensor_difference(have, want)}: fit them (sensor panel, o), then drive a run",
        )
    if moved:
        last = moved[-1]
        differs = _sensor_difference(set(sensor_texts(last.sensors)), want)
        return Check(
            False,
            f"run {last.number} carried other sensors ({differs}): they changed during it; "
            "reset the robot (r on the maze) and drive a run with only these",
        )
    return Check(False, "the robot carries them: now drive it (keys, x or VIPLE) for a run")


def check_viple(obj: Objective, station: LabStation, attempt: Attempt) -> Check:
    seen = [c for c in station.viple if c.attempt == attempt.id]
    mine = [c for c in seen if c.role == obj.role]
    drove = [c for c in mine if c.drove]
    if drove:
        c = drove[-1]
        evidence = {ATTEMPT: attempt.id, "role": c.role, "peer": c.peer, "person": c.person,
                    "distance": round(c.distance, 4),
                    "turn_degrees": round(c.turn_degrees, 4)}  # fmt: skip
        return Check(True, f"VIPLE {c.role} program at {c.peer} drove the robot", evidence)
    if mine:
        return Check(False, f"VIPLE {obj.role} program connected but has not moved the robot")
    others = sorted({c.role for c in seen})
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


def _exits(station: LabStation, attempt: Attempt, maze: LabMaze, profile: str) -> list[RunEntry]:
    """Runs of the attempt that reached the exit of exactly the lab's ``maze`` (same layout)
    on ``profile``."""
    return [
        r
        for r in _runs(station, attempt)
        if r.ended == "exit" and r.maze_digest == maze.digest and r.profile == profile
    ]


def _not_the_lab_maze(
    station: LabStation, attempt: Attempt, maze: LabMaze, profile: str
) -> RunEntry | None:
    """The attempt's last run that got out of a maze of the same name as the lab's but not its
    layout."""
    others = [
        r
        for r in _runs(station, attempt)
        if r.ended == "exit" and r.maze == maze.name and r.profile == profile
        and r.maze_digest != maze.digest
    ]  # fmt: skip
    return others[-1] if others else None


def check_exit(obj: Objective, exercise: Exercise, station: LabStation, attempt: Attempt) -> Check:
    assert obj.maze is not None
    maze = obj.maze
    profile = exercise.setup.profile
    wanted = set(obj.drivers)
    exits = _exits(station, attempt, maze, profile)
    by_them = [r for r in exits if driver_kinds(r) & wanted]
    want = set(sensor_texts(obj.run_sensors or ()))
    runs = by_them
    if obj.run_sensors is not None:
        runs = [r for r in by_them if set(sensor_texts(r.sensors)) == want]
    drivers = " or ".join(obj.drivers)
    if not runs and by_them:
        last = by_them[-1]
        return Check(
            False,
            f"run {last.number} ({last.driver}) got out carrying "
            f"{', '.join(sensor_texts(last.sensors)) or 'no sensors'}; this exercise's robot "
            f"carries {', '.join(sorted(want)) or 'none'}: fit them (o) and run again",
        )
    shipped = [r for r in exits if r.bundled and wanted & OWN_PROGRAM_DRIVERS]
    if not runs and shipped:
        last = shipped[-1]
        return Check(
            False,
            f"run {last.number} ({last.driver}) is {last.bundled}, which comes with the "
            "workbench, not your own program: complete it or write yours, and run that",
        )
    if not runs:
        other = _not_the_lab_maze(station, attempt, maze, profile)
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


def check_maze_edited(exercise: Exercise, station: LabStation, attempt: Attempt) -> Check:
    """An edit made in the editor during the attempt, with blocks added or removed by hand,
    that left a valid maze other than the set-up maze (loading a maze is not editing, and
    what Generate or New made is not done by hand)."""
    original = exercise.setup.maze.maze
    edits = [
        e for e in station.edits if e.attempt == attempt.id and e.maze_digest != e.opened_digest
    ]
    changed = [e for e in edits if e.maze_digest != original.digest()]
    good = [e for e in changed if e.hand_blocks > 0 and e.valid]
    if good:
        e = good[-1]
        evidence = {ATTEMPT: attempt.id, "edit": e.number, "maze": e.maze, "person": e.person,
                    "maze_digest": e.maze_digest, "original_digest": original.digest(),
                    "hand_blocks": e.hand_blocks}  # fmt: skip
        blocks = f"{e.hand_blocks} block{'s' if e.hand_blocks != 1 else ''}"
        return Check(True, f"edit {e.number} changed {blocks} by hand, {e.maze!r}", evidence)
    if changed and changed[-1].hand_blocks == 0:
        return Check(
            False,
            f"edit {changed[-1].number} added or removed no block by hand (Generate, New and "
            "loading do not count): in the editor (e) put or take away a block yourself",
        )
    if changed:
        return Check(False, "the edited maze has problems: fix them in the editor (e)")
    if edits:
        return Check(False, f"the edits left {original.name!r} as set up: add or remove a block")
    return Check(
        False, "the maze has not been edited yet: open the editor (e), add or remove a block"
    )


def check_compare(
    obj: Objective, exercise: Exercise, station: LabStation, attempt: Attempt
) -> Check:
    table: list[dict[str, Any]] = []
    missing = []
    for maze in obj.mazes:
        for name in obj.algorithms:
            runs = [
                r
                for r in _exits(station, attempt, maze, exercise.setup.profile)
                if f"algorithm {name}" in driver_kinds(r)
            ]
            if runs:
                table.append({"algorithm": name, **run_evidence(runs[-1])})
            else:
                missing.append(f"{name} on {maze.name!r} ({exercise.setup.profile})")
    if missing:
        more = f" (+{len(missing) - 1} more)" if len(missing) > 1 else ""
        return Check(False, f"no run to the exit yet: {missing[0]}{more}", {"runs": table})
    return Check(True, f"{len(table)} runs to compare", {ATTEMPT: attempt.id, "runs": table})


#: what an ``fsm-behaviour`` objective says while its comparison is under way
COMPARING = "comparing"


def check_fsm_behaviour(
    obj: Objective,
    exercise: Exercise,
    station: LabStation,
    attempt: Attempt,
    judge: BehaviourJudge | None,
) -> Check:
    """The student's own FSM file, as their latest run of the attempt ran it, behaves as the
    reference on the objective's mazes and seeds: the same moves and turns at the same
    times (see :mod:`workbench.control.fsm_behaviour`). A shipped FSM, even renamed, is not
    the student's; the comparison runs on the judge's thread and the check says so meanwhile."""
    assert obj.reference is not None
    profile = exercise.setup.profile
    reference = obj.reference.name
    runs = [r for r in attempt_runs(station, attempt) if r.profile == profile and r.source
            and r.driver.kind == "algorithm"]  # fmt: skip
    own = [r for r in runs if "fsm" in driver_kinds(r)]
    if not own:
        shipped = [r for r in runs if r.bundled]
        if shipped:
            last = shipped[-1]
            return Check(False, f"run {last.number} was {last.bundled}, which comes with the "
                         "workbench: write your own machine (F) and run it (ctrl+r)")  # fmt: skip
        return Check(False, f"write your own machine in the FSM editor (F) and run it (ctrl+r): "
                     f"it is then compared with {reference}")  # fmt: skip
    run = own[-1]
    if judge is None:
        return Check(False, "judged in the app: open the exercise there")
    sensors = tuple(str(s) for s in (exercise.setup.sensors or get_profile(profile).sensors))
    trials = tuple(
        Trial(str(maze.path), maze.name, seed) for maze in obj.mazes for seed in range(obj.seeds)
    )
    task = Task(run.source or "", run.program_sha256, obj.reference, trials, profile, sensors,
                obj.max_time)  # fmt: skip
    judged = judge.judged(task)
    if judged is None:
        return Check(False, f"{COMPARING} run {run.number}'s machine with {reference}...")
    if judged.problem:
        return Check(False, f"run {run.number}: {judged.problem}")
    verdict = judged.verdict
    assert verdict is not None
    if verdict.problem:
        return Check(False, verdict.problem)
    if not verdict.same:
        assert verdict.difference is not None
        unit = get_profile(profile).unit
        return Check(False, f"run {run.number}'s machine differs from {reference}: "
                     f"{verdict.difference.words(unit)}")  # fmt: skip
    evidence = {
        **run_evidence(run),
        "reference": reference,
        "compared": verdict.commands,
        "trials": [{"maze": t.shown, "seed": t.seed} for t in trials],
    }
    return Check(
        True,
        f"run {run.number}'s machine did as {reference} did: {verdict.commands} moves and "
        f"turns alike on {len(trials)} run{'s' * (len(trials) != 1)}",
        evidence,
    )


def waiting_questions(
    exercise: Exercise, answers: Mapping[str, str], tries: Mapping[str, int]
) -> list[str]:
    """The questions whose tries are used up without a right answer: they wait for the
    instructor (the student's answer box takes no more answers)."""
    return [
        q.id
        for q in exercise.questions
        if q.max_tries is not None
        and tries.get(q.id, 0) >= q.max_tries
        and not q.check(str(answers.get(q.id, "")))[0]
    ]


def check_questions(
    exercise: Exercise, answers: Mapping[str, str], tries: Mapping[str, int] | None = None
) -> Check:
    answers, _ = capped_answers(answers)
    tries = tries or {}
    unanswered = [q.id for q in exercise.questions if not str(answers.get(q.id, "")).strip()]
    wrong = [q.id for q in exercise.questions if q.id not in unanswered
             and not q.check(answers[q.id])[0]]  # fmt: skip
    total = len(exercise.questions)
    waiting = waiting_questions(exercise, answers, tries)
    evidence = {
        "correct": total - len(unanswered) - len(wrong),
        "of": total,
        "tries": {q.id: int(tries.get(q.id, 0)) for q in exercise.questions},
        "waiting": waiting,
    }
    if waiting:
        return Check(
            False,
            f"no tries left, waiting for the instructor: {', '.join(waiting)}",
            evidence,
        )
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
    attempt: Attempt | None = None,
    tries: Mapping[str, int] | None = None,
    judge: BehaviourJudge | None = None,
) -> Check:
    """``obj`` checked against the work of ``attempt`` (the exercise's latest attempt on the
    station), and the answers given in the exercise (with how often each was tried);
    ``judge`` compares machines for ``fsm-behaviour``."""
    if obj.kind == "questions":
        return check_questions(exercise, answers or {}, tries)
    if attempt is None:
        return Check(False, NOT_SET_UP)
    by_kind: dict[str, Callable[[Attempt], Check]] = {
        "keys": lambda a: check_keys(obj, station, a),
        "sensors": lambda a: check_sensors(obj, exercise, station, a),
        "viple": lambda a: check_viple(obj, station, a),
        "exit": lambda a: check_exit(obj, exercise, station, a),
        "maze-edited": lambda a: check_maze_edited(exercise, station, a),
        "compare": lambda a: check_compare(obj, exercise, station, a),
        "fsm-behaviour": lambda a: check_fsm_behaviour(obj, exercise, station, a, judge),
    }
    return by_kind[obj.kind](attempt)


def evaluate(
    lab_id: str,
    exercise: Exercise,
    station: LabStation,
    answers: Mapping[str, str] | None = None,
    tries: Mapping[str, int] | None = None,
    judge: BehaviourJudge | None = None,
) -> ExerciseProgress:
    """Every objective of ``exercise`` checked against its own work on the station now: the
    work of its latest attempt, and its answers (``tries``: how many times each question was
    answered; ``judge``: compares machines for ``fsm-behaviour``)."""
    attempt = attempt_of(station, lab_id, exercise)
    states = []
    for obj in exercise.objectives:
        check = check_objective(obj, exercise, station, answers, attempt, tries, judge)
        states.append(
            ObjectiveState(obj.kind, obj.text, check.passed, check.reason, check.evidence)
        )
    return ExerciseProgress(lab_id, exercise.id, states, dict(answers or {}), dict(tries or {}))
