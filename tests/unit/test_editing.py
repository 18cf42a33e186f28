"""The maze editor's model: cursor, edits, undo/redo, validation, new/generate, saving."""

import os
import stat
from dataclasses import replace

import pytest

from workbench.sim.editing import (
    EditorError,
    Finding,
    GenerateOptions,
    MazeEditor,
    blank_maze,
    finding_of,
    parse_seed,
    parse_size,
)
from workbench.sim.maze import MazeError
from workbench.sim.mazefile import parse_maze
from workbench.sim.mazeio import load_maze

ROOM = parse_maze("#####\n#S..#\n#..E#\n#####\n", source="room.txt")


def test_cursor_starts_on_the_start_and_is_clamped_to_the_maze():
    ed = MazeEditor(ROOM)
    assert ed.cursor == (1, 1)
    assert ed.move(-5, 0) == (0, 1)
    assert ed.move(0, 10) == (0, 3)
    assert ed.move(100, -100) == (4, 0)
    assert ed.move_to((2, 2)) == (2, 2)


def test_toggle_wall_and_undo_redo_restore_exact_mazes():
    ed = MazeEditor(ROOM)
    ed.move_to((2, 1))
    assert ed.toggle_wall()
    assert ed.maze.is_wall(2, 1) and ed.dirty and ed.can_undo and not ed.can_redo
    ed.toggle_wall((2, 2))
    assert ed.cursor == (2, 2) and ed.maze.is_wall(2, 2)
    assert ed.undo() and not ed.maze.is_wall(2, 2) and ed.maze.is_wall(2, 1)
    assert ed.undo() and ed.maze == ROOM and not ed.dirty
    assert not ed.undo()
    assert ed.redo() and ed.maze.is_wall(2, 1)
    assert ed.redo() and ed.maze.is_wall(2, 2)
    assert not ed.redo()


def test_a_new_edit_clears_redo():
    ed = MazeEditor(ROOM)
    ed.toggle_wall((2, 1))
    ed.undo()
    ed.toggle_wall((2, 2))
    assert not ed.can_redo


def test_walling_an_exit_removes_it():
    ed = MazeEditor(ROOM)
    ed.toggle_wall((3, 2))
    assert ed.maze.exits == ()


def test_set_start_moves_it_then_cycles_the_heading():
    ed = MazeEditor(ROOM)
    ed.move_to((2, 2))
    assert ed.set_start() == "right" and ed.maze.start == (2, 2)
    assert [ed.set_start() for _ in range(4)] == ["down", "left", "up", "right"]
    ed.undo()
    assert ed.maze.heading == "up"


def test_the_start_block_cannot_be_walled():
    ed = MazeEditor(ROOM)
    with pytest.raises(EditorError, match=r"move the start \(s\) before walling it"):
        ed.toggle_wall((1, 1))
    assert ed.maze == ROOM and not ed.can_undo


def test_start_and_exit_placed_on_a_wall_clear_the_block_in_one_undo_step():
    ed = MazeEditor(ROOM)
    ed.move_to((2, 0))
    ed.toggle_exit()
    assert not ed.maze.is_wall(2, 0) and ed.maze.is_exit(2, 0)
    ed.toggle_exit()
    assert not ed.maze.is_wall(2, 0) and not ed.maze.is_exit(2, 0)
    ed.toggle_wall()
    ed.move_to((2, 1))
    ed.toggle_wall()
    ed.set_start()
    assert not ed.maze.is_wall(2, 1) and ed.maze.start == (2, 1)
    ed.undo()
    assert ed.maze.is_wall(2, 1) and ed.maze.start == (1, 1)


def test_toggle_exit_adds_and_removes():
    ed = MazeEditor(ROOM)
    ed.move_to((2, 1))
    assert ed.toggle_exit() is True and ed.maze.is_exit(2, 1)
    assert ed.toggle_exit() is False and not ed.maze.is_exit(2, 1)


def test_problems_follow_the_maze_with_block_positions():
    ed = MazeEditor(ROOM)
    assert ed.problems == [] and ed.valid
    ed.toggle_wall((4, 1))  # open the boundary
    assert [(p.cell, p.message) for p in ed.problems] == [
        ((4, 1), "open floor on the outer boundary: the robot could leave the maze")
    ]
    assert not ed.valid and "(4, 1)" in str(ed.problems[0])
    ed.undo()
    assert ed.problems == []


def test_problem_positions_account_for_front_matter():
    maze = parse_maze("---\nname: x\n---\n#####\n#S..#\n#...E\n#####\n#...#\n", source="f")
    ed = MazeEditor(maze)
    cells = {p.cell for p in ed.problems}
    assert (4, 2) not in cells  # an exit on the boundary is fine
    assert (1, 4) in cells  # bottom row floor
    assert finding_of(maze, maze.problem("m", "h")) == Finding("m", "h", None)


