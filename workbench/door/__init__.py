"""What both doors to a served workbench share: the SSH lab server (``workbench.ssh``) and the
browser door (``workbench.web``) let the same students in the same way and start the same app.

  * ``users`` and ``passwords``: the course's accounts (the users file of ``ssh add-user``)
    and their scrypt password hashes;
  * ``logins`` and ``sources``: the password slow-down and lock-out, and the caps and early
    drop for connections not logged in yet, counted by source; ``checking``: a password
    checked under those rules (the door says what it makes of the verdict);
  * ``limits``: what a session may have (sessions per user and in all, the terminal size,
    memory);
  * ``appproc``, ``forkserver``, ``applog`` and ``memory``: one app process per session,
    forked from the fork server with the session's settings, its error log, and the server's
    watch on free memory;
  * ``ports``: the VIPLE ports each session is given;
  * ``course_files``: with a course database, a student's workspace brought in step at a
    session's start, and their uploads sent on;
  * ``serverlog``: the server's own log; ``workers``: the thread pools (store, passwords,
    files) so one kind of work stuck holds up no other.

Nothing here imports a door or the app (import-linter contracts keep it so).
"""
