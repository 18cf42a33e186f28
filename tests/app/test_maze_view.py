"""The maze view widget, driven through a tiny host app with App.run_test()."""

from __future__ import annotations

from dataclasses import replace

from textual import events
from textual.app import App, ComposeResult
from textual.geometry import Region
from textual.strip import Strip
from textual.widget import Widget

from tests.app.support import sync
from workbench.sim.driver import BY_KEYS
from workbench.sim.generate import generate
from workbench.sim.maze import Maze
from workbench.sim.metrics import Metrics
from workbench.sim.sensors import SensorSpec
from workbench.sim.session import Snapshot
from workbench.sim.world import Pose
from workbench.tui.widgets import MazeView

SMALL = Maze(
    rows=(
        "#########",
        "#.......#",
        "#.##.##.#",
        "#.......#",
        "#######.#",
    ),
    start=(1, 1),
    heading="right",
    exits=((7, 4),),
)
SMALL_ASCII = [
    "##################",
    "##S>            ##",
    "##  ####  ####  ##",
    "##              ##",
    "##############E ##",
]
METRICS = Metrics(False, None, 0.0, 0.0, 0.0, 0.0, 0, 0, None)


def snap(
    x: float,
    y: float,
    heading: float = 0.0,
    sensors: tuple[SensorSpec, ...] = (),
    readings: dict[int, float | int] | None = None,
) -> Snapshot:
    """A snapshot with the robot centred in block (x, y) when the cell size is 1."""
    return Snapshot(
        time=0.0,
        pose=Pose(x + 0.5, y + 0.5, heading),
        block=(int(x), int(y)),
        readings=dict(readings or {}),
        sensors=sensors,
        driver=BY_KEYS,
        state=None,
        variables={},
        metrics=METRICS,
    )


class Host(App):
    def __init__(self, maze: Maze, **options: object) -> None:
        super().__init__()
        self.maze = maze
        self.options = options
        self.clicked: list[tuple[int, int]] = []

    def compose(self) -> ComposeResult:
        yield MazeView(self.maze, id="maze", **self.options)

    def on_maze_view_block_clicked(self, message: MazeView.BlockClicked) -> None:
        self.clicked.append(message.cell)


def lines(view: MazeView) -> list[str]:
    return [view.render_line(y).text.rstrip() for y in range(view.size.height)]


def maze_lines(view: MazeView) -> list[str]:
    """The maze's rows as drawn (unscrolled views only)."""
    width = 2 * view.maze.width
    return [view.render_line(y).text[:width] for y in range(view.maze.height)]


@sync
async def test_renders_a_small_maze_in_ascii():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        await pilot.pause()
        view = app.query_one(MazeView)
        assert maze_lines(view) == SMALL_ASCII
        assert view.virtual_size.width == 18 and view.virtual_size.height == 5


@sync
async def test_robot_glyph_follows_the_heading():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        for heading, glyph in ((0, ">"), (90, "v"), (180, "<"), (270, "^"), (350, ">"), (100, "v")):
            view.show(snap(4, 3, heading), 1.0)
            await pilot.pause()
            assert maze_lines(view)[3][8:10] == glyph + " ", heading
        view.set_unicode(True)
        for heading, glyph in ((0, "▶"), (45, "◢"), (90, "▼"), (135, "◣"), (180, "◀"), (225, "◤")):
            view.show(snap(4, 3, heading), 1.0)
            await pilot.pause()
            assert maze_lines(view)[3][8] == glyph, heading


@sync
async def test_robot_position_uses_the_cell_size():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        pose = Pose(70 * 5.5, 70 * 3.5, 0.0)
        view.show(Snapshot(0.0, pose, (5, 3), {}, (), "keys", None, {}, METRICS), 70.0)
        await pilot.pause()
        assert view.robot_cell == (5, 3)
        assert maze_lines(view)[3][10:12] == "> "


@sync
async def test_distance_ray_stops_at_the_wall_and_marks_it_with_the_port():
    front = SensorSpec("distance", 2, "front")
    right = SensorSpec("distance", 1, "right")
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        # facing right from (1, 3): five floor blocks, then the wall at x = 8; the right
        # sensor looks down into the wall block right below
        view.show(snap(1, 3, 0.0, (front, right), {2: 6.4, 1: 0.4}), 1.0)
        await pilot.pause()
        row = maze_lines(view)
        assert row[3] == "##> : : : : : : 2 "
        assert row[4][2:4] == "1 "
        # a reading short of the wall: the ray stops in the corridor and marks nothing
        view.show(snap(1, 3, 0.0, (front,), {2: 2.4}), 1.0)
        await pilot.pause()
        row = maze_lines(view)
        assert row[3] == "##> : : :       ##"
        assert row[4] == SMALL_ASCII[4]


