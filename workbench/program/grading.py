"""Grading a folder of students' VIPLE programs: every program on the same mazes and seeds,
in parallel, each in a process of its own behind an outer wall of limits.

A :class:`Submission` is one student's program as found in the folder (:mod:`.submissions`);
a :class:`Plan` says what every program runs on. :func:`grade` runs each submission in a child
process (at most ``jobs`` at once) with a wall-clock deadline for all of its runs, a cap on its
address space (``RLIMIT_AS``) and the plan's simulated-time limit per run. A program that does
not load, crashes, hangs or blows its memory costs its own rows only: the reason is the row's
``refusal``. The rows come back in the submissions' order, one per maze and seed, whatever
``jobs`` is.
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import os
import pickle
import re
import resource
import signal
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any

from workbench.control.headless import RunSetupError, RunSpec, run

from .pilot import ProgramPilot, load_compiled
from .problems import ProgramError

#: wall-clock seconds one program may take for all of its runs
DEFAULT_DEADLINE = 60.0
#: MiB of address space one program's process may map
DEFAULT_MEMORY = 1024
#: the longest refusal reason a row keeps (a program's problem can be long)
MAX_REASON = 300
#: what of a student's name goes into a record's file name
_NAME = re.compile(r"[^A-Za-z0-9_.-]+")


@dataclass(frozen=True)
class Limits:
    """The outer wall around each program's process."""

    deadline: float = DEFAULT_DEADLINE
    memory: int = DEFAULT_MEMORY


@dataclass(frozen=True)
class Submission:
    """One student's program: ``path`` to open (relative to the folder), ``file`` as the table
    shows it, the sha256 of its bytes, its key script, or why it cannot be run at all."""

    student: str
    file: str
    path: str = ""
    sha256: str = ""
    keys: str = ""
    refused: str = ""


@dataclass(frozen=True)
class Plan:
    """What every program runs on: the mazes (paths), seeds 0..seeds-1, and the simulation."""

    folder: str
    mazes: tuple[str, ...]
    seeds: int = 1
    profile: str | None = None
    sensors: tuple[str, ...] = ()
    noise: str | None = None
    noise_params: tuple[str, ...] = ()
    max_time: float | None = None
    kinds: str | None = None
    #: how often the programs' sensors are reported, ms (None: the profile's period)
    report_ms: int | None = None
    #: what drives each run: made of the program's path, its key script and the kinds map
    pilot: type[ProgramPilot] = ProgramPilot
    #: a folder (absolute) where each program's run with seed 0 on each maze is recorded, for
    #: pictures: ``MAZE_NO/INDEX-STUDENT.jsonl`` (:meth:`record_of`); None records nothing
    records: str | None = None

    def record_of(self, maze_no: int, index: int, submission: Submission) -> str | None:
        """Where the ``index``-th submission's seed-0 run on maze ``maze_no`` is recorded."""
        if self.records is None:
            return None
        student = _NAME.sub("-", submission.student).strip("-.")[:40] or "student"
        return os.path.join(self.records, f"{maze_no + 1:02d}", f"{index + 1:03d}-{student}.jsonl")

    @property
    def runs(self) -> list[tuple[str, int]]:
        """Each run's maze and seed, in the table's order (that of :meth:`specs` too)."""
        return [(maze, seed) for maze in self.mazes for seed in range(self.seeds)]

    def specs(self, submission: Submission, index: int = 0) -> list[RunSpec]:
        pilot = self.pilot(
            submission.path, keys=submission.keys, kinds=self.kinds, report_ms=self.report_ms
        )
        return [
            RunSpec(
                maze=maze,
                pilot=pilot,
                profile=self.profile,
                sensors=self.sensors,
                seed=seed,
                noise=self.noise,
                noise_params=self.noise_params,
                max_time=self.max_time,
                record=self.record_of(no, index, submission) if seed == 0 else None,
            )
            for no, maze in enumerate(self.mazes)
            for seed in range(self.seeds)
        ]


@dataclass(frozen=True)
class Row:
    """One program on one maze with one seed: the table's line."""

    student: str
    file: str
    program_sha256: str
    loads: bool
    maze: str
    seed: int
    reached_exit: bool = False
    #: simulated seconds: to the exit when it got out, else until the run ended
    time: float | None = None
    distance_blocks: float | None = None
    turn_degrees: float | None = None
    collisions: int | None = None
    #: the program's errors at run time (each ends only the flow it happened in)
    errors: int | None = None
    refusal: str = ""


