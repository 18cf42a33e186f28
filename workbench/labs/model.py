"""Guided labs: the exercises of ``labs/*.yaml``, read with line numbers for clear errors.

The file format is described in ``docs/labs.md``. Every problem names the file, the line and
the key, and says what to write instead.
"""

from __future__ import annotations

import hashlib
import math
import secrets
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from decimal import Decimal
from pathlib import Path
from typing import Any

import yaml

from workbench.control.manual import DRIVE_KEYS
from workbench.files.bounded import LAB_LIMITS, BoundedFileError, compose_yaml, read_text
from workbench.files.problems import Problem
from workbench.files.yamlread import (
    NodeReader,
    Skip,
    file_problem,
    problem_list,
    refused_problem,
    syntax_problem,
)
from workbench.fsm.algorithms import list_algorithms, load_algorithm
from workbench.fsm.definition import FsmDefinition
from workbench.fsm.yaml_file import FsmFileError, load_fsm
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.profiles import PROFILES
from workbench.sim.sensors import SensorConfigError, SensorSpec, check_ports

#: the folder of the bundled labs (next to ``mazes/``)
LABS_DIR = Path(__file__).resolve().parents[2] / "labs"
OBJECTIVE_KINDS = (
    "keys",
    "sensors",
    "viple",
    "exit",
    "maze-edited",
    "compare",
    "questions",
    "fsm-behaviour",
)
CONTROLLER_KINDS = ("keys", "algorithm", "starter", "viple")
#: the speeds a set-up may ask for (the app's speed key steps through the same)
SETUP_SPEEDS: dict[str, float | None] = {"1": 1.0, "2": 2.0, "4": 4.0, "10": 10.0, "max": None}
#: what an ``exit`` objective may require of the driver
DRIVER_KINDS = ("viple", "program", "fsm", "algorithm", "any")
VIPLE_ROLES = ("tcp", "ws")


class LabFileError(ValueError):
    """A lab file that cannot be used; ``problems`` lists every problem found, each as
    ``file:line:column: where: what (hint: fix)``."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problem_list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


# -- answers --------------------------------------------------------------------------------
#: past this a number is no lab's answer (and rounding it to a step would overflow)
LARGEST_ANSWER = 1e15


def normalise_choice(text: str) -> str:
    return " ".join(str(text).split()).casefold()


def _digest(salt: str, text: str) -> str:
    return hashlib.sha256(f"{salt}\n{text}".encode()).hexdigest()


def _grid_text(value: float, step: str) -> str:
    """``value`` rounded to the nearest multiple of ``step``, written with step's decimals."""
    quantum = Decimal(step)
    k = round(Decimal(repr(float(value))) / quantum)
    return str((k * quantum).quantize(quantum.normalize() if quantum < 1 else Decimal(1)))


def hash_answer(
    answer: str | float,
    salt: str | None = None,
    tolerance: float | None = None,
    step: str | None = None,
) -> dict[str, Any]:
    """The ``answer:`` mapping a lab file stores for a question (for authors of labs).

    A choice answer stores the hash of its normalised text. A numeric answer stores the
    rounding ``step`` and one hash per multiple of ``step`` within ``tolerance`` of the answer;
    a student's number is rounded to the step and its hash looked up.
    """
    salt = salt or secrets.token_hex(8)
    if tolerance is None:
        return {"salt": salt, "sha256": [_digest(salt, normalise_choice(str(answer)))]}
    if step is None or Decimal(step) <= 0:
        raise ValueError("a numeric answer needs a positive rounding step, e.g. step='0.1'")
    quantum = float(Decimal(step))
    low = math.ceil((float(answer) - tolerance) / quantum - 1e-9)
    high = math.floor((float(answer) + tolerance) / quantum + 1e-9)
    if high - low > 1000:
        raise ValueError("tolerance / step accepts more than 1000 values: use a coarser step")
    texts = {_grid_text(k * quantum, step) for k in range(low, high + 1)}
    return {"salt": salt, "step": step, "sha256": sorted(_digest(salt, t) for t in texts)}


