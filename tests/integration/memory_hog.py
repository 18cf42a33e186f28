"""An app for the lab server's tests that takes memory until it has 1 GiB, 16 MiB at a time,
and then ends as if nothing happened: under a smaller cap an allocation fails first."""

from __future__ import annotations

import sys

CHUNK = 16 << 20
CHUNKS = 64


def main(options: list[str]) -> int:
    held = [bytearray(CHUNK) for _ in range(CHUNKS)]
    return 0 if len(held) == CHUNKS else 1


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
