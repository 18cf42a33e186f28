"""The one parallel runner of ``eval`` and ``grade``: each run in a forked process behind a
deadline and a memory cap, results in the matrix's order whatever finishes first, and an
evaluation whose run crashes, hangs or blows its memory ends with that run named."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import pytest

from tests.program.hostile_pilots import HostileAlgorithm
from tests.waiting import DEADLINE
from workbench.control.evaluate import WORDS, Entrant, EvalError, evaluate
from workbench.control.headless import AlgorithmPilot, RunSpec
from workbench.control.parallel import Limits, Outcome, Reply, run_jobs

MAZES = Path(__file__).resolve().parents[2] / "mazes"
WEB = str(MAZES / "web.txt")


def _after(marker: Path, value: str):
    """A job that waits for ``marker`` (written when the runner has told of another job's
    end) before it answers."""

    def work(reply: Reply) -> None:
        give_up = time.monotonic() + DEADLINE
        while not marker.exists() and time.monotonic() < give_up:
            time.sleep(0.01)
        reply.result(0, value if marker.exists() else "never saw the marker")

    return work


def _answers(value: str):
    def work(reply: Reply) -> None:
        reply.result(0, value)

    return work


def test_outcomes_come_in_the_jobs_order_whatever_finishes_first(tmp_path):
    marker = tmp_path / "third-told"
    seen: list[int] = []

    def progress(done: int, total: int, index: int) -> None:
        seen.append(index)
        if index == 2:
            marker.write_text("told")  # the first job answers only after this

    known = Outcome(began=False, stopped="cannot run")
    outcomes = run_jobs(
        [_after(marker, "first"), known, _answers("third")], WORDS, workers=2, progress=progress
    )
    assert [o.results.get(0) for o in outcomes] == ["first", None, "third"]
    assert outcomes[1] is known
    # the known outcome at once, then the third job, then the first that waited for it
    assert seen == [1, 2, 0]


def _entrant(name: str, attack: str) -> Entrant:
    """right-wall on seed 0 (the check before the runs passes), the attack on seed 1."""

    def spec(maze: str, seed: int) -> RunSpec:
        pilot = HostileAlgorithm("right-wall", attack=attack) if seed == 1 else None
        return RunSpec(maze, pilot or AlgorithmPilot("right-wall"), profile="web", seed=seed)

    return Entrant(name, spec)


@pytest.mark.parametrize(
    ("attack", "deadline", "reason"),
    [
        ("crash", 60, "the run's process was ended by SIGSEGV"),
        ("hog", 60, "used more than 300 MiB of memory, the cap for one run (--memory)"),
        ("sleeper", 3, "stopped after 3 s of wall-clock time, the limit for one run (--deadline)"),
    ],
)
def test_a_run_that_attacks_its_process_ends_the_evaluation_naming_it(attack, deadline, reason):
    with pytest.raises(EvalError) as raised:
        evaluate(
            [WEB],
            ["right-wall"],
            seeds=2,
            profile="web",
            jobs=2,
            others=[_entrant("rogue", attack)],
            limits=Limits(deadline=deadline, memory=300),
        )
    assert str(raised.value) == f"rogue on {WEB}, seed 1: {reason}"


def test_an_evaluation_within_its_limits_gives_every_run_in_order():
    result = evaluate(
        [WEB], ["right-wall"], seeds=2, profile="web", jobs=2, others=[_entrant("again", "")]
    )
    assert result.algorithms == ("right-wall", "again")
    # the same algorithm on the same seeds: the same figures, whichever process ran them
    mine, again = result.cell(WEB, "right-wall"), result.cell(WEB, "again")
    assert replace(again, algorithm="right-wall") == mine
    assert mine.runs == 2 and mine.reached == 2