#: the values a question may also accept as the workbench shows them (``shown:`` in a lab
#: file), each with what the reason says of it: over SSH a student's workbench listens on a
#: port of its own, and that is the port its screen shows
SHOWN = {"viple-tcp-port": "the TCP port your workbench shows VIPLE's robot listening on"}


@dataclass(frozen=True)
class Question:
    id: str
    text: str
    salt: str
    hashes: frozenset[str]
    choices: tuple[str, ...] = ()
    #: the rounding step of a numeric answer ("0.1"); None for multiple choice
    step: str | None = None
    unit: str = ""
    #: how many answers the student may try (None: as many as they like); once they are
    #: used up, a question not answered right waits for the instructor
    max_tries: int | None = None
    #: a value the workbench shows that also counts as the answer (one of :data:`SHOWN`;
    #: "" none), and what it shows now (bound by :meth:`Exercise.with_shown`)
    shown: str = ""
    shown_now: frozenset[str] = frozenset()

    @property
    def numeric(self) -> bool:
        return self.step is not None

    def check(self, answer: str) -> tuple[bool, str]:
        """(correct, reason); a malformed answer is not correct and the reason says why."""
        if self.numeric:
            try:
                value = float(str(answer).strip())
            except ValueError:
                return False, f"{answer!r} is not a number"
            if not math.isfinite(value):
                return False, f"{answer!r} is not a number"
            if abs(value) > LARGEST_ANSWER:
                return False, f"{answer[:20]!r}... is far larger than any answer here"
            text = _grid_text(value, self.step or "1")
            if text in self.shown_now:
                return True, f"correct: {SHOWN[self.shown]}"
        else:
            text = normalise_choice(answer)
            if self.choices and text not in {normalise_choice(c) for c in self.choices}:
                return False, f"{answer!r} is not one of the choices"
        if _digest(self.salt, text) in self.hashes:
            return True, "correct"
        return False, "not the expected answer"


# -- set-up, objectives, exercises ---------------------------------------------------------
@dataclass(frozen=True)
class LabMaze:
    """A maze a lab rests on, as it was read when the lab was loaded.

    The lab's checks compare runs with this layout (by :meth:`Maze.digest`), never with the
    file as it is later: an edited copy, or the file changed on disk after loading, is another
    maze and meets no objective on this one.
    """

    path: Path
    maze: Maze

    @classmethod
    def read(cls, path: Path) -> LabMaze:
        """The maze at ``path`` as it is now (:class:`MazeError` when it cannot be read)."""
        return cls(path, load_maze(path))

    @property
    def digest(self) -> str:
        return self.maze.digest()

    @property
    def name(self) -> str:
        return self.maze.name


@dataclass(frozen=True)
class Controller:
    """Who drives in the set-up: keys, a built-in algorithm, a starter FSM, or VIPLE."""

    kind: str
    #: algorithm name, starter file path, or VIPLE role (tcp / ws)
    value: str = ""
    #: a starter as it was read when the lab was loaded (the set-up uses this, not the file)
    starter: FsmDefinition | None = field(default=None, compare=False)

    def __str__(self) -> str:
        """The controller in words: a starter by its file's name (where the lab's files are
        kept is no concern of a student's)."""
        value = Path(self.value).name if self.kind == "starter" else self.value
        return f"{self.kind} {value}".strip()


@dataclass(frozen=True)
class Setup:
    profile: str
    maze: LabMaze
    sensors: tuple[SensorSpec, ...]
    controller: Controller
    #: the simulation speed the exercise runs at (None: as fast as it goes)
    speed: float | None = 1.0


@dataclass(frozen=True)
class Objective:
    kind: str
    text: str
    keys: tuple[str, ...] = ()
    sensors: tuple[SensorSpec, ...] = ()
    role: str = ""
    maze: LabMaze | None = None
    #: accepted drivers for ``exit``: "viple", "program", "fsm", "algorithm NAME", "any"
    drivers: tuple[str, ...] = ()
    max_time: float | None = None
    max_turn_degrees: float | None = None
    max_collisions: int | None = None
    algorithms: tuple[str, ...] = ()
    mazes: tuple[LabMaze, ...] = ()
    #: ``exit``: the sensors its run must have carried, no more and no fewer (its own
    #: ``sensors:``, else the exercise's ``sensors`` objective's, else the set-up's; None:
    #: any, when the exercise names none)
    run_sensors: tuple[SensorSpec, ...] | None = None
    #: ``fsm-behaviour``: the built-in machine the student's must behave as (as read when the
    #: lab was loaded), on ``mazes`` with seeds 0..seeds-1
    reference: FsmDefinition | None = field(default=None, compare=False)
    seeds: int = 1


