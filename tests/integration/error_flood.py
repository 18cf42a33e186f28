"""An app for the lab server's tests that writes a flood of lines to its error output (about
8 MB, far past a log's cap and any pipe's buffer), then one last line, and ends as if nothing
happened: it ends only if the server reads its errors as they come."""

from __future__ import annotations

import sys

LINES = 80_000
LAST = "the flood's last line"


def main(options: object = None) -> int:
    errors = sys.stderr
    for n in range(LINES):
        errors.write(f"flood line {n:06d} " + "x" * 80 + "\n")
    errors.write(LAST + "\n")
    errors.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
