"""Work done in forked processes behind an outer wall of limits: the one parallel runner of
``workbench eval`` and ``workbench grade``.

A job is a function that runs in a process of its own (forked: it starts with what this
process has loaded, at once, and takes its arguments without pickling) and sends what it
finds through a :class:`Reply`: a result or a refusal for each of its items (a run), or why it
stopped. At most ``workers`` processes run at once; each has a wall-clock deadline, a cap on
its address space (``RLIMIT_AS``) and on its processor time, and no output. A job that
crashes, hangs or blows its memory costs its own items only: the reason is its
:class:`Outcome`'s ``stopped``. Outcomes come back in the jobs' order, whatever ``workers``
is; ``progress`` is told of each job as it finishes.
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import os
import pickle
import resource
import signal
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from typing import Any

#: the longest reason an outcome keeps (a program's problem can be long)
MAX_REASON = 300


@dataclass(frozen=True)
class Limits:
    """The outer wall around each job's process: wall-clock seconds for all of its work, and
    MiB of address space it may map beyond what it was forked with."""

    deadline: float = 60.0
    memory: int = 1024


@dataclass(frozen=True)
class Words:
    """How the reasons a job stopped are said (each a ``str.format`` text)."""

    #: past its deadline (``{deadline}``: the seconds)
    deadline: str
    #: a ``MemoryError`` (``{memory}``: the MiB)
    memory: str
    #: ended without a result and without a signal (``{code}``, ``{memory}``)
    no_result: str
    #: ended by a signal (``{signal}``: its name)
    killed: str
    #: still running when the runner itself was interrupted
    interrupted: str


@dataclass
class Outcome:
    """What came back from one job: the result or refusal of each item (by its index), and
    why it stopped before its last item ("" when it did not)."""

    results: dict[int, Any] = field(default_factory=dict)
    refused: dict[int, str] = field(default_factory=dict)
    #: False when the job could not even begin (its program does not load)
    began: bool = True
    stopped: str = ""


class Reply:
    """A job's side of its pipe."""

    def __init__(self, conn: Connection) -> None:
        self._conn = conn

    def result(self, index: int, value: Any) -> None:
        self._conn.send(("result", index, value))

    def refused(self, index: int, reason: str) -> None:
        self._conn.send(("refused", index, one_line(reason)))

    def cannot_begin(self, reason: str) -> None:
        self._conn.send(("unbegun", one_line(reason)))

    def stopped(self, reason: str) -> None:
        self._conn.send(("stopped", one_line(reason)))


#: a job: run in a process of its own, answering through its reply; or an outcome already
#: known (a hand-in that cannot be run at all), counted done at once
Job = Callable[[Reply], None] | Outcome
#: told ``(done, total, index)`` as each job finishes
Progress = Callable[[int, int, int], None]


def one_line(text: str, limit: int = MAX_REASON) -> str:
    """``text`` on one line of printable characters, cut at ``limit``."""
    text = "".join(c if c.isprintable() else "?" for c in " ".join(text.split()))
    return text if len(text) <= limit else text[: limit - 3] + "..."


def run_jobs(
    jobs: Sequence[Job],
    words: Words,
    workers: int = 1,
    limits: Limits = Limits(),
    progress: Progress | None = None,
) -> list[Outcome]:
    """Every job, at most ``workers`` at once, each behind ``limits``; their outcomes in the
    jobs' order."""
    total = len(jobs)
    outcomes: list[Outcome | None] = [None] * total
    pending: deque[int] = deque()
    done = 0

    def finished(index: int, outcome: Outcome) -> None:
        nonlocal done
        outcomes[index] = outcome
        done += 1
        if progress:
            progress(done, total, index)

    for i, job in enumerate(jobs):
        if isinstance(job, Outcome):
            finished(i, job)
        else:
            pending.append(i)
    running: dict[Connection, _Child] = {}
    context = multiprocessing.get_context("fork")
    try:
        while pending or running:
            while pending and len(running) < max(1, workers):
                i = pending.popleft()
                work = jobs[i]
                assert not isinstance(work, Outcome)
                child = _Child.start(context, i, work, limits, words)
                running[child.conn] = child
            timeout = max(0.0, min(c.deadline for c in running.values()) - time.monotonic())
            for conn in wait(list(running), timeout):
                child = running[conn]  # type: ignore[index]
                if child.take():
                    del running[child.conn]
                    finished(child.index, child.outcome)
            now = time.monotonic()
            for child in [c for c in running.values() if now >= c.deadline]:
                child.stop(words.deadline.format(deadline=limits.deadline))
                del running[child.conn]
                finished(child.index, child.outcome)
    finally:
        for child in running.values():
            child.stop(words.interrupted)
    return [outcome for outcome in outcomes if outcome is not None]


@dataclass
class _Child:
    """One job's process, as the parent sees it."""

    index: int
    process: Any  # a multiprocessing process of the fork context
    conn: Connection
    deadline: float
    limits: Limits
    words: Words
    outcome: Outcome = field(default_factory=Outcome)

    @classmethod
    def start(
        cls, context: Any, index: int, work: Callable[[Reply], None], limits: Limits, words: Words
    ) -> _Child:
        mine, theirs = context.Pipe(duplex=False)
        process = context.Process(
            target=_child_main, args=(theirs, work, limits, words), daemon=True
        )
        process.start()
        theirs.close()
        return cls(index, process, mine, time.monotonic() + limits.deadline, limits, words)

    def take(self) -> bool:
        """Read what the process sent; True once it has ended (its pipe closed)."""
        if self._read():
            return False
        self.process.join()
        self._ended()
        self.conn.close()
        return True

    def stop(self, reason: str) -> None:
        """Kill the process; the items it finished keep what it sent, the others get
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
        if what == "result":
            self.outcome.results[message[1]] = message[2]
        elif what == "refused":
            self.outcome.refused[message[1]] = message[2]
        elif what == "unbegun":
            self.outcome.began = False
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
            self.outcome.stopped = self.words.killed.format(signal=name)
        else:
            self.outcome.stopped = self.words.no_result.format(code=code, memory=self.limits.memory)


# -- the job's process -------------------------------------------------------------------------
def _child_main(conn: Connection, work: Callable[[Reply], None], limits: Limits, words: Words):
    """Run one job behind its wall; a failure is sent as the reason it stopped."""
    _wall(limits.memory, limits.deadline)
    reply = Reply(conn)
    try:
        work(reply)
    except MemoryError:
        reply.stopped(words.memory.format(memory=limits.memory))
    except RecursionError:
        reply.stopped("the run failed: it nested deeper than Python's recursion limit")
    except Exception as exc:  # the job's process must name whatever went wrong
        reply.stopped(f"the run failed: {type(exc).__name__}: {exc}")
    finally:
        conn.close()


def _wall(memory: int, deadline: float) -> None:
    """The limits of a job's process: ``memory`` MiB of address space beyond what it was
    forked with, its processor time (a backstop for the parent's deadline), no core files;
    its output (a crash's report too) goes nowhere."""
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