@dataclass(frozen=True)
class Grading:
    """What ``workbench grade`` runs each student's program on for an exercise."""

    mazes: tuple[LabMaze, ...]
    #: seeds 0..seeds-1 on every maze
    seeds: int = 1
    #: simulated seconds per run (None: from the maze's size)
    max_time: float | None = None


@dataclass(frozen=True)
class Exercise:
    id: str
    title: str
    instructions: str
    setup: Setup
    objectives: tuple[Objective, ...]
    questions: tuple[Question, ...] = ()
    signoff: bool = True
    #: the exercise's ``grading:`` (None: the defaults, see :attr:`graded`)
    grading: Grading | None = None

    def with_shown(self, values: Mapping[str, str]) -> Exercise:
        """The exercise with each question that accepts a shown value (``shown:``) also
        accepting what the workbench shows now (``values``: :data:`SHOWN` key -> text)."""
        questions = tuple(
            replace(q, shown_now=frozenset({_grid_text(float(values[q.shown]), q.step)}))
            if q.shown and q.step is not None and values.get(q.shown)
            else q
            for q in self.questions
        )
        return self if questions == self.questions else replace(self, questions=questions)

    @property
    def graded(self) -> Grading:
        """How the exercise is graded: its ``grading:``, else the set-up's maze and every
        ``exit`` objective's maze, once each, with seed 0."""
        if self.grading is not None:
            return self.grading
        mazes = [self.setup.maze]
        for objective in self.objectives:
            if objective.kind == "exit" and objective.maze is not None:
                mazes.append(objective.maze)
        unique = {m.path: m for m in mazes}
        return Grading(tuple(unique.values()))


@dataclass(frozen=True)
class Lab:
    id: str
    title: str
    summary: str
    exercises: tuple[Exercise, ...]
    path: Path = field(compare=False, default=Path("."))

    def exercise(self, exercise_id: str) -> Exercise:
        for ex in self.exercises:
            if ex.id == exercise_id:
                return ex
        known = ", ".join(e.id for e in self.exercises)
        raise KeyError(f"lab {self.id!r} has no exercise {exercise_id!r} (it has: {known})")


# -- reading -------------------------------------------------------------------------------
class _Reader(NodeReader):
    def __init__(self, path: Path, label: str):
        super().__init__(label)
        self.path = path
        self.base = path.parent
        self.mazes: dict[Path, LabMaze] = {}

    def file(self, node: yaml.Node, where: str) -> Path:
        path = (self.base / self.text(node, where)).resolve()
        if not path.is_file():
            self.fail(
                node, where, f"no file {node.value!r}", f"paths are relative to {self.base.name}/"
            )
        return path

    def maze(self, node: yaml.Node, where: str) -> LabMaze:
        """The maze file ``node`` names, read now (once per lab file) and kept as read."""
        path = self.file(node, where)
        if path not in self.mazes:
            try:
                self.mazes[path] = LabMaze.read(path)
            except MazeError as exc:
                first = exc.problems[0]
                at = f"line {first.line}: " if first.line else ""
                self.fail(node, where, f"maze {node.value!r} cannot be read: {at}{first.message}",
                          "see every problem with 'workbench maze check FILE'")  # fmt: skip
        return self.mazes[path]

    def sensors(self, node: yaml.Node, where: str) -> tuple[SensorSpec, ...]:
        if isinstance(node, yaml.SequenceNode) and not node.value:
            return ()
        specs = []
        for item in self.items(node, where):
            try:
                specs.append(SensorSpec.parse(self.text(item, where)))
            except SensorConfigError as exc:
                self.fail(item, where, str(exc))
        try:
            check_ports(specs)
        except SensorConfigError as exc:
            self.fail(node, where, str(exc))
        return tuple(specs)


