"""A picture is written whole or not at all: a drawing that fails or a folder that cannot be
written leaves the old file as it was and no piece of the new one."""

from __future__ import annotations

import os

import pytest

from tests.pictures.records import record_of
from workbench.files.workspace import FileAccess
from workbench.pictures import render as render_module
from workbench.pictures.render import PictureSpec, save_picture
from workbench.pictures.runs import PictureError, load_runs


def test_a_drawing_that_fails_leaves_the_old_picture(tmp_path, monkeypatch):
    runs = load_runs([record_of(tmp_path)])
    target = tmp_path / "out" / "bend.svg"
    target.parent.mkdir()
    save_picture(runs, target)
    before = target.read_bytes()

    def broken(fig, runs, at):
        fig.add_subplot(1, 1, 1).plot([0, 1], [0, 1])
        raise MemoryError("out of memory half-way")

    kind = render_module.KINDS["path"]
    monkeypatch.setitem(
        render_module.KINDS, "path", render_module.Kind(kind.name, kind.what, kind.size, broken)
    )
    with pytest.raises(MemoryError):
        save_picture(runs, target)
    assert target.read_bytes() == before
    assert os.listdir(target.parent) == ["bend.svg"]


def test_a_folder_that_cannot_be_written(tmp_path):
    runs = load_runs([record_of(tmp_path)])
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        if os.access(folder, os.W_OK):
            pytest.skip("running as a user every folder is writable to")
        with pytest.raises(PictureError, match=r"locked/bend.png: cannot write it .*folder"):
            save_picture(runs, folder / "bend.png")
        assert os.listdir(folder) == []
    finally:
        folder.chmod(0o700)


def test_a_folder_that_is_not_there(tmp_path):
    runs = load_runs([record_of(tmp_path)])
    with pytest.raises(PictureError, match=r"nowhere/bend.svg: its folder does not exist"):
        save_picture(runs, tmp_path / "nowhere" / "bend.svg")


def test_a_name_that_is_not_a_picture(tmp_path):
    runs = load_runs([record_of(tmp_path)])
    with pytest.raises(PictureError, match=r"bend.pdf: a picture is saved as .svg or .png"):
        save_picture(runs, tmp_path / "bend.pdf")
    assert not (tmp_path / "bend.pdf").exists()


def test_a_served_student_saves_only_in_the_workspace(tmp_path):
    workspace = tmp_path / "ws"
    files = FileAccess.confined_to(workspace)
    record = record_of(workspace)
    runs = load_runs(["bend-right-wall-erobotic.jsonl"], files=files)
    assert runs[0].path == record
    (workspace / "pictures").mkdir()
    written = save_picture(runs, "pictures/bend.svg", PictureSpec("path"), files)
    assert written == workspace.resolve() / "pictures" / "bend.svg"
    for outside in ("../bend.svg", "/tmp/bend.svg", "~other/bend.svg"):
        with pytest.raises(PictureError, match=r"outside your workspace|another user"):
            save_picture(runs, outside, PictureSpec("path"), files)
    assert not (tmp_path / "bend.svg").exists()


def test_a_folder_that_is_a_file(tmp_path):
    """(The locked folder's case for a user who may write anywhere, such as root.)"""
    runs = load_runs([record_of(tmp_path)])
    (tmp_path / "notes.txt").write_text("mine\n")
    with pytest.raises(PictureError, match=r"notes.txt/bend.png: cannot write it"):
        save_picture(runs, tmp_path / "notes.txt" / "bend.png")
    assert (tmp_path / "notes.txt").read_text() == "mine\n"
