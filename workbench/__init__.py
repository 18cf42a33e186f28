"""VIPLE Maze Lab Workbench."""

__version__ = "0.1.0"
