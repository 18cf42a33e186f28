"""VIPLE programs (``.viple``, VIPLE 3.x ``.xml``): loaded, checked and run on the simulated robot.

The package is core code: it never imports Textual. :mod:`.loader` reads and checks a file,
:mod:`.viple_expr` holds VIPLE's expression language, :mod:`.interp` runs a loaded program as a
controller of a simulation session, and :mod:`.pilot` lets one drive the station's robot or a
headless run on a maze.
"""