@sync
async def test_ray_follows_the_mount_and_skips_exits():
    left = SensorSpec("distance", 3, "left")
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        # heading down at (7, 1): the left mount looks right, into the wall at x = 8;
        # heading up from (7, 3) the front ray passes (7, 2) and (7, 1), then the wall
        view.show(snap(7, 3, 270.0, (SensorSpec("distance", 4, "front"),), {4: 2.4}), 1.0)
        await pilot.pause()
        row = maze_lines(view)
        assert row[0][14:16] == "4 " and row[1][14:16] == ": " and row[2][14:16] == ": "
        view.show(snap(7, 1, 90.0, (left,), {3: 0.4}), 1.0)
        await pilot.pause()
        assert maze_lines(view)[1][14:18] == "v 3 "


@sync
async def test_pressed_touch_sensor_is_highlighted():
    touch = SensorSpec("touch", 5, "front")
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(7, 3, 0.0, (touch,), {5: 1}), 1.0)
        await pilot.pause()
        assert maze_lines(view)[3][14:18] == "> 5 "
        strip = view.render_line(3)
        styles = [seg.style for seg in strip if seg.text.startswith("5")]
        assert styles and styles[0] == view._style("touch")
        view.show(snap(7, 3, 0.0, (touch,), {5: 0}), 1.0)
        await pilot.pause()
        assert maze_lines(view)[3][14:18] == "> ##"
        assert "port 5 touch front: free" in str(view.tooltip)


@sync
async def test_trail_toggle_and_clear():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        for x in range(1, 5):
            view.show(snap(x, 3), 1.0)
        await pilot.pause()
        assert maze_lines(view)[3] == "##. . . >       ##"
        view.set_trail(False)
        await pilot.pause()
        assert maze_lines(view)[3] == "##      >       ##"
        assert not view.trail
        view.set_trail(True)
        await pilot.pause()
        assert maze_lines(view)[3] == "##. . . >       ##"
        view.clear_trail()
        await pilot.pause()
        assert maze_lines(view)[3] == "##      >       ##"


@sync
async def test_trail_is_off_when_asked_at_construction():
    app = Host(SMALL, trail=False)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 3), 1.0)
        view.show(snap(2, 3), 1.0)
        await pilot.pause()
        assert maze_lines(view)[3] == "##  >           ##"


@sync
async def test_unicode_mode_draws_outlines():
    app = Host(SMALL, unicode=True)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        assert maze_lines(view) == [
            "┌───────────────┐ ",
            "│ S▸            │ ",
            "│   ╶─╴   ╶─╴   │ ",
            "│               │ ",
            "└───────────╴ E ╵ ",
        ]
        assert view.unicode
        view.set_unicode(False)
        await pilot.pause()
        assert maze_lines(view) == SMALL_ASCII


@sync
async def test_unicode_ray_glyphs():
    front = SensorSpec("distance", 2, "front")
    app = Host(SMALL, unicode=True, trail=False)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 3, 0.0, (front,), {2: 6.4}), 1.0)
        await pilot.pause()
        assert maze_lines(view)[3] == "│ ▶ ┄┄┄┄┄┄┄┄┄┄┄┄2 "
        view.show(snap(7, 3, 270.0, (front,), {2: 2.4}), 1.0)
        await pilot.pause()
        assert [line[14:16] for line in maze_lines(view)[:4]] == ["2 ", "┆ ", "┆ ", "▲ "]


@sync
async def test_follows_the_robot_on_a_big_maze_until_the_user_scrolls():
    maze = generate(40, 40, 3)  # 81 x 81 blocks
    app = Host(maze)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        region = view.scrollable_content_region

        def robot_visible() -> bool:
            x, y = view.robot_cell
            sx, sy = view.scroll_offset
            return sx <= 2 * x and 2 * x + 2 <= sx + region.width and sy <= y < sy + region.height

        for cell in ((1, 79), (40, 40), (79, 1), (79, 79), (1, 1)):
            view.show(snap(*cell), 1.0)
            await pilot.pause()
            assert robot_visible(), (cell, view.scroll_offset)
        # a robot walking down a column scrolls by half pages, not every step
        offsets = set()
        for y in range(1, 80):
            view.show(snap(1, y), 1.0)
            offsets.add(view.scroll_offset.y)
            assert robot_visible()
        assert len(offsets) < 12
        # the user scrolls away: the view stays where the user put it
        view.post_message(events.MouseScrollUp(view, 2, 2, 0, -1, 0, False, False, False))
        await pilot.pause()
        stay = view.scroll_offset
        view.show(snap(1, 79), 1.0)
        view.show(snap(3, 79), 1.0)
        await pilot.pause()
        assert view.scroll_offset == stay
        assert robot_visible() is False or stay.y >= 79 - region.height
        view.set_follow(True)
        await pilot.pause()
        assert robot_visible()
        view.set_follow(False)
        view.show(snap(79, 1), 1.0)
        await pilot.pause()
        assert not robot_visible()


