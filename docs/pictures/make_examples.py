"""Make the example pictures of docs/pictures.md from the bundled eRobotic maze.

    .venv/bin/python docs/pictures/make_examples.py

Three runs (right-wall, farthest-distance, first-working-solution) are recorded into a
temporary folder and drawn as the three kinds; the same workbench gives the same files, so
running this again leaves the committed pictures as they are unless the drawing changed.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))

from workbench.control.headless import AlgorithmPilot, RunSpec, run  # noqa: E402
from workbench.files.bundled import maze_path  # noqa: E402
from workbench.pictures.render import PictureSpec, save_picture  # noqa: E402
from workbench.pictures.runs import load_runs  # noqa: E402

ALGORITHMS = ("right-wall", "farthest-distance", "first-working-solution")


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        records = []
        for name in ALGORITHMS:
            record = Path(tmp) / f"{name}.jsonl"
            run(RunSpec(maze_path("erobotic"), AlgorithmPilot(name), record=str(record)))
            records.append(record)
        one = load_runs(records[:1])
        made = [
            save_picture(one, HERE / "path.svg", PictureSpec("path", at=(5.0, 40.0))),
            save_picture(one, HERE / "time.svg", PictureSpec("time")),
            save_picture(load_runs(records), HERE / "compare.svg", PictureSpec("compare")),
        ]
    for path in made:
        print(f"{path.relative_to(HERE.parent.parent)}: {path.stat().st_size:,} bytes")


if __name__ == "__main__":
    main()