def test_new_maze_is_a_closed_room_with_the_start_at_1_1():
    ed = MazeEditor(ROOM, "room.txt")
    ed.new(6, 4)
    assert ed.maze.rows == ("######", "#....#", "#....#", "######")
    assert ed.maze.start == (1, 1) and ed.cursor == (1, 1)
    assert ed.path is None and ed.dirty
    assert ed.maze.notes() == ["no exits: free exploration (runs end at their time limit)"]
    assert ed.valid
    ed.undo()
    assert ed.maze == ROOM


def test_blank_maze_size_limits():
    with pytest.raises(EditorError, match="3 to 200 blocks"):
        blank_maze(2, 5)


def test_generate_is_seeded_and_checked():
    ed = MazeEditor(ROOM)
    ed.generate(4, 3, 7, "braid", "center")
    first = ed.maze
    assert (first.width, first.height) == (9, 7) and ed.valid
    ed.generate(4, 3, 7, "braid", "center")
    assert ed.maze == first
    with pytest.raises(EditorError, match="unknown style"):
        ed.generate(4, 3, 7, "spiral", "none")
    with pytest.raises(EditorError, match="unknown exit"):
        ed.generate(4, 3, 7, "perfect", "everywhere")
    with pytest.raises(EditorError, match="width must be 1 to 99"):
        ed.generate(0, 3, 7, "perfect", "none")
    assert ed.maze == first


@pytest.mark.parametrize(
    ("w", "h", "match"),
    [
        ("", "5", "width is empty"),
        ("a", "5", "'a' is not a whole number"),
        ("5", "-1", "'-1' is not a whole number"),
        ("5", "500", "height must be 3 to 200 blocks, not 500"),
    ],
)
def test_parse_size_explains_bad_input(w, h, match):
    with pytest.raises(EditorError, match=match):
        parse_size(w, h, 3, 200, "blocks")


def test_parse_size_and_seed_accept_good_input():
    assert parse_size(" 7 ", "9", 3, 200, "blocks") == (7, 9)
    assert parse_seed("42") == 42
    with pytest.raises(EditorError, match="seed"):
        parse_seed("x")


def test_save_writes_atomically_and_clears_dirty(tmp_path):
    path = tmp_path / "room.txt"
    ed = MazeEditor(ROOM)
    ed.toggle_wall((2, 1))
    assert ed.save(path) == str(path)
    assert not ed.dirty and ed.path == str(path)
    assert load_maze(path).same_layout(ed.maze)
    assert [p.name for p in tmp_path.iterdir()] == ["room.txt"]  # no temporary left behind
    ed.toggle_wall((2, 2))
    ed.save()
    assert load_maze(path).is_wall(2, 2)


def test_save_without_a_path_asks_for_one():
    ed = MazeEditor(ROOM)
    with pytest.raises(EditorError, match="save as"):
        ed.save()