def load_lab(path: str | Path) -> Lab:
    """Read and check one lab file; raises :class:`LabFileError` with every problem found,
    each naming its line and the fix."""
    path = Path(path)
    label = _label(path)
    try:
        root = compose_yaml(read_text(path, LAB_LIMITS, label), label, LAB_LIMITS)
    except BoundedFileError as exc:
        raise LabFileError([refused_problem(exc)]) from None
    except yaml.YAMLError as exc:
        raise LabFileError([syntax_problem(label, exc)]) from None
    if root is None:
        raise LabFileError(
            [file_problem(label, 1, 1, "empty file", "a lab needs 'lab', 'title' and 'exercises'")]
        )
    r = _Reader(path, label)
    try:
        lab = _lab(r, root, path)
    except Skip:
        lab = None
    r.check(LabFileError)
    assert lab is not None
    return lab


def _lab(r: _Reader, root: yaml.Node, path: Path) -> Lab:
    top = r.mapping(root, "", ("lab", "title", "exercises"), ("summary",))
    lab_id = r.text(top["lab"], "lab")
    if lab_id != path.stem:
        r.note(top["lab"], "lab", f"id {lab_id!r} differs from the file name", f"use {path.stem!r}")
    exercises: list[Exercise] = []
    read = r.each(r.items(top["exercises"], "exercises"), lambda node: (node, _exercise(r, node)))
    for node, ex in read:
        if any(e.id == ex.id for e in exercises):
            r.note(node, f"exercise {ex.id!r}", "id is used twice", "give each exercise its own id")
        exercises.append(ex)
    summary = r.text(top["summary"], "summary") if "summary" in top else ""
    return Lab(lab_id, r.text(top["title"], "title"), summary, tuple(exercises), path)


def load_labs(folder: str | Path = LABS_DIR) -> list[Lab]:
    """Every ``*.yaml`` lab in ``folder`` (starters live in a subfolder and are not labs)."""
    return [load_lab(p) for p in sorted(Path(folder).glob("*.yaml"))]


