"""Run records the picture tests draw: made by the headless runner on small mazes written to a
temporary folder, so every test draws a real run."""

from __future__ import annotations

import json
from pathlib import Path

from workbench.control.headless import AlgorithmPilot, RunSpec, run

BEND = "---\nname: Bend\n---\n#######\n#S....#\n#####.#\n#E....#\n#######\n"
LOOP = "---\nname: Loop\n---\n#######\n#S....#\n#.###.#\n#.....#\n###E###\n"


def maze_file(folder: Path, text: str = BEND, name: str = "bend.txt") -> Path:
    path = folder / name
    if not path.exists():
        path.write_text(text)
    return path


def record_of(
    folder: Path,
    algorithm: str = "right-wall",
    text: str = BEND,
    name: str = "bend.txt",
    profile: str = "erobotic",
) -> Path:
    """The record of ``algorithm``'s run on the maze ``text`` (written once per folder)."""
    maze = maze_file(folder, text, name)
    record = folder / f"{Path(name).stem}-{algorithm}-{profile}.jsonl"
    if not record.exists():
        run(RunSpec(str(maze), AlgorithmPilot(algorithm), profile=profile, record=str(record)))
    return record


def bend_record(folder: Path) -> Path:
    return record_of(folder)


def lines(record: Path) -> list[dict]:
    return [json.loads(line) for line in record.read_text().splitlines() if line.strip()]


def write_lines(path: Path, objects: list[dict]) -> Path:
    path.write_text("".join(json.dumps(o) + "\n" for o in objects))
    return path
