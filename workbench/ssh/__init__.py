"""The SSH lab server: one workbench app process per SSH session, each with its own VIPLE ports.

Nothing here is imported by the app itself; the server starts the app as a separate process
and talks to it through Textual's web-driver packets on the process's pipes.
"""
