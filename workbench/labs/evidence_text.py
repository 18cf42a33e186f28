"""An objective's saved evidence in words an instructor reads: which run it rests on, who drove
and with what program and sensors, the run's measures in blocks and the profile's own unit,
and the questions with their tries.

Evidence is the dict a check saved (:mod:`.checks`); evidence saved by older workbenches lacks
some keys (``sensors``, ``program_name``, ``tries``, ``waiting``) and is still said, with what
it has. Nothing here imports Textual: the console's screens and the gradebook both use it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from workbench.sim.profiles import PROFILES

from .checks import ExerciseProgress, ObjectiveState

#: how many hex digits of a sha256 the screens show (the gradebook keeps it whole)
SHORT_DIGEST = 12

#: each profile's unit as a length is written after a number, and its decimals
UNIT_WORDS = {"px": ("px", 0), "unit": ("units", 2)}


@dataclass(frozen=True)
class Measures:
    """The graded measures of one run, as saved in its evidence's ``metrics``."""

    reached_exit: bool
    #: seconds to the exit (or of the whole run when it did not get out)
    time: float | None
    #: blocks travelled, and the same in the profile's unit (``unit``; "" when not known)
    blocks: float | None
    distance: float | None
    unit: str
    turn_degrees: float | None
    turns: int | None
    collisions: int | None
    touches: int | None


def _number(value: object) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value)


def _whole(value: object) -> int | None:
    number = _number(value)
    return None if number is None else round(number)


def measures_of(evidence: Mapping[str, Any], profile: str = "") -> Measures | None:
    """The measures of the run ``evidence`` rests on (its ``metrics``), with lengths in the
    unit of its profile (``profile`` when the evidence names none); None: no run figures."""
    metrics = evidence.get("metrics")
    if not isinstance(metrics, Mapping):
        return None
    where = PROFILES.get(str(evidence.get("profile") or profile))
    reached = bool(metrics.get("reached_exit", evidence.get("ended") == "exit"))
    time = _number(metrics.get("exit_time")) if reached else None
    if time is None:
        time = _number(metrics.get("sim_time"))
    if time is None:
        time = _number(metrics.get("exit_time"))
    distance = _number(metrics.get("distance"))
    blocks = _number(metrics.get("distance_cells"))
    if blocks is None and distance is not None and where is not None:
        blocks = distance / where.cell  # saved before blocks were kept: the default block
    return Measures(
        reached_exit=reached,
        time=time,
        blocks=blocks,
        distance=distance,
        unit=where.unit if where is not None else "",
        turn_degrees=_number(metrics.get("turn_degrees")),
        turns=_whole(metrics.get("turns")),
        collisions=_whole(metrics.get("collisions")),
        touches=_whole(metrics.get("touches")),
    )


def length_text(value: float, unit: str) -> str:
    """A length in a profile's unit, rounded as that unit is read: ``666 px``, ``12.25 units``."""
    word, decimals = UNIT_WORDS.get(unit, (unit, 2))
    return f"{value:.{decimals}f} {word}".rstrip()


def distance_text(blocks: float | None, distance: float | None, unit: str) -> str:
    """``9.52 blocks (666 px)``; either part alone when the other is not known."""
    parts = []
    if blocks is not None:
        parts.append(f"{blocks:.2f} blocks")
    if distance is not None:
        length = length_text(distance, unit)
        parts.append(f"({length})" if parts else length)
    return " ".join(parts) or "-"


def degrees_text(value: float, unicode: bool) -> str:
    return f"{value:.0f}°" if unicode else f"{value:.0f} deg"


def _count(n: int, one: str, many: str = "") -> str:
    return f"{n} {one}" if n == 1 else f"{n} {many or one + 's'}"


def measures_text(m: Measures, unicode: bool = False) -> str:
    """The measures in one line: time, distance, turning, turns, collisions (and touches)."""
    parts = []
    if m.time is not None:
        parts.append(f"{'out in' if m.reached_exit else 'ran'} {m.time:.1f} s")
    if m.blocks is not None or m.distance is not None:
        parts.append(distance_text(m.blocks, m.distance, m.unit))
    if m.turn_degrees is not None:
        parts.append(f"turned {degrees_text(m.turn_degrees, unicode)}")
    if m.turns is not None:
        parts.append(_count(m.turns, "turn"))
    if m.collisions is not None:
        parts.append(_count(m.collisions, "collision"))
    if m.touches:
        parts.append(_count(m.touches, "touch", "touches"))
    return ", ".join(parts)


def short_digest(digest: str) -> str:
    """The first hex digits of a sha256 (with or without its ``sha256:`` prefix)."""
    return digest.removeprefix("sha256:")[:SHORT_DIGEST]


