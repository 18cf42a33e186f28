"""The maze view: a block maze drawn with Textual's Line API, two terminal columns per block.

Layers, bottom to top: the maze itself (walls, floor, exits, start), the trail of blocks the
robot has been in, the sensors (dotted distance rays over floor blocks, the wall block a ray
ends on marked with the sensor's port number, pressed touch sensors marked on the block they
touch), the robot (a heading arrow), and the editor cursor.

Each maze row is rendered once into a :class:`~textual.strip.Strip` and kept until something
on that row changes; an update re-renders and refreshes only the changed span of the changed
rows, so a robot moving at 20 Hz costs about 1-3 KB a second on an 80x24 terminal instead of
the ~150 KB a whole-widget repaint costs (``bench/tui_render.py`` measures both).

The widget only draws and routes input: it never runs the simulation. The host calls
:meth:`MazeView.show` with a session snapshot, :meth:`MazeView.set_maze` after an edit and
:meth:`MazeView.set_cursor` to move the editor cursor; a click on a block posts
:class:`MazeView.BlockClicked`. The widget does not take focus, so arrow keys stay with the
screen (the editor binds them); the mouse wheel and scrollbars scroll it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import ClassVar

from rich.segment import Segment
from rich.style import Style
from textual import events
from textual.geometry import Region, Size
from textual.message import Message
from textual.scroll_view import ScrollView
from textual.scrollbar import ScrollDown, ScrollLeft, ScrollRight, ScrollTo, ScrollUp
from textual.strip import Strip
from textual.visual import VisualType

from workbench.sim.maze import WALL, Cell, Maze
from workbench.sim.mazeview import ARROWS_ASCII, ARROWS_UNICODE, block_text
from workbench.sim.sensor_kinds import sensor_kind
from workbench.sim.sensors import MOUNT_ANGLES
from workbench.sim.session import Snapshot

from .plain_lines import plain_lines, plain_styles

#: what one block shows: its two cells of text and the name of its style
Token = tuple[str, str]

#: robot glyphs by heading, one per 45 degrees from 0 = right, clockwise (y grows down)
ROBOT_UNICODE = (
    ARROWS_UNICODE["right"],
    "◢",
    ARROWS_UNICODE["down"],
    "◣",
    ARROWS_UNICODE["left"],
    "◤",
    ARROWS_UNICODE["up"],
    "◥",
)
ROBOT_ASCII = (
    ARROWS_ASCII["right"],
    ARROWS_ASCII["down"],
    ARROWS_ASCII["left"],
    ARROWS_ASCII["up"],
)
#: ray glyphs by direction modulo 180 degrees in steps of 45: -, \, |, /
RAY_ASCII = (": ", ": ", ": ", ": ")
RAY_UNICODE = ("┄┄", "⋱ ", "┆ ", "⋰ ")
#: the start block: an S and the start heading, apart from the robot's own arrow
START_ASCII = {"up": "S^", "right": "S>", "down": "Sv", "left": "S<"}
START_UNICODE = {"up": "S▴", "right": "S▸", "down": "S▾", "left": "S◂"}
TRAIL_ASCII = ". "
TRAIL_UNICODE = "· "
#: unit steps for 0, 90, 180, 270 degrees (right, down, left, up on the screen)
_QUARTER_STEPS: tuple[Cell, ...] = ((1, 0), (0, 1), (-1, 0), (0, -1))
#: how far beyond the reading (in blocks) a ray still counts as ending on a wall: the
#: sensor sits up to half a block from the robot's centre, plus room for sensor noise
_RAY_SLACK = 0.6

STYLE_NAMES = ("wall", "floor", "exit", "start", "trail", "ray", "hit", "touch", "robot", "cursor")


def robot_glyph(heading: float, unicode: bool) -> str:
    """The arrow for a heading in degrees (0 = right, clockwise): 8 directions in Unicode, 4 in
    ASCII."""
    if unicode:
        return ROBOT_UNICODE[round(heading / 45.0) % 8]
    return ROBOT_ASCII[round(heading / 90.0) % 4]


class MazeView(ScrollView, can_focus=False):
    """A scrolling picture of a maze with the robot, its sensors and its trail."""

    DEFAULT_CSS = """
    MazeView {
        background: $surface;
        scrollbar-size: 1 1;
    }
    MazeView > .maze-view--wall {
        color: $foreground-muted;
    }
    MazeView > .maze-view--floor {
    }
    MazeView > .maze-view--exit {
        color: $text-success;
        text-style: bold;
    }
    MazeView > .maze-view--start {
        color: $text-accent;
    }
    MazeView > .maze-view--trail {
        color: $text-primary;
    }
    MazeView > .maze-view--ray {
        color: $text-warning;
    }
    MazeView > .maze-view--hit {
        color: $background;
        background: $warning;
        text-style: bold;
    }
    MazeView > .maze-view--touch {
        color: $background;
        background: $error;
        text-style: bold;
    }
    MazeView > .maze-view--robot {
        color: $background;
        background: $foreground;
        text-style: bold;
    }
    MazeView > .maze-view--cursor {
        text-style: reverse bold;
    }
    """

    COMPONENT_CLASSES: ClassVar[set[str]] = {f"maze-view--{name}" for name in STYLE_NAMES}

    class BlockClicked(Message):
        """A block of the maze was clicked."""

        def __init__(self, maze_view: MazeView, cell: Cell) -> None:
            self.maze_view = maze_view
            self.cell = cell
            super().__init__()

        @property
        def control(self) -> MazeView:
            return self.maze_view

    def __init__(
        self,
        maze: Maze,
        unicode: bool = False,
        trail: bool = True,
        follow: bool = True,
        *,
        name: str | None = None,
        id: str | None = None,
        classes: str | None = None,
        disabled: bool = False,
    ) -> None:
        super().__init__(name=name, id=id, classes=classes, disabled=disabled)
        self._maze = maze
        self._unicode = unicode
        self._show_trail = trail
        self._follow = follow
        #: the user scrolled by hand: stop following until follow is set again
        self._detached = False
        self._cursor: Cell | None = None
        self._robot: Cell | None = None
        self._last_show: tuple[Snapshot, float] | None = None
        #: what the robot and its sensors were last drawn from (a show with the same is skipped)
        self._shown: tuple[object, ...] | None = None
        self._trail: set[Cell] = set()
        #: the simulated time last shown: time going back means the robot started over
        self._last_time: float | None = None
        self._sprites: dict[Cell, Token] = {}
        self._sprite_rows: dict[int, dict[int, Token]] = {}
        self._base_rows: list[list[Token] | None] = [None] * maze.height
        self._strips: list[Strip | None] = [None] * maze.height
        self._styles: dict[str, Style] = {}
        self._tooltip_text = ""
        #: the readings changed since the tooltip was last worded (it is worded when read)
        self._tooltip_stale = False
        #: what the view last scrolled to follow: the robot's block and the view's sizes
        self._followed: tuple[object, ...] | None = None
        #: how many row strips have been rendered since the widget was made (for tests/stations)
        self.strips_built = 0

    # -- public API ----------------------------------------------------------------------
    @property
    def maze(self) -> Maze:
        return self._maze

    @property
    def unicode(self) -> bool:
        return self._unicode

    @property
    def trail(self) -> bool:
        return self._show_trail

    @property
    def follow(self) -> bool:
        return self._follow

    @property
    def cursor(self) -> Cell | None:
        return self._cursor

    @property
    def robot_cell(self) -> Cell | None:
        """The block the robot is drawn in, or None when no robot is shown."""
        return self._robot

    def set_maze(self, maze: Maze) -> None:
        """Show ``maze`` (typically an edit of the current one); only changed rows repaint."""
        old = self._maze
        self._maze = maze
        self._shown = None
        if (old.width, old.height) != (maze.width, maze.height):
            self._base_rows = [None] * maze.height
            self._strips = [None] * maze.height
            self._trail = {c for c in self._trail if maze.in_bounds(*c)}
            self._set_sprites({c: t for c, t in self._sprites.items() if maze.in_bounds(*c)})
            if self._cursor is not None and not maze.in_bounds(*self._cursor):
                self._cursor = None
            if self._robot is not None and not maze.in_bounds(*self._robot):
                self._robot = None
            self.virtual_size = Size(2 * maze.width, maze.height)
            self.refresh()
            return
        rows = {y for y in range(maze.height) if old.rows[y] != maze.rows[y]}
        marks = {old.start, maze.start, *old.exits, *maze.exits}
        if old.start != maze.start or old.heading != maze.heading or old.exits != maze.exits:
            rows.update(c[1] for c in marks if c is not None)
        reach = 2 if self._unicode else 0
        affected = {
            r for y in rows for r in range(y - reach, y + reach + 1) if 0 <= r < maze.height
        }
        spans: dict[int, tuple[int, int]] = {}
        for y in sorted(affected):
            before = self._base_rows[y]
            if before is None:
                self._strips[y] = None
                continue
            after = self._make_base_row(y)
            self._base_rows[y] = after
            changed = [x for x, (a, b) in enumerate(zip(before, after, strict=True)) if a != b]
            if changed:
                spans[y] = (changed[0], changed[-1])
        if self._last_show is not None and self._robot is not None:
            snapshot, cell_size = self._last_show
            moved = self._set_sprites(self._sensor_sprites(snapshot, cell_size, self._robot))
            for y, (x0, x1) in self._spans(moved).items():
                span = spans.get(y)
                spans[y] = (x0, x1) if span is None else (min(span[0], x0), max(span[1], x1))
        self._apply(spans)

    def show(self, snapshot: Snapshot, cell_size: float) -> bool:
        """Draw the robot, its sensors and its trail from a session snapshot; returns whether
        a cell of the view changed (it is redrawn in the screen's next update).

        ``cell_size`` is the block size in world units (``world.cell``), to turn the pose into
        blocks.
        """
        self._last_show = (snapshot, cell_size)
        shown = (snapshot.pose, snapshot.readings, snapshot.sensors, cell_size)
        if shown == self._shown:
            return False  # the robot and its sensors are drawn as they are now
        self._shown = shown
        if self._last_time is not None and snapshot.time < self._last_time:
            self._forget_trail()  # the robot started over: a reset, a new maze, a new run
        self._last_time = snapshot.time
        maze = self._maze
        pose = snapshot.pose
        bx = min(max(math.floor(pose.x / cell_size), 0), max(maze.width - 1, 0))
        by = min(max(math.floor(pose.y / cell_size), 0), max(maze.height - 1, 0))
        robot = (bx, by)
        changed = self._set_sprites(self._sensor_sprites(snapshot, cell_size, robot))
        self._robot = robot
        if robot not in self._trail:
            self._trail.add(robot)
            if self._show_trail:
                changed.add(robot)
        spans = self._spans(changed)
        self._apply(spans)
        # (the widget's outer size and raw scroll: read every tick, the cheapest that change)
        followed = (robot, self.outer_size, self.virtual_size, self.scroll_x, self.scroll_y)
        moved = followed != self._followed
        if moved:
            # the robot changed blocks, or the view its size or scroll: follow it (within a
            # block the view would not scroll)
            self._followed = followed
            self._follow_robot()
        # the tooltip is worded when it is read, live only while the mouse rests on the view
        self._tooltip_stale = True
        if self.mouse_hover:
            self._update_tooltip(snapshot)
        return bool(spans) or moved

    def hide_robot(self) -> None:
        """Stop drawing the robot and its sensors (the trail stays until cleared)."""
        self._last_show = None
        self._shown = None
        self._robot = None
        self._apply(self._spans(self._set_sprites({})))

    def set_unicode(self, unicode: bool) -> None:
        """Draw with box-drawing outlines and Unicode arrows (True) or pure ASCII (False)."""
        if unicode == self._unicode:
            return
        self._unicode = unicode
        self._base_rows = [None] * self._maze.height
        self._strips = [None] * self._maze.height
        if self._last_show is not None:
            snapshot, cell_size = self._last_show
            robot = self._robot or (0, 0)
            self._set_sprites(self._sensor_sprites(snapshot, cell_size, robot))
        self.refresh()

    def set_trail(self, trail: bool) -> None:
        """Show (True) or hide (False) the blocks the robot has driven through."""
        if trail == self._show_trail:
            return
        self._show_trail = trail
        self._apply(self._spans(self._trail))

    def _forget_trail(self) -> None:
        gone, self._trail = self._trail, set()
        if self._show_trail:
            self._apply(self._spans(gone))

    def clear_trail(self) -> None:
        """Forget the blocks driven so far (the robot's own block is kept)."""
        gone = self._trail - {self._robot}
        self._trail -= gone
        if self._show_trail:
            self._apply(self._spans(gone))

    def set_follow(self, follow: bool) -> None:
        """Keep the robot in view (True), also after the user scrolled away, or stop (False)."""
        self._follow = follow
        self._detached = False
        self._follow_robot()

    def set_cursor(self, cell: Cell | None) -> None:
        """Put the editor cursor on ``cell`` (scrolled into view) or remove it (None)."""
        if cell is not None and not self._maze.in_bounds(*cell):
            raise ValueError(
                f"cursor {cell} is outside the {self._maze.width}x{self._maze.height} maze"
            )
        old = self._cursor
        if cell == old:
            return
        self._cursor = cell
        self._apply(self._spans(c for c in (old, cell) if c is not None))
        if cell is not None:
            self._scroll_to_cell(cell, margin=1)

    # -- rendering -------------------------------------------------------------------------
    def on_mount(self) -> None:
        self.virtual_size = Size(2 * self._maze.width, self._maze.height)

    def notify_style_update(self) -> None:
        super().notify_style_update()
        self._styles.clear()
        self._strips = [None] * self._maze.height

    def render_lines(self, crop: Region) -> list[Strip]:
        """The lines of ``crop`` (relative to the widget) straight from the row strips.

        For a widget without border, padding, outline, tint, hatch or opacity, as the maze
        view is styled, these are the lines Textual's styles cache makes of :meth:`render_line`:
        each row, the app's line filters applied, cut to the crop's columns. Its set-up for
        each call (the ancestors' colours, the filters, regions, the border titles) cost more
        than the rows themselves while the robot moves, a few rows a frame. Styled otherwise,
        the view is drawn Textual's way.
        """
        if not plain_styles(self):
            return super().render_lines(crop)
        scroll_x, scroll_y = self.scroll_offset
        width = self.size.width
        return plain_lines(self, crop, lambda y: self._line(scroll_y + y, scroll_x, width))

    def render_line(self, y: int) -> Strip:
        scroll_x, scroll_y = self.scroll_offset
        return self._line(scroll_y + y, scroll_x, self.size.width)

    def _line(self, row: int, scroll_x: int, width: int) -> Strip:
        """Maze row ``row`` as the view shows it, scrolled ``scroll_x`` columns along."""
        base = self._style("")
        if row >= self._maze.height:
            return Strip.blank(width, base)
        strip = self._strips[row]
        if strip is None:
            strip = self._build_strip(row)
        return strip.crop_extend(scroll_x, scroll_x + width, base)

    def _style(self, key: str) -> Style:
        """The widget's own style (``key`` ""), or it with the named components' (``"ray"``,
        ``"wall+cursor"``); kept until the styles change."""
        style = self._styles.get(key)
        if style is None:
            base = self.rich_style
            if key:
                base += Style.combine(
                    self.get_component_rich_style(f"maze-view--{n}", partial=True)
                    for n in key.split("+")
                )
            style = self._styles[key] = base
        return style

    def _make_base_row(self, y: int) -> list[Token]:
        maze = self._maze
        unicode = self._unicode
        start = maze.start
        exits = maze.exits
        row = maze.rows[y]
        tokens: list[Token] = []
        for x in range(maze.width):
            text = block_text(maze, x, y, unicode)
            if (x, y) == start:
                text = (START_UNICODE if unicode else START_ASCII)[maze.heading]
                kind = "start"
            elif (x, y) in exits:
                kind = "exit"
            elif row[x] == "#":
                kind = "wall"
            else:
                kind = "floor"
            tokens.append((text, kind))
        return tokens

    def _build_strip(self, y: int) -> Strip:
        base = self._base_rows[y]
        if base is None:
            base = self._base_rows[y] = self._make_base_row(y)
        sprites = self._sprite_rows.get(y, {})
        trail = self._trail if self._show_trail else ()
        trail_token = (TRAIL_UNICODE if self._unicode else TRAIL_ASCII, "trail")
        cursor_x = self._cursor[0] if self._cursor is not None and self._cursor[1] == y else -1
        segments: list[Segment] = []
        run: list[str] = []
        run_key = ""
        for x, token in enumerate(base):
            sprite = sprites.get(x)
            if sprite is not None:
                token = sprite
            elif token[1] == "floor" and (x, y) in trail:
                token = trail_token
            key = token[1] + "+cursor" if x == cursor_x else token[1]
            if key != run_key:
                if run:
                    segments.append(Segment("".join(run), self._style(run_key)))
                run = [token[0]]
                run_key = key
            else:
                run.append(token[0])
        if run:
            segments.append(Segment("".join(run), self._style(run_key)))
        strip = Strip(segments, 2 * len(base))
        self._strips[y] = strip
        self.strips_built += 1
        return strip

    # -- changes -----------------------------------------------------------------------------
    def _spans(self, cells: Iterable[Cell]) -> dict[int, tuple[int, int]]:
        """Changed cells grouped by row as (first x, last x)."""
        spans: dict[int, tuple[int, int]] = {}
        maze = self._maze
        for x, y in cells:
            if not maze.in_bounds(x, y):
                continue
            span = spans.get(y)
            spans[y] = (x, x) if span is None else (min(span[0], x), max(span[1], x))
        return spans

    def _apply(self, spans: dict[int, tuple[int, int]]) -> None:
        """Forget the strips of the changed rows and repaint only the changed spans."""
        strips = self._strips
        for y in spans:
            strips[y] = None
        if not spans or not self.is_mounted:
            return
        scroll_x, scroll_y = self.scroll_offset
        width, height = self.size
        regions = []
        for y, (x0, x1) in spans.items():
            row = y - scroll_y
            if not 0 <= row < height:
                continue
            left = max(2 * x0 - scroll_x, 0)
            right = min(2 * x1 + 2 - scroll_x, width)
            if left < right:
                regions.append(Region(left, row, right - left, 1))
        if regions:
            self.refresh(*regions)

    def _set_sprites(self, sprites: dict[Cell, Token]) -> set[Cell]:
        """Replace the sprite layer; returns the cells whose sprite changed."""
        old = self._sprites
        changed = {c for c in old.keys() | sprites.keys() if old.get(c) != sprites.get(c)}
        self._sprites = sprites
        rows: dict[int, dict[int, Token]] = {}
        for (x, y), token in sprites.items():
            rows.setdefault(y, {})[x] = token
        self._sprite_rows = rows
        return changed

    def _sensor_sprites(
        self, snapshot: Snapshot, cell_size: float, robot: Cell
    ) -> dict[Cell, Token]:
        maze = self._maze
        pose = snapshot.pose
        px = pose.x / cell_size
        py = pose.y / cell_size
        dots: dict[Cell, Token] = {}
        marks: dict[Cell, Token] = {}
        touches: dict[Cell, Token] = {}
        rays = RAY_UNICODE if self._unicode else RAY_ASCII
        for spec in snapshot.sensors:
            value = snapshot.readings.get(spec.port)
            if value is None:
                continue
            angle = pose.heading + MOUNT_ANGLES[spec.mount]
            label = f"{spec.port:<2}"[:2]
            mark = sensor_kind(spec.kind).panel.mark
            if mark == "ray":
                glyph = rays[round(angle / 45.0) % 4]
                path, hit = self._trace(px, py, angle, value / cell_size)
                for cell in path:
                    dots[cell] = (glyph, "ray")
                if hit is not None:
                    marks[hit] = (label, "hit")
            elif mark == "contact" and value:
                dx, dy = _QUARTER_STEPS[round(angle / 90.0) % 4]
                cell = (robot[0] + dx, robot[1] + dy)
                if maze.in_bounds(*cell):
                    touches[cell] = (label, "touch")
        sprites = dots
        sprites.update(marks)
        sprites.update(touches)
        glyph = robot_glyph(pose.heading, self._unicode)
        sprites[robot] = (glyph + " ", "robot")
        return sprites

    def _trace(
        self, px: float, py: float, angle: float, reading: float
    ) -> tuple[list[Cell], Cell | None]:
        """Floor blocks a ray crosses up to its reading, and the wall block it ends on, if any.

        Walks the block grid from (px, py) in blocks along ``angle`` (degrees, 0 = right,
        clockwise); exits and the start keep their own glyph.
        """
        maze = self._maze
        rad = math.radians(angle)
        dx = math.cos(rad)
        dy = math.sin(rad)
        ix = math.floor(px)
        iy = math.floor(py)
        step_x = 1 if dx > 0 else -1
        step_y = 1 if dy > 0 else -1
        if abs(dx) > 1e-9:
            delta_x = 1.0 / abs(dx)
            next_x = ((ix + 1 - px) if dx > 0 else (px - ix)) * delta_x
        else:
            delta_x = next_x = math.inf
        if abs(dy) > 1e-9:
            delta_y = 1.0 / abs(dy)
            next_y = ((iy + 1 - py) if dy > 0 else (py - iy)) * delta_y
        else:
            delta_y = next_y = math.inf
        limit = max(reading, 0.0) + _RAY_SLACK
        path: list[Cell] = []
        special = {maze.start, *maze.exits}
        rows = maze.rows
        width, height = maze.width, maze.height
        for _ in range(width + height + 2):
            if next_x < next_y:
                t = next_x
                ix += step_x
                next_x += delta_x
            else:
                t = next_y
                iy += step_y
                next_y += delta_y
            if t > limit or not (0 <= ix < width and 0 <= iy < height):
                return path, None
            if rows[iy][ix] == WALL:
                return path, (ix, iy)
            if (ix, iy) not in special:
                path.append((ix, iy))
        return path, None

    @property
    def tooltip(self) -> VisualType | None:
        """The sensors' readings as last shown, one line per port (None with no sensor)."""
        if self._tooltip_stale and self._last_show is not None:
            self._update_tooltip(self._last_show[0])
        return ScrollView.tooltip.fget(self)  # type: ignore[attr-defined]

    @tooltip.setter
    def tooltip(self, tooltip: VisualType | None) -> None:
        self._tooltip_stale = False
        ScrollView.tooltip.fset(self, tooltip)  # type: ignore[attr-defined]

    def _update_tooltip(self, snapshot: Snapshot) -> None:
        self._tooltip_stale = False
        lines = []
        for spec in sorted(snapshot.sensors, key=lambda s: s.port):
            value = snapshot.readings.get(spec.port)
            if value is None:
                continue
            state = sensor_kind(spec.kind).panel.state(value)
            shown = f"{value:.3g}" if state is None else state
            lines.append(f"port {spec.port} {spec.kind} {spec.mount}: {shown}")
        text = "\n".join(lines)
        if text != self._tooltip_text:
            self._tooltip_text = text
            self.tooltip = text or None

    # -- scrolling and input -------------------------------------------------------------------
    def _follow_robot(self) -> None:
        if self._follow and not self._detached and self._robot is not None:
            self._scroll_to_cell(self._robot, margin=None)

    def _scroll_to_cell(self, cell: Cell, margin: int | None) -> None:
        """Scroll so ``cell`` is at least ``margin`` rows (twice as many columns) inside the view.

        With ``margin=None`` the margin is a quarter of the view (at most 3 rows), and when the
        cell comes that close to an edge the view jumps to centre it, so following a moving
        robot scrolls (and repaints the whole view) rarely.
        """
        if not self.is_mounted:
            return
        region = self.scrollable_content_region
        view_w, view_h = region.width, region.height
        if view_w <= 0 or view_h <= 0:
            return
        x, y = cell
        if margin is None:
            my = min(3, max(0, (view_h - 1) // 4))
            mx = min(6, max(0, (view_w - 2) // 4))
        else:
            my = min(margin, max(0, (view_h - 1) // 2))
            mx = min(2 * margin, max(0, (view_w - 2) // 2))
        scroll_x, scroll_y = self.scroll_offset
        new_x, new_y = scroll_x, scroll_y
        col = 2 * x
        if col < scroll_x + mx or col + 2 > scroll_x + view_w - mx:
            new_x = (
                col + 1 - view_w // 2
                if margin is None
                else (col - mx if col < scroll_x + mx else col + 2 + mx - view_w)
            )
        if y < scroll_y + my or y >= scroll_y + view_h - my:
            new_y = (
                y - view_h // 2
                if margin is None
                else (y - my if y < scroll_y + my else y + 1 + my - view_h)
            )
        new_x = min(max(new_x, 0), max(self.virtual_size.width - view_w, 0))
        new_y = min(max(new_y, 0), max(self.virtual_size.height - view_h, 0))
        if (new_x, new_y) != (scroll_x, scroll_y):
            self.scroll_to(new_x, new_y, animate=False)

    def _stop_following(self) -> None:
        if self.allow_vertical_scroll or self.allow_horizontal_scroll:
            self._detached = True

    def on_mouse_scroll_down(self, event: events.MouseScrollDown) -> None:
        self._stop_following()

    def on_mouse_scroll_up(self, event: events.MouseScrollUp) -> None:
        self._stop_following()

    def on_mouse_scroll_left(self, event: events.MouseScrollLeft) -> None:
        self._stop_following()

    def on_mouse_scroll_right(self, event: events.MouseScrollRight) -> None:
        self._stop_following()

    def on_scroll_to(self, message: ScrollTo) -> None:
        self._stop_following()

    def on_scroll_up(self, message: ScrollUp) -> None:
        self._stop_following()

    def on_scroll_down(self, message: ScrollDown) -> None:
        self._stop_following()

    def on_scroll_left(self, message: ScrollLeft) -> None:
        self._stop_following()

    def on_scroll_right(self, message: ScrollRight) -> None:
        self._stop_following()

    def on_resize(self, event: events.Resize) -> None:
        self._follow_robot()

    def on_click(self, event: events.Click) -> None:
        offset = event.get_content_offset(self)
        if offset is None:
            return
        scroll_x, scroll_y = self.scroll_offset
        cell = ((offset.x + scroll_x) // 2, offset.y + scroll_y)
        if self._maze.in_bounds(*cell):
            self.post_message(self.BlockClicked(self, cell))
