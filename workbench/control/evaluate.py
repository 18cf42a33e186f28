"""The entrant x maze matrix: every algorithm (or VIPLE program) on every maze over several
seeds, in parallel.

An entrant is a name and a way to make the :class:`~.headless.RunSpec` of one run (maze,
seed); a spec checks itself before anything runs and runs itself in a process of its own,
through the one parallel runner (:mod:`.parallel`: forked, behind a wall-clock deadline and a
memory cap per run, results in the matrix's order whatever the number of workers). A run that
crashes, hangs or blows its memory ends the evaluation with an :class:`EvalError` naming it.
An algorithm's entrant is made here; a VIPLE program's comes from
:mod:`workbench.program.pilot`.
"""

from __future__ import annotations

import csv
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from .headless import AlgorithmPilot, RunSetupError, RunSpec
from .parallel import Job, Limits, Reply, Words, run_jobs

MEASURES = ("distance_cells", "turn_degrees", "sim_time", "collisions", "touches", "turns")

#: the outer wall around each run's process: a run is bounded in simulated time already, so
#: the deadline only catches one that hangs (the largest bundled maze takes a few seconds)
EVAL_LIMITS = Limits(deadline=600.0, memory=1024)
#: the least address space (MiB) a run's process may be given: less cannot load the simulator
MIN_EVAL_MEMORY = 256
#: how a run's process is said to have stopped
WORDS = Words(
    deadline="stopped after {deadline:g} s of wall-clock time, the limit for one run (--deadline)",
    memory="used more than {memory} MiB of memory, the cap for one run (--memory)",
    no_result="the run's process ended without a result (exit status {code}); it may have "
    "run out of its {memory} MiB of memory (--memory)",
    killed="the run's process was ended by {signal}",
    interrupted="the evaluation was interrupted",
)


class EvalError(ValueError):
    """The evaluation cannot start (named inputs that do not load)."""


@dataclass(frozen=True)
class Entrant:
    """What takes part: its name in the table, and the spec of its run on a maze with a seed."""

    name: str
    spec: Callable[[str, int], RunSpec]


def algorithm_entrant(
    algorithm: str,
    profile: str | None = None,
    noise: str | None = None,
    noise_params: tuple[str, ...] = (),
    max_time: float | None = None,
) -> Entrant:
    def spec(maze: str, seed: int) -> RunSpec:
        return RunSpec(
            maze=maze,
            pilot=AlgorithmPilot(algorithm),
            profile=profile,
            seed=seed,
            noise=noise,
            noise_params=noise_params,
            max_time=max_time,
        )

    return Entrant(algorithm, spec)


@dataclass(frozen=True)
class Cell:
    """One algorithm on one maze, summarised over the seeds."""

    maze: str
    algorithm: str
    runs: int
    reached: int
    mean: dict[str, float]
    spread: dict[str, float]  # population standard deviation over the seeds

    def as_dict(self) -> dict[str, Any]:
        return {
            "maze": self.maze,
            "algorithm": self.algorithm,
            "runs": self.runs,
            "reached": self.reached,
            "mean": {k: round(v, 3) for k, v in self.mean.items()},
            "spread": {k: round(v, 3) for k, v in self.spread.items()},
        }


@dataclass(frozen=True)
class EvalResult:
    mazes: tuple[str, ...]
    algorithms: tuple[str, ...]
    seeds: int
    cells: tuple[Cell, ...]

    def cell(self, maze: str, algorithm: str) -> Cell:
        return next(c for c in self.cells if c.maze == maze and c.algorithm == algorithm)

    def ranking(self, maze: str) -> list[Cell]:
        """Best first: most runs out, then fewest turning degrees, then shortest distance."""
        cells = [c for c in self.cells if c.maze == maze]
        return sorted(
            cells,
            key=lambda c: (-c.reached, c.mean["turn_degrees"], c.mean["distance_cells"]),
        )

    def as_dict(self) -> dict[str, Any]:
        return {
            "seeds": self.seeds,
            "cells": [c.as_dict() for c in self.cells],
            "ranking": {m: [c.algorithm for c in self.ranking(m)] for m in self.mazes},
        }


