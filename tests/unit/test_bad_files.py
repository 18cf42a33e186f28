"""Every kind of input file refuses hostile content with its own error type and a clear
message naming the file, never a traceback, a hang or a huge allocation."""

from __future__ import annotations

import pytest

from tests.bad_files import GOOD_FSM, GOOD_LAB, GOOD_MAZE, GOOD_USERS, SECRET, corpus, write_corpus
from workbench.door.passwords import hash_password
from workbench.door.users import UsersFileError, load_users
from workbench.files.bounded import MAX_PROBLEMS
from workbench.fsm.yaml_file import FsmFileError, load_fsm
from workbench.labs.model import LabFileError, load_lab
from workbench.sim.maze import MazeError
from workbench.sim.mazeio import load_maze

LOADERS = {
    "maze": (load_maze, MazeError),
    "fsm": (load_fsm, FsmFileError),
    "lab": (load_lab, LabFileError),
    "users": (load_users, UsersFileError),
}
BOM = b"\xef\xbb\xbf"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    return {bad.filename: (bad, path) for bad, path in write_corpus(tmp_path_factory.mktemp("bad"))}


@pytest.mark.parametrize("name", [bad.filename for bad in corpus()])
def test_each_bad_file_is_refused_with_its_formats_error(written, name):
    bad, path = written[name]
    load, error = LOADERS[bad.kind]
    with pytest.raises(error) as info:
        load(path)
    message = str(info.value)
    assert bad.says in message
    assert str(path.name) in message
    assert SECRET not in message
    assert len(message.splitlines()) <= MAX_PROBLEMS + 1


def test_a_maze_with_many_problems_lists_twenty_and_counts_the_rest(written):
    _bad, path = written["maze-40000-problems.txt"]
    with pytest.raises(MazeError) as info:
        load_maze(path)
    problems = info.value.problems
    assert len(problems) == MAX_PROBLEMS + 1
    assert problems[0].message == "unknown character 'Z'" and problems[0].line == 1
    assert problems[-1].message == "and 39,980 more problems"


def test_a_nan_cell_is_refused_at_its_line_by_the_check_not_later(written):
    _bad, path = written["maze-nan.txt"]
    with pytest.raises(MazeError) as info:
        load_maze(path)
    (problem,) = info.value.problems
    assert (problem.source, problem.line, problem.column) == (str(path), 2, 7)


def test_an_fsm_problem_names_line_and_column(written):
    _bad, path = written["fsm-nan-parameter.yaml"]
    with pytest.raises(FsmFileError) as info:
        load_fsm(path)
    assert str(info.value).startswith(f"{path}:5:9: a number that is not finite")


def test_a_bom_is_accepted_in_every_text_format(tmp_path):
    maze = tmp_path / "bom.txt"
    maze.write_bytes(BOM + GOOD_MAZE.encode())
    assert load_maze(maze).name == "ok"
    micro = tmp_path / "bom-micro.txt"
    micro.write_bytes(BOM + b"o---o\n| G |\no---o\n")
    assert load_maze(micro).exits
    fsm = tmp_path / "bom.yaml"
    fsm.write_bytes(BOM + GOOD_FSM.encode())
    assert load_fsm(fsm).name == "mine"
    (tmp_path / "m.txt").write_text(GOOD_MAZE)
    lab = tmp_path / "bom-lab.yaml"
    lab.write_bytes(BOM + GOOD_LAB.format(name="bom-lab").encode())
    assert load_lab(lab).title == "A small lab"
    users = tmp_path / "users.yaml"
    users.write_bytes(
        BOM + GOOD_USERS.format(hash=hash_password("a good password", n=2**10)).encode()
    )
    assert list(load_users(users)) == ["ann"]
