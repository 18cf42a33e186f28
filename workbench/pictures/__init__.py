"""Pictures of runs for a lab report, drawn from run records (``docs/pictures.md``).

- ``runs.py``: the records a picture is drawn from, read and checked, with their maze
  (:func:`load_runs`, :class:`PictureError` for everything that cannot be drawn).
- ``series.py``: what a record says over time, as plain values (wheel powers, state spans,
  turns and contacts).
- ``words.py``: the caption and the graded figures in the words the app uses.
- ``draw_maze.py``, ``draw_time.py``, ``draw_compare.py``: the three kinds, drawn with
  matplotlib (imported only inside the functions that draw).
- ``render.py``: the kinds by name, a picture as bytes (the same record gives the same bytes)
  and a picture saved whole (:func:`save_picture`).
- ``naming.py``: the names of pictures saved for a maze or a run.
"""

#: the kinds of picture (``render.KINDS`` holds how each is drawn), here for the command line's
#: options, which must not load the drawing code when the app starts
KIND_NAMES = ("path", "time", "compare")