def _summarise(maze: str, algorithm: str, results: list[dict[str, Any]]) -> Cell:
    mean = {k: statistics.fmean(r[k] for r in results) for k in MEASURES}
    spread = {k: statistics.pstdev([r[k] for r in results]) for k in MEASURES}
    return Cell(
        maze, algorithm, len(results), sum(r["reached_exit"] for r in results), mean, spread
    )


def evaluate(
    mazes: Sequence[str],
    algorithms: Sequence[str] = (),
    seeds: int = 3,
    profile: str | None = None,
    noise: str | None = None,
    noise_params: tuple[str, ...] = (),
    max_time: float | None = None,
    jobs: int = 1,
    progress: bool | Callable[[int, int], None] = False,
    others: Sequence[Entrant] = (),
    limits: Limits = EVAL_LIMITS,
) -> EvalResult:
    """Every algorithm (by name) and every other entrant (VIPLE programs) on every maze, each
    run in a process of its own behind ``limits``."""
    entrants = [
        *(algorithm_entrant(a, profile, noise, noise_params, max_time) for a in algorithms),
        *others,
    ]
    names = [e.name for e in entrants]
    if not entrants:
        raise EvalError("nothing to evaluate: give algorithms or programs")
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise EvalError(f"two entrants are named {', '.join(twice)}: give each once")
    specs = [e.spec(m, s) for m in mazes for e in entrants for s in range(seeds)]
    what = [f"{e.name} on {m}, seed {s}" for m in mazes for e in entrants for s in range(seeds)]
    # fail fast, in this process, on inputs that cannot run at all
    for m in mazes:
        for e in entrants:
            try:
                e.spec(m, 0).check()
            except (RunSetupError, ValueError) as exc:
                raise EvalError(f"{e.name} on {m}: {exc}") from None
    results = _run_all(specs, what, jobs, limits, progress)
    cells = []
    for i, (m, name) in enumerate((m, n) for m in mazes for n in names):
        cells.append(_summarise(m, name, results[i * seeds : (i + 1) * seeds]))
    return EvalResult(tuple(mazes), tuple(names), seeds, tuple(cells))


def _run_all(
    specs: list[RunSpec],
    what: list[str],
    jobs: int,
    limits: Limits,
    progress: bool | Callable[[int, int], None],
) -> list[dict[str, Any]]:
    """Each run's result, in the specs' order; an :class:`EvalError` names the first run (in
    that order) that gave none, and why."""
    report = _progress_bar(len(specs)) if progress is True else progress or None
    told = (lambda done, total, _: report(done, total)) if report else None
    try:
        outcomes = run_jobs([_job(spec) for spec in specs], WORDS, jobs, limits, told)
    finally:
        close = getattr(report, "close", None)
        if close:
            close()
    results = []
    for outcome, name in zip(outcomes, what, strict=True):
        if 0 not in outcome.results:
            why = outcome.refused.get(0) or outcome.stopped or "the run gave no result"
            raise EvalError(f"{name}: {why}")
        results.append(outcome.results[0])
    return results


def _job(spec: RunSpec) -> Job:
    """One run in a process of its own: its result, or why it cannot run."""

    def work(reply: Reply) -> None:
        try:
            result = spec.execute()
        except (RunSetupError, ValueError) as exc:  # a program's problems too (ProgramError)
            reply.refused(0, str(exc))
            return
        reply.result(0, result)

    return work


class _progress_bar:
    """A progress bar on standard error (rich), so standard output stays clean."""

    def __init__(self, total: int) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

        self._progress = Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=Console(stderr=True),
        )
        self._task = self._progress.add_task("runs", total=total)
        self._progress.start()

    def __call__(self, done: int, total: int) -> None:
        self._progress.update(self._task, completed=done)

    def close(self) -> None:
        self._progress.stop()


#: the narrow table's measures: heading, the cell of an entrant
_NARROW: tuple[tuple[str, Callable[[Cell], str]], ...] = (
    ("out", lambda c: f"{c.reached}/{c.runs}"),
    ("turn deg", lambda c: _pm(c, "turn_degrees", 0)),
    ("blocks", lambda c: _pm(c, "distance_cells", 1)),
    ("time s", lambda c: f"{c.mean['sim_time']:.1f}"),
    ("hits", lambda c: f"{c.mean['collisions']:.1f}"),
    ("touches", lambda c: f"{c.mean['touches']:.1f}"),
)
NARROW_WIDTH = 80