@dataclass
class _Outcome:
    """What came back from one program's process."""

    loads: bool = True
    measures: dict[int, dict[str, Any]] = field(default_factory=dict)
    refused: dict[int, str] = field(default_factory=dict)
    #: why the process stopped before its last run (every run without a result gets it)
    stopped: str = ""


Progress = Callable[[int, int, Submission], None]


def grade(
    submissions: Sequence[Submission],
    plan: Plan,
    jobs: int = 1,
    limits: Limits = Limits(),
    progress: Progress | None = None,
) -> list[Row]:
    """Every submission on the plan's mazes and seeds: one row per submission, maze and seed,
    in the submissions' order. ``progress(done, total, submission)`` is told of each finished
    submission."""
    total = len(submissions)
    outcomes: list[_Outcome | None] = [None] * total
    pending: deque[int] = deque()
    done = 0
    for i, s in enumerate(submissions):
        if s.refused:
            outcomes[i] = _Outcome(loads=False, stopped=s.refused)
            done += 1
            if progress:
                progress(done, total, s)
        else:
            pending.append(i)
    running: dict[Connection, _Child] = {}
    # forked: a program's process starts with what this one has loaded, at once (a fresh
    # interpreter would import the command's main module again for each program)
    context = multiprocessing.get_context("fork")
    try:
        while pending or running:
            while pending and len(running) < max(1, jobs):
                i = pending.popleft()
                child = _Child.start(context, i, submissions[i], plan, limits)
                running[child.conn] = child
            now = time.monotonic()
            timeout = max(0.0, min(c.deadline for c in running.values()) - now)
            for conn in wait(list(running), timeout):
                child = running[conn]  # type: ignore[index]
                if child.take():
                    del running[child.conn]
                    outcomes[child.index] = child.outcome
                    done += 1
                    if progress:
                        progress(done, total, submissions[child.index])
            now = time.monotonic()
            for child in [c for c in running.values() if now >= c.deadline]:
                child.stop(
                    f"stopped after {limits.deadline:g} s of wall-clock time, the limit for "
                    "one program's runs (--deadline)"
                )
                del running[child.conn]
                outcomes[child.index] = child.outcome
                done += 1
                if progress:
                    progress(done, total, submissions[child.index])
    finally:
        for child in running.values():
            child.stop("grading was interrupted")
    rows = []
    for submission, outcome in zip(submissions, outcomes, strict=True):
        assert outcome is not None
        rows += _rows(submission, plan, outcome)
    return rows


@dataclass
class _Child:
    """One program's process, as the parent sees it."""

    index: int
    process: Any  # a multiprocessing process of the fork context
    conn: Connection
    deadline: float
    memory: int
    outcome: _Outcome = field(default_factory=_Outcome)

    @classmethod
    def start(cls, context, index: int, submission: Submission, plan: Plan, limits: Limits):
        mine, theirs = context.Pipe(duplex=False)
        process = context.Process(
            target=_child_main,
            args=(theirs, plan.folder, submission.path, plan.kinds, plan.specs(submission, index)),
            kwargs={"memory": limits.memory, "deadline": limits.deadline},
            daemon=True,
        )
        process.start()
        theirs.close()
        return cls(index, process, mine, time.monotonic() + limits.deadline, limits.memory)

    def take(self) -> bool:
        """Read what the process sent; True once it has ended (its pipe closed)."""
        if self._read():
            return False
        self.process.join()
        self._ended()
        self.conn.close()
        return True

    def stop(self, reason: str) -> None:
        """Kill the process; the runs it finished keep what it sent, the others get
        ``reason``."""
        self.process.kill()
        self.process.join()
        self._read()
        self.conn.close()
        self.outcome.stopped = self.outcome.stopped or reason

    def _read(self) -> bool:
        """Take every message waiting in the pipe; False once the pipe has closed (a message
        cut short by a killed process is dropped)."""
        try:
            while self.conn.poll():
                self._note(self.conn.recv())
        except (EOFError, OSError, pickle.UnpicklingError):
            return False
        return True

    def _note(self, message: tuple) -> None:
        what = message[0]
        if what == "run":
            self.outcome.measures[message[1]] = message[2]
        elif what == "refused":
            self.outcome.refused[message[1]] = message[2]
        elif what == "unloadable":
            self.outcome.loads = False
            self.outcome.stopped = message[1]
        elif what == "stopped":
            self.outcome.stopped = message[1]

    def _ended(self) -> None:
        code = self.process.exitcode
        if code == 0 or self.outcome.stopped:
            return
        if code is not None and code < 0:
            try:
                name = signal.Signals(-code).name
            except ValueError:
                name = f"signal {-code}"
            self.outcome.stopped = f"the program's process was ended by {name}"
        else:
            self.outcome.stopped = (
                f"the program's process ended without a result (exit status {code}); "
                f"it may have run out of its {self.memory} MiB of memory (--memory)"
            )