@sync
async def test_a_200_by_200_maze_at_80x24():
    rows = ["#" * 200] + ["#" + "." * 198 + "#" for _ in range(198)] + ["#" * 200]
    maze = Maze(rows=tuple(rows), start=(1, 1))
    app = Host(maze, unicode=True)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        built = view.strips_built
        assert built <= view.size.height  # only the visible rows were rendered
        view.show(snap(198, 198, 45.0), 1.0)
        await pilot.pause()
        assert view.scroll_offset.x > 300 and view.scroll_offset.y > 170
        assert "◢" in "".join(lines(view))
        svg = app.export_screenshot()
        assert "◢" in svg


@sync
async def test_click_posts_block_clicked_with_the_cell():
    maze = generate(40, 40, 3)
    app = Host(maze)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        await pilot.click(MazeView, offset=(7, 3))
        await pilot.pause()
        assert app.clicked == [(3, 3)]
        view.show(snap(60, 70), 1.0)
        await pilot.pause()
        sx, sy = view.scroll_offset
        assert (sx, sy) != (0, 0)
        await pilot.click(MazeView, offset=(10, 4))
        await pilot.pause()
        assert app.clicked[-1] == ((10 + sx) // 2, 4 + sy)


@sync
async def test_click_outside_the_maze_posts_nothing():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        await pilot.pause()
        await pilot.click(MazeView, offset=(30, 8))
        await pilot.pause()
        assert app.clicked == []


@sync
async def test_moving_one_block_rebuilds_only_the_affected_rows():
    maze = generate(16, 16, 5)
    app = Host(maze)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        start = maze.start
        view.show(snap(*start), 1.0)
        await pilot.pause()
        before = view.strips_built
        # idle frames rebuild nothing
        view.show(snap(*start), 1.0)
        await pilot.pause()
        assert view.strips_built == before
        # one block up, within the corridor: the old row and the new row
        x, y = start
        target = next(
            (x + dx, y + dy) for dx, dy in ((0, -1), (1, 0)) if not maze.is_wall(x + dx, y + dy)
        )
        view.show(snap(*target), 1.0)
        await pilot.pause()
        assert view.strips_built - before == (1 if target[1] == y else 2)


@sync
async def test_sensor_changes_rebuild_only_their_rows():
    front = SensorSpec("distance", 2, "front")
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 3, 0.0, (front,), {2: 6.4}), 1.0)
        await pilot.pause()
        before = view.strips_built
        view.show(snap(1, 3, 0.0, (front,), {2: 2.4}), 1.0)
        await pilot.pause()
        assert view.strips_built - before == 1


@sync
async def test_set_maze_repaints_only_the_edited_rows():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        before = view.strips_built
        view.set_maze(SMALL.with_block(4, 3, wall=True))
        await pilot.pause()
        assert view.strips_built - before == 1
        assert maze_lines(view)[3] == "##      ##      ##"
        edited = SMALL.with_start(5, 1, "down").with_exit(7, 4, present=False)
        view.set_maze(edited)
        await pilot.pause()
        assert maze_lines(view)[1] == "##        Sv    ##"
        assert maze_lines(view)[4] == "##############  ##"
        bigger = Maze(rows=("#####", "#...#", "#####"), start=(1, 1))
        view.set_maze(bigger)
        await pilot.pause()
        assert maze_lines(view) == ["##########", "##S>    ##", "##########"]
        assert view.virtual_size.width == 10


@sync
async def test_set_maze_in_unicode_updates_the_neighbouring_outlines():
    app = Host(SMALL, unicode=True)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        view.set_maze(SMALL.with_block(4, 2, wall=True))
        await pilot.pause()
        assert maze_lines(view)[2] == "│   ╶───────╴   │ "


