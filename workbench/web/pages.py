"""The browser door's two pages: the login form and the workbench's terminal.

Neither has a script or style of its own inline: the terminal page loads xterm.js, its fit
addon and ``workbench.js`` from ``/static/`` (the Content-Security-Policy allows nothing
else), and reads its form token and the user's name from ``data-`` attributes. The fonts are
the browser's own monospace ones.
"""

from __future__ import annotations

from html import escape

_HEAD = """<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<link rel="stylesheet" href="/static/workbench.css">
{extra}</head>
"""


def login_page(csrf: str, message: str = "", *, header_mode: bool = False) -> str:
    """The login form (with ``message`` above it, such as why the last try failed)."""
    said = f'<p class="message" role="alert">{escape(message)}</p>' if message else ""
    if header_mode:
        body = (
            "<p>This workbench is reached through the course's sign-on page; "
            "open it from there.</p>"
        )
    else:
        body = f"""<form method="post" action="/login">
<input type="hidden" name="csrf" value="{escape(csrf)}">
<label>Login name <input name="user" autocomplete="username" required maxlength="64"
 autofocus></label>
<label>Password <input name="password" type="password" autocomplete="current-password"
 required maxlength="1024"></label>
<button type="submit">Log in</button>
</form>"""
    return (
        _HEAD.format(title="VIPLE Maze Lab Workbench: log in", extra="")
        + f"""<body class="login"><main>
<h1>VIPLE Maze Lab Workbench</h1>
{said}
{body}
<p class="hint">Your login is the one the course gave you for the lab server.</p>
</main></body></html>
"""
    )


def terminal_page(user: str, role: str, csrf: str) -> str:
    """The workbench's page: the terminal, and the files panel."""
    extra = (
        '<link rel="stylesheet" href="/static/xterm.css">\n'
        '<script src="/static/xterm.js" defer></script>\n'
        '<script src="/static/addon-fit.js" defer></script>\n'
        '<script src="/static/workbench.js" defer></script>\n'
    )
    return (
        _HEAD.format(title=f"Workbench: {escape(user)}", extra=extra)
        + f"""<body class="workbench" data-user="{escape(user)}" data-role="{escape(role)}"
 data-csrf="{escape(csrf)}">
<header><span class="who">{escape(user)} ({escape(role)})</span>
<button type="button" id="files-button" aria-controls="files">Files</button>
<form method="post" action="/logout" class="logout">
<input type="hidden" name="csrf" value="{escape(csrf)}">
<button type="submit">Log out</button></form></header>
<div id="notice" role="status" hidden></div>
<div id="terminal"></div>
<section id="files" hidden aria-label="Files">
<form id="upload" method="post" action="/files" enctype="multipart/form-data">
<input type="hidden" name="csrf" value="{escape(csrf)}">
<label>Send a program or maze to your workspace <input type="file" name="file"
 required></label>
<button type="submit">Upload</button></form>
<p id="upload-result" role="status"></p>
<h2>Your workspace</h2><p id="folder"></p><ul id="listing"></ul>
</section>
</body></html>
"""
    )
