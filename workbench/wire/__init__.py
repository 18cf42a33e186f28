"""The wire between a door and a served app: what the app is started with and how the two speak.

Both doors to a served workbench (the SSH lab server, ``workbench.ssh``, and the browser door,
``workbench.web``) and the app itself (``workbench.tui``) import this package, so no door
imports the app to start it:

  * ``settings``: :class:`~.settings.AppSettings`, the one value the app starts from, sent to a
    served app as a JSON object;
  * ``packets``: Textual's web-driver packets, the protocol on the app process's pipes.

It imports no Textual (an import-linter contract keeps it so).
"""