def _rows(submission: Submission, plan: Plan, outcome: _Outcome) -> list[Row]:
    rows = []
    for i, (maze, seed) in enumerate(plan.runs):
        row = Row(
            submission.student,
            submission.file,
            submission.sha256,
            outcome.loads,
            Path(maze).name,
            seed,
        )
        measures = outcome.measures.get(i)
        if measures is not None:
            rows.append(replace(row, **measures))
        else:
            reason = outcome.refused.get(i) or outcome.stopped or "the run gave no result"
            rows.append(replace(row, refusal=_short(reason)))
    return rows


def _short(text: str) -> str:
    """``text`` on one line of printable characters, cut at :data:`MAX_REASON`."""
    text = "".join(c if c.isprintable() else "?" for c in " ".join(text.split()))
    return text if len(text) <= MAX_REASON else text[: MAX_REASON - 3] + "..."


# -- the program's process ---------------------------------------------------------------------
def _child_main(
    conn: Connection,
    folder: str,
    program: str,
    kinds: str | None,
    specs: list[RunSpec],
    memory: int,
    deadline: float,
) -> None:
    """Run one program's runs, sending each result; a failure is sent as the reason."""
    _wall(memory, deadline)
    try:
        os.chdir(folder)
        try:
            load_compiled(program, kinds)
        except ProgramError as exc:
            conn.send(("unloadable", _problems(exc)))
            return
        for i, spec in enumerate(specs):
            try:
                conn.send(("run", i, _measures(run(spec).as_dict())))
            except ProgramError as exc:
                conn.send(("refused", i, _problems(exc)))
            except RunSetupError as exc:
                conn.send(("refused", i, str(exc)))
    except MemoryError:
        conn.send(("stopped", f"used more than {memory} MiB of memory, the cap per program "
                              "(--memory)"))  # fmt: skip
    except RecursionError:
        conn.send(("stopped", "the run failed: it nested deeper than Python's recursion limit"))
    except Exception as exc:  # the program's process must name whatever went wrong
        conn.send(("stopped", _short(f"the run failed: {type(exc).__name__}: {exc}")))
    finally:
        conn.close()


def _wall(memory: int, deadline: float) -> None:
    """The limits of a program's process: ``memory`` MiB of address space beyond what it
    was forked with, its processor time (a backstop for the parent's deadline), no core
    files; its output (a crash's report too) goes nowhere."""
    faulthandler.disable()
    _lower(resource.RLIMIT_AS, _mapped() + (memory << 20))
    _lower(resource.RLIMIT_CPU, int(deadline) + 5)
    _lower(resource.RLIMIT_CORE, 0)
    devnull = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(devnull, fd)
    os.close(devnull)


def _lower(limit: int, value: int) -> None:
    """Set ``limit`` to ``value``, or keep it where it is already lower."""
    _, hard = resource.getrlimit(limit)
    if hard != resource.RLIM_INFINITY:
        value = min(value, hard)
    resource.setrlimit(limit, (value, value))


def _mapped() -> int:
    """Bytes of address space this process has mapped (0 where ``/proc`` does not say)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * resource.getpagesize()
    except (OSError, ValueError, IndexError):
        return 0


def _problems(exc: ProgramError) -> str:
    first = str(exc.problems[0]) if exc.problems else str(exc)
    more = len(exc.problems) - 1
    if more > 0:
        first += f" (and {more} more: workbench viple check FILE lists them)"
    return _short(first)


def _measures(result: dict[str, Any]) -> dict[str, Any]:
    reached = bool(result["reached_exit"])
    seconds = result.get("exit_time") if reached else result["sim_time"]
    return {
        "reached_exit": reached,
        "time": round(float(seconds if seconds is not None else result["sim_time"]), 3),
        "distance_blocks": round(float(result["distance_cells"]), 3),
        "turn_degrees": round(float(result["turn_degrees"]), 3),
        "collisions": int(result["collisions"]),
        "errors": len(result["errors"]),
        # a program past its bounds is stopped by the interpreter: its measures so far, and why
        "refusal": _short(f"stopped at {result['stopped']}") if result.get("stopped") else "",
    }