def _label(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def _exercise(r: _Reader, node: yaml.Node) -> Exercise:
    keys = r.mapping(
        node,
        "exercise",
        ("id", "title", "instructions", "setup", "objectives"),
        ("questions", "signoff", "grading", "max_tries"),
    )
    ex_id = r.text(keys["id"], "exercise")
    where = f"exercise {ex_id!r}"
    max_tries = _max_tries(r, keys["max_tries"], where) if "max_tries" in keys else None
    questions = (
        tuple(
            r.each(
                r.items(keys["questions"], f"{where}: questions"),
                lambda q: _question(r, q, where, max_tries),
            )
        )
        if "questions" in keys
        else ()
    )
    ids = [q.id for q in questions]
    if len(set(ids)) != len(ids):
        r.note(keys["questions"], where, "two questions share an id", "give each its own id")
    objectives = tuple(
        r.each(
            r.items(keys["objectives"], f"{where}: objectives"), lambda o: _objective(r, o, where)
        )
    )
    if any(o.kind == "questions" for o in objectives) and not questions:
        r.note(keys["objectives"], where, "a 'questions' objective but no questions", "add them")
    if "signoff" in keys and keys["signoff"].value != "required":
        r.note(keys["signoff"], where, "sign-off can only be 'required'", "write it so")
    setup = _setup(r, keys["setup"], where)
    return Exercise(
        ex_id,
        r.text(keys["title"], where),
        r.text(keys["instructions"], where),
        setup,
        _with_mazes(_with_run_sensors(objectives, setup), setup),
        questions,
        grading=_grading(r, keys["grading"], where) if "grading" in keys else None,
    )


#: the most tries a question may allow
MAX_TRIES = 100


def _max_tries(r: _Reader, node: yaml.Node, where: str) -> int:
    value = yaml.safe_load(yaml.serialize(node)) if isinstance(node, yaml.ScalarNode) else None
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= MAX_TRIES:
        shown = repr(node.value) if isinstance(node, yaml.ScalarNode) else "this"
        r.fail(
            node,
            f"{where}: max_tries",
            f"{shown} is not a whole number from 1 to {MAX_TRIES}",
            "write how many answers a student may try, e.g. 'max_tries: 3'",
        )
    return int(value)


def _with_mazes(objectives: tuple[Objective, ...], setup: Setup) -> tuple[Objective, ...]:
    """The exercise's ``fsm-behaviour`` objectives with the set-up's maze where they name
    none."""
    return tuple(
        replace(o, mazes=(setup.maze,)) if o.kind == "fsm-behaviour" and not o.mazes else o
        for o in objectives
    )


def _with_run_sensors(objectives: tuple[Objective, ...], setup: Setup) -> tuple[Objective, ...]:
    """The exercise's ``exit`` objectives with the sensors their runs must carry: their own,
    else those of the exercise's ``sensors`` objective, else the set-up's (when it names
    any)."""
    named = next((o.sensors for o in objectives if o.kind == "sensors"), None)
    if named is None and setup.sensors:
        named = setup.sensors
    return tuple(
        replace(o, run_sensors=named) if o.kind == "exit" and o.run_sensors is None else o
        for o in objectives
    )


#: the most seeds an exercise's grading may ask for
MAX_GRADING_SEEDS = 100


def _grading(r: _Reader, node: yaml.Node, where: str) -> Grading:
    here = f"{where}: grading"
    keys = r.mapping(node, here, ("mazes",), ("seeds", "max_time"))
    mazes = tuple(r.maze(n, here) for n in r.items(keys["mazes"], here))
    seeds = 1
    if "seeds" in keys:
        value = r.number(keys["seeds"], f"{here}: seeds", minimum=1)
        if value != int(value) or value > MAX_GRADING_SEEDS:
            r.fail(keys["seeds"], here, f"seeds must be a whole number from 1 to "
                   f"{MAX_GRADING_SEEDS}", "write e.g. 'seeds: 3'")  # fmt: skip
        seeds = int(value)
    max_time = None
    if "max_time" in keys:
        max_time = r.number(keys["max_time"], f"{here}: max_time")
        if not 0 < max_time <= 24 * 3600:
            r.fail(keys["max_time"], here, "max_time must be above 0 and at most a day",
                   "write simulated seconds, e.g. 'max_time: 300'")  # fmt: skip
    return Grading(mazes, seeds, max_time)


def _setup(r: _Reader, node: yaml.Node, where: str) -> Setup:
    here = f"{where}: setup"
    keys = r.mapping(node, here, ("profile", "maze", "controller"), ("sensors", "speed"))
    profile = r.choice(keys["profile"], here, tuple(PROFILES), "profile")
    sensors = r.sensors(keys["sensors"], here) if "sensors" in keys else ()
    speed: float | None = 1.0
    if "speed" in keys:
        speed = SETUP_SPEEDS[r.choice(keys["speed"], here, SETUP_SPEEDS, "speed")]
    maze = r.maze(keys["maze"], here)
    return Setup(profile, maze, sensors, _controller(r, keys, where), speed)


def _controller(r: _Reader, keys: dict[str, yaml.Node], where: str) -> Controller:
    node = keys["controller"]
    parts = r.text(node, f"{where}: controller").split(None, 1)
    kind = parts[0]
    value = parts[1].strip() if len(parts) > 1 else ""
    here = f"{where}: controller"
    if kind not in CONTROLLER_KINDS:
        r.fail(node, here, f"unknown controller {kind!r}", "use keys, algorithm NAME, "
               "starter FILE or viple tcp|ws")  # fmt: skip
    if kind == "keys" and value:
        r.fail(node, here, "'keys' takes nothing after it", "write just 'keys'")
    if kind == "algorithm" and value not in list_algorithms():
        r.fail(node, here, f"no built-in algorithm {value!r}",
               f"use one of {', '.join(list_algorithms())}")  # fmt: skip
    if kind == "starter":
        path = (r.base / value).resolve()
        if not value or not path.is_file():
            r.fail(node, here, f"no starter file {value!r}", "write 'starter starters/NAME.yaml'")
        try:
            starter = load_fsm(path)
        except FsmFileError as exc:
            r.fail(node, here, f"starter {value!r} cannot be read: {exc.problems[0].message}",
                   "see every problem with 'workbench algorithms FILE'")  # fmt: skip
        return Controller(kind, str(path), starter)
    if kind == "viple" and value not in VIPLE_ROLES:
        r.fail(node, here, f"unknown VIPLE role {value!r}", "use 'viple tcp' or 'viple ws'")
    return Controller(kind, value)


_OBJECTIVE_KEYS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "keys": ((), ("keys", "role")),
    "sensors": (("sensors",), ()),
    "viple": (("role",), ()),
    "exit": (
        ("maze", "driver"),
        ("max_time", "max_turn_degrees", "max_collisions", "sensors"),
    ),
    "maze-edited": ((), ()),
    "compare": (("algorithms", "mazes"), ()),
    "questions": ((), ()),
    "fsm-behaviour": (("reference",), ("mazes", "seeds", "max_time")),
}


