"""The browser door: the same served workbench as over SSH, in a web page.

``workbench serve-web`` serves a login page, a page with a terminal (xterm.js, vendored in
``static/``) and one WebSocket per open page, over which the student's own app process (forked
from the fork server with the session's settings, as the SSH server starts it:
``workbench.door``) sends its screen and takes keys and sizes.

  * ``config``: what the server is started with (the options of ``serve-web``);
  * ``cookies``: the logins of browsers, known by random ids kept on the server, and the
    CSRF tokens of their forms;
  * ``gate``: connections that have sent no request yet, under the SSH server's caps and
    early drop for connections not logged in;
  * ``proxy``: the trusted-header mode (an authenticating proxy names the user) and the
    client's address behind a proxy;
  * ``relay``: one student's app and the page attached to it, kept through a reload for a
    grace period, taken over by a second tab;
  * ``transfer``: uploads into the workspace and downloads of run records and pictures, under
    the file server's rules;
  * ``pages``: the HTML of the login page and the terminal page;
  * ``server``: the HTTP and WebSocket server tying them together.
"""