@sync
async def test_cursor_overlay():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        assert view.cursor is None
        view.set_cursor((2, 2))
        await pilot.pause()
        assert view.cursor == (2, 2)
        strip = view.render_line(2)
        cursor_style = view._style("wall+cursor")
        assert [seg.text for seg in strip if seg.style == cursor_style] == ["##"]
        before = view.strips_built
        view.set_cursor((3, 2))
        await pilot.pause()
        assert view.strips_built - before == 1
        view.set_cursor(None)
        await pilot.pause()
        assert all(not (seg.style and seg.style.reverse) for seg in view.render_line(2))
        try:
            view.set_cursor((40, 40))
        except ValueError:
            pass
        else:
            raise AssertionError("a cursor outside the maze must be refused")


@sync
async def test_cursor_is_scrolled_into_view():
    maze = generate(40, 40, 3)
    app = Host(maze, follow=False)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        view.set_cursor((70, 75))
        await pilot.pause()
        sx, sy = view.scroll_offset
        region = view.scrollable_content_region
        assert sx <= 140 < sx + region.width and sy <= 75 < sy + region.height


@sync
async def test_hide_robot_removes_robot_and_rays():
    front = SensorSpec("distance", 2, "front")
    app = Host(SMALL, trail=False)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 3, 0.0, (front,), {2: 6.4}), 1.0)
        await pilot.pause()
        view.hide_robot()
        await pilot.pause()
        assert maze_lines(view) == SMALL_ASCII
        assert view.robot_cell is None


@sync
async def test_an_edit_redraws_the_rays_at_once():
    front = SensorSpec("distance", 2, "front")
    app = Host(SMALL, trail=False)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 3, 0.0, (front,), {2: 6.4}), 1.0)
        await pilot.pause()
        view.set_maze(SMALL.with_block(4, 3, wall=True))
        await pilot.pause()
        assert maze_lines(view)[3] == "##> : : 2       ##"


@sync
async def test_tiny_view_does_not_break():
    maze = generate(40, 40, 3)
    app = Host(maze)
    async with app.run_test(size=(4, 3)) as pilot:
        view = app.query_one(MazeView)
        for cell in ((1, 79), (79, 1), (40, 40)):
            view.show(snap(*cell), 1.0)
            await pilot.pause()
        view.set_cursor((3, 3))
        await pilot.pause()


@sync
async def test_the_start_is_marked_apart_from_the_robot_and_the_trail_goes_when_it_starts_over():
    app = Host(SMALL)
    async with app.run_test(size=(40, 10)) as pilot:
        view = app.query_one(MazeView)
        view.show(snap(1, 1), 1.0)  # on the start block: only the robot is drawn there
        for x in (2, 3, 4):
            view.show(replace(snap(x, 1), time=x), 1.0)
        await pilot.pause()
        assert maze_lines(view)[1] == "##S>. . >       ##"  # the start is S>, the robot >
        view.show(snap(1, 1), 1.0)  # time back at 0: a reset or a new maze
        view.show(replace(snap(2, 1), time=1.0), 1.0)
        await pilot.pause()
        assert maze_lines(view)[1] == "##S>>           ##"  # no dots left from before


def styles_cache_lines(view: MazeView, crop: Region) -> list[Strip]:
    """The lines Textual's own way makes of the view's rows (its styles cache)."""
    return Widget.render_lines(view, crop)


@sync
async def test_the_lines_drawn_are_the_ones_textuals_styles_cache_makes():
    maze = generate(40, 40, 3)  # scrolls both ways at 80x24: the scrollbars show
    sensors = (SensorSpec("distance", 1, "front"), SensorSpec("touch", 2, "left"))
    app = Host(maze, unicode=True)
    async with app.run_test(size=(80, 24)) as pilot:
        view = app.query_one(MazeView)
        await pilot.pause()
        width, height = view.outer_size
        crops = [
            Region(0, 0, width, height),
            Region(0, 3, width, 2),
            Region(10, 5, 7, 3),
            Region(width - 4, 0, 4, height),
        ]
        for cell, heading in (((1, 1), 0.0), ((40, 39), 90.0), ((79, 79), 225.0)):
            view.show(snap(*cell, heading, sensors, {1: 3.0, 2: 1}), 1.0)
            await pilot.pause()
            for crop in crops:
                assert view.render_lines(crop) == styles_cache_lines(view, crop), (cell, crop)
        # styled with a border and padding, the view is drawn Textual's way
        view.styles.border = ("round", "red")
        view.styles.padding = (0, 1)
        await pilot.pause()
        crop = Region(0, 0, *view.outer_size)
        drawn = view.render_lines(crop)
        assert drawn == styles_cache_lines(view, crop)
        assert drawn[0].text.startswith("╭")
