"""The kinds of picture by name, a picture as bytes, and a picture saved whole.

The same records give the same bytes: the SVG's ids come from a fixed salt and neither file
holds a date or the drawing software's name. A picture is drawn in full in memory and then
written through the one atomic writer (``files/atomic.py``, or the workspace's rules where the
app saves), so a failure leaves no half-written file. matplotlib (its Agg backend, no window)
is imported only here, when a picture is drawn.
"""

from __future__ import annotations

import io
import os
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.files.atomic import write_bytes_atomic
from workbench.files.terminal import terminal_safe
from workbench.files.workspace import LOCAL, FileAccess, OutsideWorkspace

from . import KIND_NAMES
from .draw_compare import draw_compare_figure
from .draw_maze import draw_path_figure
from .draw_time import draw_time_figure
from .runs import PictureError, PictureRun

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: the file formats, by the output file's suffix
FORMATS = {".svg": "svg", ".png": "png"}
#: the largest picture drawn, in pixels a side
MAX_SIDE = 4000
MIN_SIDE = 200
#: the salt of the SVG's ids, so that the same picture has the same ids
HASH_SALT = "workbench-picture"


@dataclass(frozen=True)
class Kind:
    """One kind of picture: how many runs it takes, its default size and how it is drawn."""

    name: str
    what: str
    size: Callable[[Sequence[PictureRun]], tuple[int, int]]
    draw: Callable[[Figure, Sequence[PictureRun], Sequence[float]], None]
    one_run: bool = True
    #: lines may leave out points that add nothing at the picture's resolution (a long run's
    #: readings and small paths); False keeps every recorded point (the path picture's)
    simplify: bool = False


def _path(fig: Figure, runs: Sequence[PictureRun], at: Sequence[float]) -> None:
    draw_path_figure(fig, runs[0], at)


def _time(fig: Figure, runs: Sequence[PictureRun], at: Sequence[float]) -> None:
    draw_time_figure(fig, runs[0])


def _compare(fig: Figure, runs: Sequence[PictureRun], at: Sequence[float]) -> None:
    draw_compare_figure(fig, runs)


def _maze_size(runs: Sequence[PictureRun]) -> tuple[int, int]:
    """1000 pixels wide, as high as the maze's shape asks (with room for the caption)."""
    maze = runs[0].maze
    tall = maze.height / max(1, maze.width)
    return 1000, max(600, min(2400, round(820 * tall) + 320))


def _compare_size(runs: Sequence[PictureRun]) -> tuple[int, int]:
    maze = runs[0].maze
    rows = -(-len(runs) // 4)
    per_row = round(350 * min(2.0, maze.height / max(1, maze.width))) + 60
    return 1400, max(600, min(3600, rows * per_row + 420))


KINDS: dict[str, Kind] = {
    k.name: k
    for k in (
        Kind("path", "the run's path on its maze", _maze_size, _path),
        Kind(
            "time",
            "the sensors, wheel powers and states over time",
            lambda runs: (1200, 900),
            _time,
            simplify=True,
        ),
        Kind(
            "compare", "several runs on one maze side by side", _compare_size, _compare, False, True
        ),
    )
}


assert tuple(KINDS) == KIND_NAMES


@dataclass(frozen=True)
class PictureSpec:
    """What to draw: the kind, the file format, the size in pixels and the beams' moments."""

    kind: str = "path"
    fmt: str = "svg"
    size: tuple[int, int] | None = None
    at: tuple[float, ...] = field(default=())

    def check(self) -> None:
        if self.kind not in KINDS:
            raise PictureError(f"unknown kind {self.kind!r}: use one of {', '.join(KINDS)}")
        if self.fmt not in FORMATS.values():
            raise PictureError(f"unknown format {self.fmt!r}: use .svg or .png")
        if self.size is not None:
            w, h = self.size
            if not (MIN_SIDE <= w <= MAX_SIDE and MIN_SIDE <= h <= MAX_SIDE):
                raise PictureError(
                    f"a picture of {w}x{h} pixels: give each side from {MIN_SIDE} to {MAX_SIDE}"
                )


def format_for(path: str | os.PathLike) -> str:
    """The format a file name asks for (``.svg`` or ``.png``), or :class:`PictureError`."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise PictureError(
            f"{terminal_safe(os.fspath(path))}: a picture is saved as .svg or .png: end the "
            "file name with one of them"
        )
    return FORMATS[suffix]


_LOCK = threading.Lock()  # matplotlib's settings are global: one picture at a time


def render(runs: Sequence[PictureRun], spec: PictureSpec) -> bytes:
    """The picture as the bytes of its file (the same runs and spec give the same bytes)."""
    spec.check()
    kind = KINDS[spec.kind]
    if not runs:
        raise PictureError("no run to draw")
    if kind.one_run and len(runs) > 1:
        raise PictureError(
            f"a {kind.name} picture shows one run and {len(runs)} were given: give one "
            "record, or --kind compare for several"
        )
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    width, height = spec.size or kind.size(runs)
    settings: dict[str, Any] = {
        "svg.hashsalt": HASH_SALT,
        "svg.fonttype": "none",
        "text.parse_math": False,
        "path.simplify": kind.simplify,
        "font.family": "DejaVu Sans",
        "figure.dpi": 100,
        "savefig.dpi": 100,
    }
    with _LOCK, matplotlib.rc_context(settings):  # type: ignore[arg-type]
        fig = Figure(figsize=(width / 100, height / 100), dpi=100, layout="constrained")
        FigureCanvasAgg(fig)
        kind.draw(fig, runs, spec.at)
        out = io.BytesIO()
        metadata: dict[str, str | None] = (
            {"Date": None, "Creator": None} if spec.fmt == "svg" else {"Software": None}
        )
        fig.savefig(out, format=spec.fmt, dpi=100, metadata=metadata)
    return out.getvalue()


def save_picture(
    runs: Sequence[PictureRun],
    target: str | os.PathLike,
    spec: PictureSpec | None = None,
    files: FileAccess = LOCAL,
) -> Path:
    """Draw the picture and write it whole at ``target`` (its format from the suffix when no
    spec gives one), within ``files``' rules; the path written is returned."""
    fmt = format_for(target)
    spec = PictureSpec(fmt=fmt) if spec is None else PictureSpec(spec.kind, fmt, spec.size, spec.at)
    data = render(runs, spec)
    shown = terminal_safe(files.shown(target))
    try:
        if files.confined:
            return files.write_bytes(target, data)
        path = files.for_writing(target)
        write_bytes_atomic(path, data)
        return path
    except OutsideWorkspace as exc:
        raise PictureError(str(exc)) from None
    except FileNotFoundError:
        raise PictureError(
            f"{shown}: its folder does not exist: make the folder, or save elsewhere"
        ) from None
    except OSError as exc:
        raise PictureError(
            f"{shown}: cannot write it ({exc.strerror}): save it in a folder you can write to"
        ) from None
