"""Grading a folder of students' VIPLE programs: every program on the same mazes and seeds,
in parallel, each in a process of its own behind an outer wall of limits.

A :class:`Submission` is one student's program as found in the folder (:mod:`.submissions`);
a :class:`Plan` says what every program runs on. :func:`grade` runs each submission in a child
process of the one parallel runner (:mod:`workbench.control.parallel`, at most ``jobs`` at
once) with a wall-clock deadline for all of its runs, a cap on its address space
(``RLIMIT_AS``) and the plan's simulated-time limit per run. A program that does
not load, crashes, hangs or blows its memory costs its own rows only: the reason is the row's
``refusal``. The rows come back in the submissions' order, one per maze and seed, whatever
``jobs`` is.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from workbench.control.headless import RunSetupError, RunSpec, run
from workbench.control.parallel import (
    Job,
    Limits,
    Outcome,
    Reply,
    Words,
    one_line,
    run_jobs,
)

from .pilot import ProgramPilot, load_compiled
from .problems import ProgramError

#: wall-clock seconds one program may take for all of its runs
DEFAULT_DEADLINE = 60.0
#: MiB of address space one program's process may map
DEFAULT_MEMORY = 1024
#: the outer wall around each program's process, unless the command says otherwise
DEFAULT_LIMITS = Limits(DEFAULT_DEADLINE, DEFAULT_MEMORY)
#: what of a student's name goes into a record's file name
_NAME = re.compile(r"[^A-Za-z0-9_.-]+")


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


Progress = Callable[[int, int, Submission], None]

#: how a program's process is said to have stopped
WORDS = Words(
    deadline="stopped after {deadline:g} s of wall-clock time, the limit for one program's "
    "runs (--deadline)",
    memory="used more than {memory} MiB of memory, the cap per program (--memory)",
    no_result="the program's process ended without a result (exit status {code}); it may "
    "have run out of its {memory} MiB of memory (--memory)",
    killed="the program's process was ended by {signal}",
    interrupted="grading was interrupted",
)


def grade(
    submissions: Sequence[Submission],
    plan: Plan,
    jobs: int = 1,
    limits: Limits = DEFAULT_LIMITS,
    progress: Progress | None = None,
) -> list[Row]:
    """Every submission on the plan's mazes and seeds: one row per submission, maze and seed,
    in the submissions' order. ``progress(done, total, submission)`` is told of each finished
    submission."""
    work: list[Job] = [
        Outcome(began=False, stopped=s.refused) if s.refused else _runs(s, index, plan)
        for index, s in enumerate(submissions)
    ]
    told = (lambda done, total, i: progress(done, total, submissions[i])) if progress else None
    outcomes = run_jobs(work, WORDS, jobs, limits, told)
    rows = []
    for submission, outcome in zip(submissions, outcomes, strict=True):
        rows += _rows(submission, plan, outcome)
    return rows


def _runs(submission: Submission, index: int, plan: Plan) -> Callable[[Reply], None]:
    """The ``index``-th program's runs, in a process of its own: each result, or why it was
    refused."""
    specs = plan.specs(submission, index)

    def work(reply: Reply) -> None:
        os.chdir(plan.folder)
        try:
            load_compiled(submission.path, plan.kinds)
        except ProgramError as exc:
            reply.cannot_begin(_problems(exc))
            return
        for i, spec in enumerate(specs):
            try:
                reply.result(i, _measures(run(spec).as_dict()))
            except ProgramError as exc:
                reply.refused(i, _problems(exc))
            except RunSetupError as exc:
                reply.refused(i, str(exc))

    return work


def _rows(submission: Submission, plan: Plan, outcome: Outcome) -> list[Row]:
    rows = []
    for i, (maze, seed) in enumerate(plan.runs):
        row = Row(
            submission.student,
            submission.file,
            submission.sha256,
            outcome.began,
            Path(maze).name,
            seed,
        )
        measures = outcome.results.get(i)
        if measures is not None:
            rows.append(replace(row, **measures))
        else:
            reason = outcome.refused.get(i) or outcome.stopped or "the run gave no result"
            rows.append(replace(row, refusal=one_line(reason)))
    return rows


def _problems(exc: ProgramError) -> str:
    first = str(exc.problems[0]) if exc.problems else str(exc)
    more = len(exc.problems) - 1
    if more > 0:
        first += f" (and {more} more: workbench viple check FILE lists them)"
    return one_line(first)


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
        "refusal": one_line(f"stopped at {result['stopped']}") if result.get("stopped") else "",
    }