def format_narrow(result: EvalResult, width: int = NARROW_WIDTH) -> str:
    """Per maze: each entrant's means (± spread over the seeds), best first, in lines of at
    most ``width`` columns: the measures' columns are as wide as their figures, and a name
    longer than the room left stands on a line of its own above its figures."""
    lines = []
    cells = result.cells
    sep = "  "
    widths = [max(len(h), *(len(cell(c)) for c in cells)) for h, cell in _NARROW]
    rank_width = len(str(len(result.algorithms))) + 1
    figures = sum(widths) + len(sep) * len(widths)
    room = max(width - 2 - rank_width - figures, len("entrant"))
    name_width = min(max(len("entrant"), *(len(c.algorithm) for c in cells)), room)

    def row(rank: str, name: str, values: list[str]) -> str:
        shown = "".join(f"{sep}{v:>{w}}" for v, w in zip(values, widths, strict=True))
        return f"  {rank:<{rank_width}}{name:<{name_width}}{shown}".rstrip()

    seeds = f"{result.seeds} seed{'s' if result.seeds > 1 else ''}"
    for maze in result.mazes:
        lines.extend(wrap_line(f"{maze}  ({seeds}; mean ± spread, best first)", width))
        lines.append(row("#", "entrant", [h for h, _ in _NARROW]))
        for rank, c in enumerate(result.ranking(maze), start=1):
            values = [cell(c) for _, cell in _NARROW]
            if len(c.algorithm) > name_width:
                name = f"  {rank:<{rank_width}}{c.algorithm}"
                lines.extend(wrap_line(name, width, indent=2 + rank_width))
                lines.append(row("", "", values))
            else:
                lines.append(row(str(rank), c.algorithm, values))
        lines.append("")
    return "\n".join(lines).rstrip()


def wrap_line(text: str, width: int, indent: int = 0) -> list[str]:
    """``text`` in lines of at most ``width`` characters, the lines after the first indented
    by ``indent`` spaces (a long path is cut where the line ends)."""
    lines = [text[:width]]
    rest, room = text[width:], width - indent
    while rest:
        lines.append(" " * indent + rest[:room])
        rest = rest[room:]
    return lines


def format_table(result: EvalResult) -> str:
    """Per maze: each algorithm's means (± spread), best first, in wide lines (``--wide``)."""
    lines = []
    for maze in result.mazes:
        lines.append(f"{maze}  ({result.seeds} seed{'s' if result.seeds > 1 else ''})")
        lines.append(
            f"  {'rank':<5}{'algorithm':<26}{'out':>6}{'turning deg':>18}{'distance (blocks)':>22}"
            f"{'time s':>10}{'collisions':>12}{'touches':>9}"
        )
        for rank, c in enumerate(result.ranking(maze), start=1):
            lines.append(
                f"  {rank:<5}{c.algorithm:<26}{f'{c.reached}/{c.runs}':>6}"
                f"{_pm(c, 'turn_degrees', 0):>18}{_pm(c, 'distance_cells', 1):>22}"
                f"{c.mean['sim_time']:>10.1f}{c.mean['collisions']:>12.1f}"
                f"{c.mean['touches']:>9.1f}"
            )
        lines.append("")
    return "\n".join(lines).rstrip()


def _pm(c: Cell, key: str, digits: int) -> str:
    return f"{c.mean[key]:.{digits}f} ± {c.spread[key]:.{digits}f}"


def write_csv(path: str, result: EvalResult) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        header = ["maze", "algorithm", "rank", "runs", "reached"]
        header += [f"{k}_mean" for k in MEASURES] + [f"{k}_spread" for k in MEASURES]
        writer.writerow(header)
        for maze in result.mazes:
            for rank, c in enumerate(result.ranking(maze), start=1):
                writer.writerow(
                    [c.maze, c.algorithm, rank, c.runs, c.reached]
                    + [round(c.mean[k], 3) for k in MEASURES]
                    + [round(c.spread[k], 3) for k in MEASURES]
                )