def program_of(evidence: Mapping[str, Any]) -> tuple[str, str] | None:
    """The program a run's evidence names: its sha256 and its name (the name from the driver
    when older evidence keeps no ``program_name``); None when no program file drove, or the
    one that drove is a file the workbench ships (the evidence says ``bundled``)."""
    digest = evidence.get("program_sha256")
    if not isinstance(digest, str) or not digest or evidence.get("bundled"):
        return None  # (a file the workbench ships, a built-in a lab asked for: nobody's own)
    name = evidence.get("program_name")
    if not isinstance(name, str) or not name:
        driver = str(evidence.get("driver") or "")
        name = driver.removeprefix("VIPLE program ") or "program"
    return digest.removeprefix("sha256:"), name


def program_text(evidence: Mapping[str, Any]) -> str:
    """``program wall.viple (sha256 ab12cd34ef56)``, or "" when no program file drove."""
    program = program_of(evidence)
    if program is None:
        return ""
    digest, name = program
    return f"program {name} (sha256 {short_digest(digest)})"


def _list(value: object) -> list[str]:
    if isinstance(value, list | tuple):
        return [str(v) for v in value]
    return []


# -- the lines of one objective's evidence --------------------------------------------------
def run_lines(evidence: Mapping[str, Any], profile: str = "", unicode: bool = False) -> list[str]:
    """A run's evidence: the run, its driver and who sat at the station, the program and the
    sensors it used, and its measures."""
    by = evidence.get("person")
    at = f" ({by} at the station)" if by and by not in str(evidence.get("driver", "")) else ""
    where = evidence.get("maze") or "-"
    lines = [
        f"run {evidence.get('run', '?')} by {evidence.get('driver') or '?'}{at} on {where} "
        f"({evidence.get('profile') or profile or '?'}), ended by {evidence.get('ended') or '?'}"
    ]
    used = [program_text(evidence)]
    if "sensors" in evidence:
        used.append(f"sensors {', '.join(_list(evidence['sensors'])) or 'none'}")
    used = [part for part in used if part]
    if used:
        lines.append("; ".join(used))
    m = measures_of(evidence, profile)
    if m is not None:
        lines.append(measures_text(m, unicode))
    return lines


