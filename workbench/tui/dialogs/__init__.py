"""Dialogs of the workbench app: modal boxes over a screen, one module each.

``frame`` holds the titled box with its error line and buttons that the small dialogs share.
"""
