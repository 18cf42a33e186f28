"""A served student's file access: their workspace and the bundled files, nothing else, however
the path is spelt; a local user's access is unconfined but never writes a bundled file."""

from __future__ import annotations

import os

import pytest

from workbench.files.workspace import (
    BUNDLED,
    LOCAL,
    FileAccess,
    OutsideWorkspace,
    workspace_folder,
)

BUNDLED_MAZE = BUNDLED[0] / "unity-default.txt"


@pytest.fixture
def served(tmp_path):
    data = tmp_path / "data"
    (data / "workbench.sqlite3").parent.mkdir(parents=True)
    (data / "workbench.sqlite3").write_text("the database")
    return FileAccess.confined_to(workspace_folder(data, "ann")), data


def test_the_workspace_is_made_private_under_the_data_folder(served):
    files, data = served
    assert files.workspace == (data / "workspaces" / "ann").resolve()
    assert files.workspace.stat().st_mode & 0o777 == 0o700


@pytest.mark.parametrize("name", ["..", "../ben", "a/b", "", ".hidden", "x" * 80])
def test_a_name_that_would_walk_out_cannot_name_a_workspace(tmp_path, name):
    with pytest.raises(ValueError, match="cannot name a workspace"):
        workspace_folder(tmp_path, name)


def test_paths_in_the_workspace_are_read_and_written_however_spelt(served):
    files, _ = served
    root = files.workspace
    spellings = ("maze.txt", "~/maze.txt", "./maze.txt", "sub/../maze.txt", str(root / "maze.txt"))
    for typed in spellings:
        assert files.for_reading(typed) == root / "maze.txt"
        assert files.for_writing(typed) == root / "maze.txt"
    assert files.shown(root / "runs" / "r.jsonl") == "~/runs/r.jsonl"


@pytest.mark.parametrize(
    "typed",
    ["../../workbench.sqlite3", "~/../../workbench.sqlite3", "/etc/passwd", "~root/.bashrc",
     "../ben/maze.txt", "/"],
)  # fmt: skip
def test_paths_outside_the_workspace_are_refused_before_anything_is_read(served, typed):
    files, _ = served
    with pytest.raises(OutsideWorkspace) as refused:
        files.for_reading(typed)
    assert "workspace" in str(refused.value)
    assert "the database" not in str(refused.value)
    with pytest.raises(OutsideWorkspace):
        files.for_writing(typed)


def test_a_symlink_in_the_workspace_does_not_lead_out(served):
    files, data = served
    os.symlink(data / "workbench.sqlite3", files.workspace / "innocent.txt")
    os.symlink(data, files.workspace / "folder")
    for typed in ("innocent.txt", "folder/workbench.sqlite3", "folder/new.txt"):
        with pytest.raises(OutsideWorkspace):
            files.for_reading(typed)
        with pytest.raises(OutsideWorkspace):
            files.for_writing(typed)


def test_bundled_files_are_read_but_never_written(served, tmp_path):
    files, _ = served
    assert files.for_reading(BUNDLED_MAZE) == BUNDLED_MAZE.resolve()
    with pytest.raises(OutsideWorkspace, match="bundled file, kept as shipped"):
        files.for_writing(BUNDLED_MAZE)
    # nor on a person's own machine
    with pytest.raises(OutsideWorkspace, match="bundled file"):
        LOCAL.for_writing(BUNDLED_MAZE)
    assert LOCAL.for_writing(tmp_path / "mine.txt") == tmp_path / "mine.txt"
    assert LOCAL.for_reading("~/x.txt") == LOCAL.resolve("~/x.txt")


@pytest.mark.parametrize("access", [LOCAL, None])
def test_a_path_with_control_characters_is_refused_not_crashed_on(served, access):
    files = access or served[0]
    for typed in ("maze\x00.txt", "a\nb", "x\x1b[2J"):
        with pytest.raises(OutsideWorkspace, match="control characters"):
            files.for_reading(typed)
