"""Reading a picture's SVG by what it holds: the points of a path and the marks of a group."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

SVG = "{http://www.w3.org/2000/svg}"


def group(svg: bytes, gid: str) -> ET.Element:
    root = ET.fromstring(svg)
    found = root.find(f".//{SVG}g[@id='{gid}']")
    assert found is not None, f"the picture has no {gid}"
    return found


def path_points(svg: bytes, gid: str) -> int:
    """How many points the paths of the group ``gid`` draw (M and L commands)."""
    return sum(
        len(re.findall(r"[ML] ", p.get("d", ""))) for p in group(svg, gid).iter(f"{SVG}path")
    )


def subpaths(svg: bytes, gid: str) -> int:
    """How many closed shapes the group ``gid`` draws (M commands)."""
    return sum(p.get("d", "").count("M ") for p in group(svg, gid).iter(f"{SVG}path"))


def marks(svg: bytes, gid: str) -> int:
    """How many markers the group ``gid`` places."""
    return len(list(group(svg, gid).iter(f"{SVG}use")))


def texts(svg: bytes) -> str:
    """Every text of the picture, one a line."""
    root = ET.fromstring(svg)
    return "\n".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))


def rectangle_area(svg: bytes, gid: str) -> float:
    """The area the axis-aligned rectangles of the group ``gid`` cover (SVG units)."""
    area = 0.0
    for p in group(svg, gid).iter(f"{SVG}path"):
        for shape in p.get("d", "").split("M ")[1:]:
            numbers = [float(v) for v in re.findall(r"-?[0-9.]+", shape)]
            xs, ys = numbers[0::2], numbers[1::2]
            area += (max(xs) - min(xs)) * (max(ys) - min(ys))
    return area