def _questions(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    line = f"{evidence.get('correct', '?')} of {evidence.get('of', '?')} right"
    tries = evidence.get("tries")
    lines = [line]
    if isinstance(tries, Mapping) and tries:
        lines[0] += "; tries: " + ", ".join(f"{q} {n}" for q, n in tries.items())
    waiting = _list(evidence.get("waiting"))
    if waiting:
        lines.append(f"waiting for you (no tries left): {', '.join(waiting)}")
    return lines


def _keys(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    if evidence.get("role"):
        motions = ", ".join(_list(evidence.get("motions"))) or "-"
        return [f"VIPLE {evidence['role']} program at {evidence.get('peer') or '?'} asked for "
                f"{motions}"]  # fmt: skip
    people = _list(evidence.get("people"))
    by = f" by {', '.join(people)}" if people else ""
    return [f"keys used{by}: {', '.join(_list(evidence.get('keys_used'))) or '-'}"]


def _sensors(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    if "run" in evidence:
        return run_lines(evidence, profile, unicode)
    by = f" ({evidence['person']} at the station)" if evidence.get("person") else ""
    return [f"sensors set{by}: {', '.join(_list(evidence.get('sensors'))) or 'none'}"]


def _viple(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    where = PROFILES.get(profile)
    distance = _number(evidence.get("distance"))
    turned = _number(evidence.get("turn_degrees"))
    parts = [f"VIPLE {evidence.get('role', '?')} program at {evidence.get('peer') or '?'}"]
    if distance is not None:
        blocks = distance / where.cell if where is not None else None
        parts.append(f"drove {distance_text(blocks, distance, where.unit if where else '')}")
    if turned is not None:
        parts.append(f"turned {degrees_text(turned, unicode)}")
    return [", ".join(parts)]


def _edited(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    by = f" by {evidence['person']}" if evidence.get("person") else ""
    layout = str(evidence.get("maze_digest") or "")
    shown = f" (layout {short_digest(layout)})" if layout else ""
    return [f"edit {evidence.get('edit', '?')}{by} left the maze {evidence.get('maze')!r}{shown}"]


def _compare(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    lines = []
    rows = evidence.get("runs")
    for row in rows if isinstance(rows, list) else []:
        if not isinstance(row, Mapping):
            continue
        m = measures_of(row, profile)
        figures = f": {measures_text(m, unicode)}" if m is not None else ""
        sensors = f" with {', '.join(_list(row['sensors']))}" if "sensors" in row else ""
        lines.append(
            f"{row.get('algorithm', '?')} run {row.get('run', '?')} on {row.get('maze') or '-'}"
            f"{sensors}{figures}"
        )
    return lines


#: the keys a reader never needs spelt out (digests and ids the record keeps)
QUIET_KEYS = frozenset({"attempt", "record", "record_sha256", "maze_digest", "original_digest"})


def _other(evidence: Mapping[str, Any], profile: str, unicode: bool) -> list[str]:
    parts = []
    for key, value in sorted(evidence.items()):
        if key in QUIET_KEYS or value in (None, "", [], {}):
            continue
        text = ", ".join(map(str, value)) if isinstance(value, list) else str(value)
        parts.append(f"{key.replace('_', ' ')} {text}")
    return ["; ".join(parts)] if parts else []


Wording = Callable[[Mapping[str, Any], str, bool], list[str]]

#: how each kind of objective's evidence is said
BY_KIND: dict[str, Wording] = {
    "exit": lambda e, p, u: run_lines(e, p, u),
    "sensors": _sensors,
    "questions": _questions,
    "keys": _keys,
    "viple": _viple,
    "maze-edited": _edited,
    "compare": _compare,
}


def evidence_lines(state: ObjectiveState, profile: str = "", unicode: bool = False) -> list[str]:
    """What ``state``'s evidence says, a few lines ("" parts left out); [] without evidence.
    ``profile`` is the exercise's, for evidence that names none."""
    evidence = state.evidence
    if not isinstance(evidence, Mapping) or not evidence:
        return []
    if "run" in evidence and "metrics" in evidence:
        lines = run_lines(evidence, profile, unicode)
        if state.kind == "fsm-behaviour":
            lines += _behaved(evidence)
    else:
        lines = BY_KIND.get(state.kind, _other)(evidence, profile, unicode)
    # saved evidence may hold any text (an edited store, a key with a line break in it):
    # each line said stays one line
    return [" ".join(line.splitlines()) for line in lines]


def _behaved(evidence: Mapping[str, Any]) -> list[str]:
    """An ``fsm-behaviour`` pass: what the run's machine was compared with, and where."""
    given = evidence.get("trials")
    trials = [t for t in given if isinstance(t, Mapping)] if isinstance(given, list) else []
    where = ", ".join(
        f"{t.get('maze', '?')}" + (f" seed {t['seed']}" if t.get("seed") else "") for t in trials
    )
    return [
        f"behaved as {evidence.get('reference', '?')}: {evidence.get('compared', '?')} moves "
        f"and turns alike on {where or '-'}"
    ]


# -- the programs an exercise's evidence rests on ------------------------------------------
def programs_of(
    progress: ExerciseProgress, bundled: frozenset[str] = frozenset()
) -> dict[str, str]:
    """The programs the passed objectives of ``progress`` rest on: sha256 to name. Bundled
    files (``bundled``: the built-in algorithms a ``compare`` runs, say) are not the student's
    program and are left out; more than one entry means the evidence mixes programs."""
    found: dict[str, str] = {}
    for state in progress.objectives:
        if not state.passed or not isinstance(state.evidence, Mapping):
            continue
        program = program_of(state.evidence)
        if program is not None and program[0] not in bundled:
            found.setdefault(*program)
    return found


def mixed_programs_text(programs: Mapping[str, str]) -> str:
    """The line that warns of evidence resting on several programs ("" for one or none)."""
    if len(programs) < 2:
        return ""
    named = ", ".join(f"{name} ({short_digest(d)})" for d, name in sorted(programs.items()))
    return f"the evidence mixes {len(programs)} programs: {named}"


def lines_of_progress(
    progress: ExerciseProgress,
    profile: str,
    unicode: bool,
    marks: Sequence[str] = ("[X]", "[ ]"),
) -> list[str]:
    """Every objective of ``progress``: its mark, text and reason, then its evidence indented
    (a run said once: the objectives after it that rest on the same run say so)."""
    passed, failed = marks
    lines = []
    said: set[tuple[str, str]] = set()
    for state in progress.objectives:
        lines.append(f"{passed if state.passed else failed} {state.text}: {state.reason}")
        evidence = state.evidence if isinstance(state.evidence, Mapping) else {}
        run = (str(evidence.get("attempt", "")), str(evidence.get("run", "")))
        if "run" in evidence and "metrics" in evidence and run in said:
            lines.append(f"    on run {run[1]}, as above")
            continue
        if "run" in evidence and "metrics" in evidence:
            said.add(run)
        lines += [f"    {line}" for line in evidence_lines(state, profile, unicode)]
    return lines
