"""Dialogs of the workbench app."""
