"""One run's life on a session: it starts, it is recorded, it ends.

Every front end that runs the robot goes through :class:`Run`: the lab station (one run per
``RunEntry``), the headless runner of ``workbench run``, ``eval`` and ``viple run``, and
``workbench serve``. A run holds the record it writes (``docs/run-record.md``), if any: it
opens it (:func:`record_file` for a file a command names, :meth:`Run.in_folder` for a station's
record folder within its quota), hands it to the session, which appends a line per control
tick, watches its bounds (:meth:`Run.watch`), and writes its summary and closes it
(:meth:`Run.end`). :func:`ending` is the one place that says a run is over on its own: the
robot got out, or the program driving stopped itself past its limits. The other ends (a
stop, a reset, a new maze) are someone's act, and the front end names them with the kinds
here; a headless run also ends at its time limit, where its session stops stepping.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from workbench.sim.record import KEEPS_SUMMARY, Recorder, RecordStop
from workbench.sim.session import Session

from .driving import Driving
from .recording import RECORD_CAP, RecordQuota, RecordTrouble, open_record

#: how a run ends (a station's ``RunEntry.ended`` and its record's summary say it)
EXIT = "exit"
STOPPED = "stopped"
RESET = "reset"
MAZE_CHANGED = "maze changed"
#: an algorithm failed, or a program stopped itself past its limits
ERROR = "error"


@dataclass(frozen=True)
class Ending:
    """Why a run is over on its own: :data:`EXIT` or :data:`ERROR` (with the program's words
    in ``detail``)."""

    kind: str
    detail: str = ""


def ending(session: Session, driving: Driving | None = None) -> Ending | None:
    """Why the run on ``session`` is over now, None while it goes on: the program driving
    stopped itself (:data:`ERROR`, first: its run ends there), or the robot got out of a maze
    that has exits (:data:`EXIT`). (A headless run also ends at its time limit: the session
    steps up to it, :meth:`Session.run`.)"""
    stopped = driving.stopped if driving is not None else None
    why = stopped() if stopped is not None else None
    if why is not None:
        return Ending(ERROR, why)
    if session.maze.exits and session.reached_exit:
        return Ending(EXIT)
    return None


def record_file(path: str) -> Recorder:
    """A record written to the file ``path`` that a command names (raises ``OSError`` when it
    cannot be created; the command says so in its own words), under the cap every record the
    workbench writes keeps (:data:`RECORD_CAP`): pictures and replays read any record it
    wrote, however long the run."""
    return Recorder(path, cap=RECORD_CAP)


@dataclass
class Run:
    """One run on ``session`` and its record (None: unrecorded)."""

    session: Session
    recorder: Recorder | None = None
    #: where the record is (kept when the record stopped mid-run and was let go)
    path: str | None = None
    #: why the record stopped before the run ended (None: it did not, or no record)
    record_stop: RecordStop | None = None
    #: :attr:`record_stop` was handed to the front end (by :meth:`watch` or :meth:`end`)
    _told: bool = False

    @classmethod
    def start(cls, session: Session, recorder: Recorder | None = None, **header: Any) -> Run:
        """The run begins: the session appends its ticks to ``recorder``, whose header says
        the session's set-up and ``header`` (who drives, ...)."""
        run = cls(session, recorder, str(recorder.path) if recorder and recorder.path else None)
        session.recorder = recorder
        session.record_header(**header)
        return run

    @classmethod
    def in_folder(
        cls,
        session: Session,
        folder: str | None,
        name: str,
        quota: RecordQuota,
        workspace: Path | None = None,
        **header: Any,
    ) -> tuple[Run, RecordTrouble | None]:
        """The run begins, recorded as ``folder/name`` within ``quota`` when there is a
        folder (:func:`~.recording.open_record`); what stood in the way, if anything (the
        run then goes unrecorded, or was recorded after moving a file aside)."""
        if not folder:
            return cls(session), None
        recorder, trouble = open_record(folder, name, quota, workspace)
        if recorder is None:
            session.recorder = None
            return cls(session), trouble
        return cls.start(session, recorder, **header), trouble

    def watch(self) -> RecordStop | None:
        """After steps: the record's stop when it is newly seen (once), else None. A record
        that can take no more lines at all (a full disk) is let go: the run goes on
        unrecorded. One stopped by its cap or its rate still takes its summary."""
        recorder = self.recorder
        if recorder is None or recorder.stopped is None or self._told:
            return None
        stop = self._tell(recorder)
        if stop.reason not in KEEPS_SUMMARY:
            self.close()
        return stop

    def end(self, **summary: Any) -> RecordStop | None:
        """The run ends: the record gets its summary (the session's measures and ``summary``)
        and is closed. Its stop, when it stopped and :meth:`watch` had not said so yet."""
        recorder = self.recorder
        if recorder is None:
            return None
        self.session.record_summary(**summary)
        self.close()
        return self._tell(recorder) if recorder.stopped is not None and not self._told else None

    def close(self) -> None:
        """Close the record without a summary (a run cut short by a failure); nothing when
        it is closed already."""
        recorder = self.recorder
        if recorder is None:
            return
        self.recorder = None
        if self.session.recorder is recorder:
            self.session.recorder = None
        try:
            recorder.close()
        finally:
            self.record_stop = recorder.stopped

    def _tell(self, recorder: Recorder) -> RecordStop:
        assert recorder.stopped is not None
        self._told = True
        self.record_stop = recorder.stopped
        return recorder.stopped