def _objective(r: _Reader, node: yaml.Node, where: str) -> Objective:
    if not isinstance(node, yaml.MappingNode):
        r.fail(node, where, "an objective must be a mapping", "start it with 'kind: ...'")
    kind_node = next((v for k, v in node.value if k.value == "kind"), None)
    if kind_node is None:
        r.fail(node, where, "objective without 'kind'", f"use one of {', '.join(OBJECTIVE_KINDS)}")
    kind = r.choice(kind_node, where, OBJECTIVE_KINDS, "objective kind")
    required, optional = _OBJECTIVE_KEYS[kind]
    here = f"{where}: objective {kind!r}"
    keys = r.mapping(node, here, ("kind", "text", *required), optional)
    text = r.text(keys["text"], here)
    if kind == "keys":
        chosen = r.texts(keys["keys"], here) if "keys" in keys else DRIVE_KEYS
        for key in chosen:
            if key not in DRIVE_KEYS:
                r.fail(keys["keys"], here, f"{key!r} is not a drive key",
                       f"use {', '.join(DRIVE_KEYS)}")  # fmt: skip
        role = r.choice(keys["role"], here, VIPLE_ROLES, "role") if "role" in keys else ""
        return Objective(kind, text, keys=chosen, role=role)
    if kind == "sensors":
        return Objective(kind, text, sensors=r.sensors(keys["sensors"], here))
    if kind == "viple":
        return Objective(kind, text, role=r.choice(keys["role"], here, VIPLE_ROLES, "role"))
    if kind == "exit":
        drivers = r.texts(keys["driver"], here)
        for d in drivers:
            head, _, name = d.partition(" ")
            if head not in DRIVER_KINDS or (head == "algorithm") != bool(name):
                r.fail(keys["driver"], here, f"unknown driver {d!r}",
                       "use viple, program, fsm, algorithm NAME or any")  # fmt: skip
        # the optional keys of "exit" but sensors are Objective's limits: max_time, ...
        limits: dict[str, Any]
        limits = {
            k: r.number(keys[k], f"{here}: {k}") for k in optional if k in keys and k != "sensors"
        }
        if "max_collisions" in limits:
            limits["max_collisions"] = int(limits["max_collisions"])
        run_sensors = r.sensors(keys["sensors"], here) if "sensors" in keys else None
        maze = r.maze(keys["maze"], here)
        return Objective(kind, text, maze=maze, drivers=drivers, run_sensors=run_sensors, **limits)
    if kind == "compare":
        mazes = tuple(r.maze(n, here) for n in r.items(keys["mazes"], here))
        return Objective(kind, text, algorithms=r.texts(keys["algorithms"], here), mazes=mazes)
    if kind == "fsm-behaviour":
        return _behaviour(r, keys, kind, text, here)
    return Objective(kind, text)


#: the most simulated seconds one run of an ``fsm-behaviour`` comparison may take
MAX_BEHAVIOUR_TIME = 600.0
#: the most seeds and mazes one comparison runs (each run is two machines' runs)
MAX_BEHAVIOUR_RUNS = 10


