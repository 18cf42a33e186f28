"""The pictures by what they hold: one point per recorded pose, every wall block and
collision, the caption's figures, the requested size, and the same bytes every time."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest
from PIL import Image

from tests.pictures.records import BEND, LOOP, lines, record_of, write_lines
from tests.pictures.svg import marks, path_points, rectangle_area, subpaths, texts
from workbench.pictures.render import PictureSpec, render, save_picture
from workbench.pictures.runs import load_runs


def _ticks(record) -> int:
    return sum("type" not in obj for obj in lines(record))


def _walls(text: str) -> int:
    return text.split("---\n")[-1].count("#")


def test_the_path_has_one_point_per_pose_and_every_wall(tmp_path):
    record = record_of(tmp_path)
    svg = render(load_runs([record]), PictureSpec("path"))
    assert path_points(svg, "robot-path") == _ticks(record) > 20
    # the walls are drawn as few rectangles; together they cover every wall block, counted by
    # the area of one block (the exit's square)
    assert subpaths(svg, "maze-exits") == 1
    block = rectangle_area(svg, "maze-exits")
    assert rectangle_area(svg, "maze-walls") / block == pytest.approx(_walls(BEND), abs=0.01)
    assert _walls(BEND) == 24
    assert subpaths(svg, "maze-walls") < 24  # (rows of wall are one rectangle each)


def test_collisions_and_turns_are_marked(tmp_path):
    record = record_of(tmp_path, text=LOOP, name="loop.txt")
    objects = lines(record)
    ticks = [o for o in objects if "type" not in o]
    for tick in (ticks[5], ticks[9], ticks[30]):
        tick["events"] = [*tick.get("events", []), "collision"]
    bumped = write_lines(tmp_path / "bumped.jsonl", objects)
    svg = render(load_runs([bumped]), PictureSpec("path"))
    assert marks(svg, "collisions") == 3
    summary = objects[-1]
    assert marks(svg, "turns") == summary["turns"] > 0
    words = texts(svg)
    assert f"{summary['turns']} turns" in words
    assert (
        f"distance {summary['distance']:.0f} px ({summary['distance_cells']:.1f} blocks)" in words
    )
    assert "Loop (erobotic) | driver: algorithm right-wall" in words


def test_beams_at_chosen_moments(tmp_path):
    record = record_of(tmp_path)
    svg = render(load_runs([record]), PictureSpec("path", at=(0.0, 2.0)))
    # two distance sensors each time: a beam of two points each
    assert path_points(svg, "beams-1") == path_points(svg, "beams-2") == 4
    assert "t 2.0 s" in texts(svg)


def test_over_time_shows_each_sensor_the_wheels_and_the_states(tmp_path):
    record = record_of(tmp_path)
    svg = render(load_runs([record]), PictureSpec("time"))
    n = _ticks(record)
    header = lines(record)[0]
    ports = [s.split(":")[1] for s in header["sensors"]]
    for port in ports:
        # every reading, less the points that lie on the line between their neighbours
        assert 10 < path_points(svg, f"sensor-{port}") <= n
    words = texts(svg)
    states = {o["state"] for o in lines(record) if "state" in o}
    for state in states:
        assert state in words
    assert "wheel power" in words and "state" in words


def test_side_by_side_has_a_map_per_run_and_bars_per_figure(tmp_path):
    a = record_of(tmp_path, "right-wall", text=LOOP, name="loop.txt")
    b = record_of(tmp_path, "farthest-distance", text=LOOP, name="loop.txt")
    svg = render(load_runs([a, b]), PictureSpec("compare"))
    # each path keeps its corners at least (small maps leave out the points between them)
    for k, record in enumerate((a, b), start=1):
        turns = lines(record)[-1]["turns"]
        assert turns + 2 <= path_points(svg, f"robot-path-{k}") <= _ticks(record)
    words = texts(svg)
    assert "2 runs side by side" in words
    for title in ("time (s)", "distance (blocks)", "turning (°)", "turns", "collisions"):
        assert title in words
    turns = [lines(r)[-1]["turns"] for r in (a, b)]
    assert all(str(t) in words.split("\n") for t in turns)


def test_the_png_has_the_size_asked_for(tmp_path):
    record = record_of(tmp_path)
    for kind in ("path", "time", "compare"):
        png = render(load_runs([record]), PictureSpec(kind, "png", size=(640, 480)))
        image = Image.open(io.BytesIO(png))
        assert image.format == "PNG"
        assert image.size == (640, 480)


def test_the_same_record_gives_the_same_bytes(tmp_path):
    record = record_of(tmp_path)
    for kind, fmt in (("path", "svg"), ("path", "png"), ("time", "svg"), ("compare", "png")):
        spec = PictureSpec(kind, fmt, at=(1.0,))
        assert render(load_runs([record]), spec) == render(load_runs([record]), spec)
    svg = render(load_runs([record]), PictureSpec("path"))
    assert b"<dc:date>" not in svg and b"Matplotlib" not in svg and b"matplotlib.org" not in svg
    png = render(load_runs([record]), PictureSpec("path", "png"))
    assert b"Software" not in png and b"matplotlib" not in png.lower()


def test_another_process_draws_the_same_bytes(tmp_path):
    record = record_of(tmp_path)
    for suffix in (".svg", ".png"):
        here = tmp_path / f"here{suffix}"
        save_picture(load_runs([record]), here)
        there = tmp_path / f"there{suffix}"
        code = (
            "from workbench.pictures.render import save_picture\n"
            "from workbench.pictures.runs import load_runs\n"
            f"save_picture(load_runs([{str(record)!r}]), {str(there)!r})\n"
        )
        subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
        assert there.read_bytes() == here.read_bytes()
