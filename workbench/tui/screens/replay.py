"""The replay screen: a recorded run (JSONL) drawn tick by tick, stepped or played at a speed.

The cursor over the record is :class:`~workbench.sim.replay.Replay`; this screen draws its
current tick (the robot on the maze, its sensor readings, the state and the events) and turns
keys into steps, jumps and play/pause. Playing uses a timer only while it plays, fed with the
real time elapsed, so a replay at 1x takes as long as the run did.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from time import monotonic
from typing import ClassVar

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.timer import Timer
from textual.widgets import Static

from workbench.files.workspace import LOCAL, FileAccess
from workbench.sim.maze import Maze
from workbench.sim.replay import Replay, load_replay, replay_maze
from workbench.sim.sensor_kinds import sensor_kind

from ..host import FollowsUnicode, ToggleUnicode
from ..keys import REPLAY_KEY_IDS, REPLAY_LEGEND, bindings, legend_text
from ..picture_saving import save_picture_off_the_loop
from ..serving.single_layout import SingleLayout
from ..widgets.key_bar import KeyBar
from ..widgets.maze_view import MazeView
from ..widgets.text import count

#: how often the view is redrawn while playing (frames per second of wall time)
PLAY_HZ = 20
#: transition log lines shown before the screen has its size
LOG_LINES = 8


def _number(value: object) -> str:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return str(value)
    if isinstance(value, int):
        return str(value)
    return f"{value:.1f}"


def _command(cmd: object) -> str:
    if not isinstance(cmd, dict) or len(cmd) != 1:
        return str(cmd)
    ((name, value),) = cmd.items()
    if name == "stop":
        return "stop"
    if name == "wheels" and isinstance(value, list):
        return "wheels " + " ".join(_number(v) for v in value)
    if name == "motor" and isinstance(value, dict):
        return f"motor {value.get('wheel')} {_number(value.get('power'))}"
    return f"{name} {_number(value)}"


class ReplayScreen(FollowsUnicode, SingleLayout, Screen[None]):
    """Step through or play a recorded run; escape goes back."""

    AUTO_FOCUS = ""

    DEFAULT_CSS = """
    ReplayScreen #replay-title {
        height: 1;
        padding: 0 1;
        background: $boost;
        text-style: bold;
    }
    ReplayScreen #replay-note {
        height: auto;
        padding: 0 1;
        color: $text-warning;
    }
    ReplayScreen #replay-note.-empty, ReplayScreen #replay-said.-empty {
        display: none;
    }
    ReplayScreen #replay-said {
        height: auto;
        padding: 0 1;
        color: $text-muted;
    }
    ReplayScreen #replay-said.-error {
        color: $text-error;
    }
    ReplayScreen #replay-body {
        height: 1fr;
    }
    ReplayScreen #replay-maze, ReplayScreen #replay-nomaze {
        width: 1fr;
        height: 1fr;
    }
    ReplayScreen #replay-nomaze {
        padding: 1 2;
        color: $text-muted;
    }
    ReplayScreen #replay-side {
        width: 34;
        height: 1fr;
        padding: 0 1;
        border-left: vkey $panel;
    }
    ReplayScreen #replay-tick {
        height: 12;
    }
    ReplayScreen #replay-log {
        height: 1fr;
        margin-top: 1;
        color: $text-muted;
        text-wrap: nowrap;
        text-overflow: ellipsis;
    }
    ReplayScreen #replay-keys {
        height: auto;
        color: $text-muted;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*REPLAY_KEY_IDS)]

    def __init__(
        self,
        record_path: str | os.PathLike,
        replay: Replay | None = None,
        mazes: Sequence[Maze] = (),
        unicode: bool = False,
        *,
        files: FileAccess = LOCAL,
        name: str | None = None,
        id: str | None = None,
        classes: str | None = None,
    ) -> None:
        """``replay`` is the record already loaded (else it is loaded here and a malformed
        record raises :class:`~workbench.sim.record.RecordError`); ``mazes`` are mazes the run
        may have been on (the station's), found again by their layout digest; a maze file named
        by the record is read only where ``files`` allows."""
        super().__init__(name=name, id=id, classes=classes)
        self.record_path = os.fspath(record_path)
        self.replay = replay if replay is not None else load_replay(record_path)
        self.maze, self.note = replay_maze(self.replay, record_path, mazes, files)
        self.files = files
        #: the last message about a picture (what was saved where, or why not)
        self.said = ""
        self._unicode = unicode
        self._timer: Timer | None = None
        self._last_time = 0.0
        self._drawn = -1

    def compose(self) -> ComposeResult:
        yield Static(id="replay-title", markup=False)
        yield Static(
            self.note, id="replay-note", markup=False, classes="" if self.note else "-empty"
        )
        yield Static(id="replay-said", markup=False, classes="-empty")
        with Horizontal(id="replay-body"):
            if self.maze is not None:
                yield MazeView(self.maze, unicode=self._unicode, id="replay-maze")
            else:
                yield Static(
                    "The maze cannot be drawn; the recorded ticks are on the right.",
                    id="replay-nomaze",
                    markup=False,
                )
            with Vertical(id="replay-side"):
                yield Static(id="replay-tick", markup=False)
                yield Static(id="replay-log", markup=False)
                yield Static(legend_text(REPLAY_LEGEND), id="replay-keys", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        self._draw()

    def on_resize(self) -> None:
        self.call_after_refresh(self._draw_panel)

    # -- public ------------------------------------------------------------------------------
    @property
    def unicode(self) -> bool:
        return self._unicode

    def set_unicode(self, unicode: bool) -> None:
        self._unicode = unicode
        if self.is_mounted and self.maze is not None:
            self.query_one(MazeView).set_unicode(unicode)
            self._draw_panel()

    # -- pictures ----------------------------------------------------------------------------
    def action_picture(self, kind: str) -> None:
        """Save the run's picture (``path``: with the beams at this tick; ``time``), drawn in
        a thread."""
        save_picture_off_the_loop(
            self,
            [self.record_path],
            kind,
            self.files,
            self._say,
            what="this run",
            at=(self.replay.frame().t,) if kind == "path" else (),
            known=(self.maze,) if self.maze is not None else (),
        )

    def _say(self, text: str, error: bool = False) -> None:
        self.said = text
        line = self.query_one("#replay-said", Static)
        line.update(text)
        line.set_class(not text, "-empty")
        line.set_class(error, "-error")

    # -- drawing -------------------------------------------------------------------------------
    def _draw(self) -> None:
        self._draw_view()
        self._draw_panel()

    def _draw_view(self) -> None:
        replay = self.replay
        index = replay.index
        if self.maze is None or index == self._drawn:
            return
        view = self.query_one(MazeView)
        cell = replay.cell
        if index < self._drawn or self._drawn < 0:
            view.hide_robot()
            view.clear_trail()
            first = 0
        else:
            first = self._drawn + 1
        current = replay.snapshot(index)
        last_block = None
        for i in range(first, index):
            pose = replay.poses[i]
            block = (int(pose.x // cell), int(pose.y // cell))
            if block != last_block:
                last_block = block
                view.show(replace(current, pose=pose, block=block, sensors=(), readings={}), cell)
        view.show(current, cell)
        self._drawn = index

    def _draw_panel(self) -> None:
        replay = self.replay
        frame = replay.frame()
        state = "playing" if replay.playing else "paused"
        self.query_one("#replay-title", Static).update(
            f"Replay: {replay.title}  [{os.path.basename(self.record_path)}]"
        )
        deg = "°" if self.unicode else " deg"
        text = Text()
        text.append(f"Tick {frame.index + 1}/{len(replay)}", style="bold")
        text.append(f"  t {frame.t:.2f} s\n")
        text.append(f"{state} at {replay.speed:g}x\n")
        x, y, heading = frame.pose
        text.append(f"Pose {x:.1f}, {y:.1f}  {heading:.0f}{deg}\n")
        text.append("State ", style="bold")
        text.append(f"{frame.state or '-'}\n")
        sensors = {s.port: s for s in replay.sensors}
        for port, value in sorted(frame.sensors.items()):
            spec = sensors.get(port)
            what = f"{spec.kind} {spec.mount}" if spec else "sensor"
            word = sensor_kind(spec.kind).panel.state(value) if spec else None
            shown = value if word is None else word
            text.append(f"port {port} {what}: {_number(shown)}\n")
        if frame.commands:
            text.append(f"Cmd {', '.join(_command(c) for c in frame.commands)}\n")
        if frame.events:
            text.append(f"Events {', '.join(frame.events)}\n", style="bold")
        m = replay.metrics()
        text.append(
            f"So far {m.distance_cells:.2f} blocks, {m.turn_degrees:.0f}{deg}\n"
            f"{count(m.turns, 'turn')}, {count(m.collisions, 'collision')}"
        )
        if m.touches:
            # bumps a touch sensor was meant to feel, apart from the collisions
            text.append(f",\n{count(m.touches, 'touch', 'touches')} (touch sensor)")
        if replay.at_end and replay.summary is not None:
            s = replay.summary
            ended = s.get("ended", "stopped")
            out = "out through the exit" if s.get("reached_exit") else f"{ended}, not out"
            text.append(f"\nEnd: {out}", style="bold")
        self.query_one("#replay-tick", Static).update(text)
        log_view = self.query_one("#replay-log", Static)
        height = log_view.size.height
        log = replay.log(height if height > 0 else LOG_LINES)
        lines = [line.strip() for line in log] or ["no state changes yet"]
        log_view.update("\n".join(lines))

    # -- actions ------------------------------------------------------------------------------
    def action_step(self, ticks: int) -> None:
        self.replay.step(ticks)
        self._stop_timer()
        self._draw()

    def action_first(self) -> None:
        self.replay.to_start()
        self._stop_timer()
        self._draw()

    def action_last(self) -> None:
        self.replay.to_end()
        self._stop_timer()
        self._draw()

    def action_play(self) -> None:
        if self.replay.toggle():
            self._last_time = monotonic()
            if self._timer is None:
                self._timer = self.set_interval(1 / PLAY_HZ, self._tick)
            else:
                self._timer.resume()
        else:
            self._stop_timer()
        self._draw()

    def action_faster(self) -> None:
        self.replay.faster()
        self._draw_panel()

    def action_slower(self) -> None:
        self.replay.slower()
        self._draw_panel()

    def _tick(self) -> None:
        now = monotonic()
        elapsed, self._last_time = now - self._last_time, now
        self.replay.advance(elapsed)
        if not self.replay.playing:
            self._stop_timer()
        self._draw()

    def _stop_timer(self) -> None:
        if self._timer is not None:
            self._timer.pause()

    def action_unicode(self) -> None:
        self.post_message(ToggleUnicode())

    def action_leave(self) -> None:
        self._stop_timer()
        if len(self.app.screen_stack) > 1 and self.app.screen is self:
            self.dismiss(None)
        else:
            self.app.exit()

    def on_unmount(self) -> None:
        if self._timer is not None:
            self._timer.stop()