def _behaviour(
    r: _Reader, keys: dict[str, yaml.Node], kind: str, text: str, here: str
) -> Objective:
    """An ``fsm-behaviour`` objective: the reference is a built-in algorithm's name; the
    mazes default to the set-up's (filled in by :func:`_exercise`)."""
    name = r.text(keys["reference"], here)
    if name not in list_algorithms():
        r.fail(keys["reference"], here, f"no built-in algorithm {name!r}",
               f"use one of {', '.join(list_algorithms())}")  # fmt: skip
    reference = load_algorithm(name)
    mazes = tuple(r.maze(n, here) for n in r.items(keys["mazes"], here)) if "mazes" in keys else ()
    seeds = 1
    if "seeds" in keys:
        value = r.number(keys["seeds"], f"{here}: seeds", minimum=1)
        if value != int(value) or value > MAX_BEHAVIOUR_RUNS:
            r.fail(keys["seeds"], here, f"seeds must be a whole number from 1 to "
                   f"{MAX_BEHAVIOUR_RUNS}", "write e.g. 'seeds: 2'")  # fmt: skip
        seeds = int(value)
    if len(mazes or (None,)) * seeds > MAX_BEHAVIOUR_RUNS:
        r.fail(keys["seeds"] if "seeds" in keys else keys["mazes"], here,
               f"mazes times seeds is over {MAX_BEHAVIOUR_RUNS} runs",
               "compare on fewer mazes or seeds")  # fmt: skip
    max_time = None
    if "max_time" in keys:
        max_time = r.number(keys["max_time"], f"{here}: max_time")
        if not 0 < max_time <= MAX_BEHAVIOUR_TIME:
            r.fail(
                keys["max_time"],
                here,
                f"max_time must be above 0 and at most {MAX_BEHAVIOUR_TIME:g}",
                "write simulated seconds, e.g. 'max_time: 120'",
            )
    return Objective(kind, text, mazes=mazes, reference=reference, seeds=seeds,
                     max_time=max_time)  # fmt: skip


def _question(r: _Reader, node: yaml.Node, where: str, max_tries: int | None = None) -> Question:
    keys = r.mapping(
        node,
        f"{where}: question",
        ("id", "text", "answer"),
        ("choices", "unit", "max_tries", "shown"),
    )
    q_id = r.text(keys["id"], f"{where}: question")
    here = f"{where}: question {q_id!r}"
    if "max_tries" in keys:
        max_tries = _max_tries(r, keys["max_tries"], here)
    answer = r.mapping(keys["answer"], f"{here}: answer", ("salt", "sha256"), ("step",))
    hashes = r.texts(answer["sha256"], f"{here}: answer")
    for h, n in zip(hashes, r.items(answer["sha256"], here), strict=True):
        if len(h) != 64 or any(c not in "0123456789abcdef" for c in h):
            r.fail(n, f"{here}: answer", "not a sha256 hex digest",
                   "make it with workbench.labs.model.hash_answer")  # fmt: skip
    step = None
    if "step" in answer:
        step = r.text(answer["step"], f"{here}: answer")
        try:
            ok = Decimal(step) > 0
        except ArithmeticError:
            ok = False
        if not ok:
            r.fail(answer["step"], f"{here}: answer", f"step {step!r} is not a positive number")
    choices = r.texts(keys["choices"], here) if "choices" in keys else ()
    if step is None and not choices:
        r.fail(node, here, "neither choices nor a numeric step", "add 'choices:' or answer 'step:'")
    if step is not None and choices:
        r.fail(keys["choices"], here, "a numeric question has no choices", "drop one of them")
    shown = r.text(keys["shown"], here) if "shown" in keys else ""
    if shown and shown not in SHOWN:
        r.fail(keys["shown"], here, f"unknown shown value {shown!r}", f"use {', '.join(SHOWN)}")
    if shown and step is None:
        r.fail(keys["shown"], here, "a shown value is a number", "give the answer a 'step:'")
    return Question(
        q_id,
        r.text(keys["text"], here),
        r.text(answer["salt"], f"{here}: answer"),
        frozenset(hashes),
        choices,
        step,
        r.text(keys["unit"], here) if "unit" in keys else "",
        max_tries,
        shown,
    )
