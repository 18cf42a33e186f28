"""Plain-text pictures of a maze: ASCII (any terminal) or Unicode box drawing.

Each block is two characters wide so that the picture keeps its proportions in a terminal.
"""

from __future__ import annotations

from .maze import Maze

ARROWS_ASCII = {"up": "^", "right": ">", "down": "v", "left": "<"}
ARROWS_UNICODE = {"up": "▲", "right": "▶", "down": "▼", "left": "◀"}
# (up, right, down, left) wall neighbours -> box-drawing junction
BOX = {
    (0, 0, 0, 0): "■",
    (1, 0, 0, 0): "╵",
    (0, 1, 0, 0): "╶",
    (0, 0, 1, 0): "╷",
    (0, 0, 0, 1): "╴",
    (1, 0, 1, 0): "│",
    (0, 1, 0, 1): "─",
    (1, 1, 0, 0): "└",
    (0, 1, 1, 0): "┌",
    (0, 0, 1, 1): "┐",
    (1, 0, 0, 1): "┘",
    (1, 1, 1, 0): "├",
    (0, 1, 1, 1): "┬",
    (1, 0, 1, 1): "┤",
    (1, 1, 0, 1): "┴",
    (1, 1, 1, 1): "┼",
}


def block_text(maze: Maze, x: int, y: int, unicode: bool = False) -> str:
    """The two characters that draw block (x, y)."""
    if maze.start == (x, y):
        arrows = ARROWS_UNICODE if unicode else ARROWS_ASCII
        return arrows[maze.heading] + " "
    if (x, y) in maze.exits:
        return "E "
    if not maze.is_wall(x, y):
        return "  "
    if not unicode:
        return "##"
    links = wall_links(maze, x, y)
    if links == (0, 0, 0, 0) and all(
        _solid(maze, x + dx, y + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)
    ):
        return "  "  # inside a solid region: only its outline is drawn
    return BOX[links] + ("─" if links[1] else " ")


def _solid(maze: Maze, x: int, y: int) -> bool:
    return maze.is_wall(x, y)  # outside the grid counts as solid


def wall_links(maze: Maze, x: int, y: int) -> tuple[int, int, int, int]:
    """Which neighbouring wall blocks (up, right, down, left) a wall block joins with a line.

    Two wall blocks are joined unless the seam between them touches no floor on either side,
    so thick walls are drawn as outlines rather than as a mesh.
    """

    def joined(ax: int, ay: int, bx: int, by: int) -> bool:
        if not (maze.in_bounds(bx, by) and maze.is_wall(bx, by)):
            return False
        if ay == by:  # horizontal seam: look above and below both blocks
            return not all(_solid(maze, cx, cy) for cx in (ax, bx) for cy in (ay - 1, ay + 1))
        return not all(_solid(maze, cx, cy) for cy in (ay, by) for cx in (ax - 1, ax + 1))

    return (
        int(joined(x, y, x, y - 1)),
        int(joined(x, y, x + 1, y)),
        int(joined(x, y, x, y + 1)),
        int(joined(x, y, x - 1, y)),
    )


def render(maze: Maze, unicode: bool = False) -> str:
    return "\n".join(
        "".join(block_text(maze, x, y, unicode) for x in range(maze.width)).rstrip()
        for y in range(maze.height)
    )
