"""Widgets of the workbench app."""

from .maze_view import MazeView

__all__ = ["MazeView"]
