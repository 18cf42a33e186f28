"""Pilots that attack the process a grading run gives each program, as a program might that
slipped past the interpreter's own bounds. Which attack is the program file's name: a file
named ``hog...`` allocates until its memory runs out, ``sleeper...`` never returns,
``crash...`` dies of a segmentation fault, ``deep...`` recurses without end, ``later...``
drives its first run and never returns from its second; any other file drives as a program
does."""

from __future__ import annotations

import os
import signal
import time
from dataclasses import dataclass
from pathlib import Path

from workbench.control.headless import AlgorithmPilot
from workbench.program.pilot import ProgramPilot

#: the runs a ``later...`` program's process has started
_runs: list[str] = []


@dataclass(frozen=True)
class HostilePilot(ProgramPilot):
    def drive(self, profile, sensors):
        name = Path(self.program).name
        if name.startswith("hog"):
            hoard = []
            while True:
                hoard.append(bytearray(1 << 20))
        if name.startswith("sleeper"):
            time.sleep(3600)
        if name.startswith("crash"):
            os.kill(os.getpid(), signal.SIGSEGV)
        if name.startswith("deep"):
            return _deeper(0)
        if name.startswith("later"):
            _runs.append(name)
            if len(_runs) > 1:
                time.sleep(3600)
        return super().drive(profile, sensors)


def _deeper(n: int):
    return _deeper(n + 1) + 1


@dataclass(frozen=True)
class HostileAlgorithm(AlgorithmPilot):
    """An algorithm's run that attacks its process as it starts: ``attack`` is ``hog``,
    ``sleeper`` or ``crash`` (as above)."""

    attack: str = ""

    def drive(self, profile, sensors):
        if self.attack == "hog":
            hoard = []
            while True:
                hoard.append(bytearray(1 << 20))
        if self.attack == "sleeper":
            time.sleep(3600)
        if self.attack == "crash":
            os.kill(os.getpid(), signal.SIGSEGV)
        return super().drive(profile, sensors)