def test_failed_saves_keep_the_maze_and_the_dirty_flag(tmp_path):
    ed = MazeEditor(ROOM, tmp_path / "room.txt")
    ed.toggle_wall((2, 1))
    edited = ed.maze
    with pytest.raises(EditorError, match="does not exist"):
        ed.save(tmp_path / "nowhere" / "m.txt")
    with pytest.raises(EditorError, match="is a folder"):
        ed.save(tmp_path)
    with pytest.raises(EditorError, match=r"cannot save as .*maz"):
        ed.save(tmp_path / "m.maz")  # not a 16x16 micromouse maze
    assert ed.maze == edited and ed.dirty and ed.path == str(tmp_path / "room.txt")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_gives_a_clear_message(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        ed = MazeEditor(ROOM)
        ed.toggle_wall((2, 1))
        with pytest.raises(EditorError, match="Permission denied; the maze is still here"):
            ed.save(folder / "m.txt")
        assert ed.dirty and ed.maze.is_wall(2, 1)
    finally:
        folder.chmod(stat.S_IRWXU)


def test_handover_gives_the_robot_a_changed_valid_maze_with_a_name(tmp_path):
    ed = MazeEditor(ROOM, "labs/room.txt")
    assert ed.handover() == (None, "")  # nothing changed: the robot keeps its run
    ed.toggle_wall((2, 1))
    maze, note = ed.handover()
    assert maze.is_wall(2, 1) and maze.name == "room" and note == ""
    assert ed.handover(discard=True) == (None, "")  # nothing saved: back to the opened maze
    ed.toggle_wall((4, 1))
    assert ed.handover() == (
        None,
        "the maze has 1 problem, so the robot stays on the previous maze",
    )
    ed.undo()
    ed.save(tmp_path / "room2.txt")
    ed.toggle_wall((3, 1))
    maze, _ = ed.handover(discard=True)
    assert maze is not None and not maze.is_wall(3, 1) and maze.is_wall(2, 1)
    ed.new(5, 5)
    assert ed.handover()[0].name == "new maze"


def test_generate_options_are_parsed_with_reasons():
    assert GenerateOptions.parse("4", "5", "9", "braid", "none") == GenerateOptions(
        4, 5, 9, "braid", "none"
    )
    with pytest.raises(EditorError, match="height must be 1 to 99 cells, not 100"):
        GenerateOptions.parse("4", "100", "9", "braid", "none")
    with pytest.raises(EditorError, match="seed '-3'"):
        GenerateOptions.parse("4", "4", "-3", "braid", "none")
    with pytest.raises(EditorError, match="unknown style"):
        GenerateOptions.parse("4", "4", "1", "x", "none")


def test_suggested_path_comes_from_the_file_or_the_title():
    ed = MazeEditor(ROOM, "labs/room.txt")
    assert ed.suggested_path() == "labs/room.txt"
    ed.generate(3, 3, 5, "perfect", "none")
    assert ed.suggested_path() == "perfect-3x3-seed-5.txt"


def test_a_write_error_comes_back_as_a_message(tmp_path, monkeypatch):
    def refuse(path, data, mode=None):
        raise PermissionError(13, "Permission denied", str(path))

    # the one writer every save of the app goes through
    monkeypatch.setattr("workbench.files.workspace.write_bytes_atomic", refuse)
    ed = MazeEditor(ROOM)
    ed.toggle_wall((2, 1))
    with pytest.raises(EditorError, match="Permission denied; the maze is still here"):
        ed.save(tmp_path / "m.txt")
    assert ed.dirty and ed.path is None and ed.maze.is_wall(2, 1)


BIDI = ["\u202a", "\u202b", "\u202c", "\u202d", "\u202e", "\u2066", "\u2067", "\u2068",
        "\u2069", "\u200e", "\u200f", "\u061c"]  # fmt: skip


@pytest.mark.parametrize("control", BIDI)
def test_a_maze_name_with_a_bidi_control_is_refused_where_it_is_written(control):
    text = f"---\nname: Evil{control}txt.exe\n---\n#####\n#S..#\n#..E#\n#####\n"
    with pytest.raises(MazeError) as caught:
        parse_maze(text, source="evil.txt")
    problem = caught.value.problems[0]
    assert problem.message == (
        f"the maze's name has a bidi control character (U+{ord(control):04X} at position 5), "
        "which shows text in another order than it is written"
    )
    assert (problem.source, problem.line) == ("evil.txt", 2)


def test_the_editor_refuses_to_save_a_maze_named_with_a_bidi_override(tmp_path):
    named = MazeEditor(replace(ROOM, name="Room\u202etxt.exe"))
    with pytest.raises(EditorError) as caught:
        named.save(tmp_path / "room.txt")
    assert str(caught.value) == (
        f"cannot save as {tmp_path / 'room.txt'}: the maze's name has a bidi control character "
        "(U+202E at position 5), which shows text in another order than it is written (type "
        "it again without it)"
    )
    assert list(tmp_path.iterdir()) == []  # nothing written
    # a file name with one is refused as a path (control characters are never in one)
    with pytest.raises(EditorError, match="control characters"):
        MazeEditor(ROOM).save(tmp_path / "maze\u202etxt.exe")


def test_hand_blocks_count_only_what_was_walled_or_cleared_by_hand():
    ed = MazeEditor(ROOM)
    assert ed.hand_blocks() == 0
    ed.toggle_wall((2, 1))
    ed.toggle_wall((3, 1))
    assert ed.hand_blocks() == 2
    ed.undo()
    assert ed.hand_blocks() == 1  # an edit undone is not counted
    ed.toggle_wall((2, 1))  # walled and cleared again: back as it was
    assert ed.hand_blocks() == 0
    ed.redo()  # nothing to redo after a new edit
    assert ed.hand_blocks() == 0


def test_generate_and_new_are_not_hand_edits_but_edits_after_them_are():
    ed = MazeEditor(ROOM)
    ed.toggle_wall((2, 1))
    ed.generate(4, 3, 7, "braid", "center")
    assert ed.maze != ROOM and ed.hand_blocks() == 0
    inner = next((x, y) for y in range(1, ed.maze.height - 1)
                 for x in range(1, ed.maze.width - 1) if ed.maze.is_wall(x, y))  # fmt: skip
    ed.toggle_wall(inner)
    assert ed.hand_blocks() == 1
    ed.undo()
    ed.undo()  # back before Generate: the hand edit on the room counts again
    assert ed.maze.width == ROOM.width and ed.hand_blocks() == 1
    ed.new(6, 5)
    assert ed.hand_blocks() == 0


def test_hand_blocks_of_the_maze_last_saved(tmp_path):
    ed = MazeEditor(ROOM)
    ed.toggle_wall((2, 1))
    ed.save(tmp_path / "mine.txt")
    ed.generate(4, 3, 7, "braid", "center")
    assert ed.hand_blocks() == 0
    assert ed.hand_blocks(discard=True) == 1  # what leaving with "discard" hands over
