"""Judging a student's state machine by its behaviour, beside the screen's thread.

An ``fsm-behaviour`` objective compares the FSM file a student ran during the exercise with
the exercise's reference machine (:func:`workbench.control.fsm_behaviour.compare`). That
takes runs of both machines, too long for a check made at every redraw, so the check asks a
:class:`BehaviourJudge`: it answers at once with the verdict it has for that file (by its
digest) or None, and meanwhile judges it on a worker thread of its own, one comparison at a
time, each bounded by the comparison's wall-clock deadline. The verdicts are kept (the most
recent :data:`KEPT` of them), so the same file is judged once.
"""

from __future__ import annotations

import math
import queue
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass

from workbench.control.fsm_behaviour import DEFAULT_DEADLINE, Trial, Verdict, compare
from workbench.files.workspace import FileAccess, OutsideWorkspace
from workbench.fsm.machine import FsmDefinition
from workbench.fsm.yaml_file import FsmFileError, load_fsm

#: how many verdicts a judge keeps
KEPT = 64


@dataclass(frozen=True)
class Task:
    """What to judge: the student's file as it ran (its path and digest), the reference, and
    the runs both machines make."""

    source: str
    digest: str
    reference: FsmDefinition
    trials: tuple[Trial, ...]
    profile: str
    sensors: tuple[str, ...]
    max_time: float | None = None

    @property
    def key(self) -> tuple[object, ...]:
        ref = self.reference
        return (self.digest, ref.name, ref.digest, self.trials, self.profile, self.sensors,
                self.max_time)  # fmt: skip


@dataclass(frozen=True)
class Judged:
    """A task's outcome: the comparison's verdict, or why the file could not be compared."""

    verdict: Verdict | None = None
    problem: str = ""


class BehaviourJudge:
    """Judges tasks one at a time on a thread of its own (``inline``: at once, on the
    caller's thread, for headless uses)."""

    def __init__(
        self,
        files: FileAccess | None = None,
        deadline: float = DEFAULT_DEADLINE,
        inline: bool = False,
    ) -> None:
        self.files = files or FileAccess()
        self.deadline = deadline
        self.inline = inline
        self._lock = threading.Lock()
        self._done: OrderedDict[tuple[object, ...], Judged] = OrderedDict()
        self._pending: dict[tuple[object, ...], Task] = {}
        self._queue: queue.SimpleQueue[tuple[tuple[object, ...], Task]] = queue.SimpleQueue()
        self._worker: threading.Thread | None = None
        self._closed = threading.Event()
        self._idle = threading.Condition(self._lock)

    @property
    def busy(self) -> bool:
        with self._lock:
            return bool(self._pending)

    def judged(self, task: Task) -> Judged | None:
        """The task's outcome if it is known; else None, and it is being judged."""
        key = task.key
        with self._lock:
            if key in self._done:
                self._done.move_to_end(key)
                return self._done[key]
            if key in self._pending:
                return None
        if self.inline:
            self._keep(key, self.judge(task))
            return self._done[key]
        with self._lock:
            self._pending[key] = task
            if self._worker is None:
                # a daemon: a comparison under way never holds the app's exit
                self._worker = threading.Thread(
                    target=self._work, name="fsm-behaviour", daemon=True
                )
                self._worker.start()
        self._queue.put((key, task))
        return None

    def wait(self, timeout: float | None = None) -> None:
        """Until every pending task is judged (tests)."""
        with self._idle:
            self._idle.wait_for(lambda: not self._pending, timeout)

    def close(self) -> None:
        """No more judging: a comparison under way stops at its next tick (out of time)."""
        self._closed.set()

    def _clock(self) -> float:
        return math.inf if self._closed.is_set() else time.monotonic()

    def _work(self) -> None:
        while True:  # a daemon thread: it ends with the process
            key, task = self._queue.get()
            try:
                outcome = self.judge(task)
            except Exception as exc:  # a bug must not leave the objective checking for ever
                outcome = Judged(problem=f"could not be compared: {type(exc).__name__}")
            self._keep(key, outcome)

    def _keep(self, key: tuple[object, ...], outcome: Judged) -> None:
        with self._lock:
            self._pending.pop(key, None)
            self._done[key] = outcome
            while len(self._done) > KEPT:
                self._done.popitem(last=False)
            self._idle.notify_all()

    def judge(self, task: Task) -> Judged:
        """Read the student's file (it must still be the one that ran) and compare it."""
        if self._closed.is_set():
            return Judged(problem="not compared: the workbench is closing")
        try:
            definition = load_fsm(self.files.for_reading(task.source))
        except (FsmFileError, OutsideWorkspace, OSError):
            return Judged(problem="the file that ran cannot be read now: save it and run it again")
        if definition.digest != task.digest:
            return Judged(
                problem="the file has changed since it ran, or ran with parameters set in the "
                "algorithm dialog: run the file as it is saved (ctrl+r in the FSM editor)"
            )
        verdict = compare(
            task.reference,
            definition,
            task.trials,
            task.profile,
            task.sensors,
            task.max_time,
            self.deadline,
            self._clock,
        )
        return Judged(verdict)
