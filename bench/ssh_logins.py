"""Password guessing and connection floods against the SSH lab server, measured on loopback.

Starts the lab server in this process (a throwaway data folder, the default login policy unless
options say otherwise) with a student `mallory` (key) and an instructor `rivera` (password), then:

1. mallory guesses rivera's password --guesses times, logging in with her own key between
   guesses from the same address (the old slow-down forgot everything on any success): the
   wait before each refusal, the total time, and what happens once the account locks (the
   right password refused, rivera's key still let in);
2. --flood TCP connections from 127.0.0.1 that never log in: how many the server holds, and
   how long a real key login from 127.0.0.2 takes during the flood, against one without it.

Figures vary a little from run to run (scrypt takes about 50 ms a check).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import logging
import sys
import tempfile
import time
from pathlib import Path

import asyncssh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from workbench.door.logins import LoginPolicy  # noqa: E402
from workbench.door.passwords import hash_password  # noqa: E402
from workbench.door.users import add_user, users_path  # noqa: E402
from workbench.ssh.server import LabServer, ServerConfig  # noqa: E402

PASSWORD = "rivera-secret-1"


async def connect(port: int, name: str, *, key=None, password=None, source="127.0.0.1"):
    return await asyncssh.connect(
        "127.0.0.1",
        port,
        username=name,
        client_keys=[key] if key else [],
        password=password,
        known_hosts=None,
        agent_path=None,
        preferred_auth=["publickey"] if key else ["password"],
        local_addr=(source, 0),
    )


async def timed_login(port: int, name: str, **kw) -> tuple[bool, float]:
    start = time.monotonic()
    try:
        conn = await connect(port, name, **kw)
    except asyncssh.PermissionDenied:
        return False, time.monotonic() - start
    conn.close()
    return True, time.monotonic() - start


async def guessing(port: int, guesses: int, mallory, rivera) -> None:
    print(f"1. {guesses} guesses at rivera's password, mallory's own key login between each")
    start = time.monotonic()
    for n in range(1, guesses + 1):
        ok, took = await timed_login(port, "rivera", password=f"guess-{n:03d}")
        await timed_login(port, "mallory", key=mallory)
        print(f"   guess {n:2d}: {'LET IN' if ok else 'refused'} after {took:5.2f} s")
    total = time.monotonic() - start
    print(f"   {guesses} guesses took {total:.1f} s ({guesses / total * 60:.1f} a minute)")
    ok, took = await timed_login(port, "rivera", password=PASSWORD)
    print(f"   the right password now: {'let in' if ok else 'refused'} after {took:.2f} s")
    ok, took = await timed_login(port, "rivera", key=rivera)
    print(f"   rivera's key now: {'let in' if ok else 'refused'} after {took:.2f} s")


async def flood(port: int, count: int, mallory) -> None:
    print(f"2. {count} connections from 127.0.0.1 that never log in")
    _, alone = await timed_login(port, "mallory", key=mallory, source="127.0.0.2")
    sockets = []
    for _ in range(count):
        with contextlib.suppress(OSError):
            sockets.append(await asyncio.open_connection("127.0.0.1", port))
    await asyncio.sleep(1.0)
    held = 0
    for reader, _ in sockets:
        try:
            async with asyncio.timeout(0.01):
                while await reader.read(4096):
                    pass
        except TimeoutError:
            held += 1  # still open
        except ConnectionError:
            pass
    ok, during = await timed_login(port, "mallory", key=mallory, source="127.0.0.2")
    print(f"   held open after 1 s: {held} of {len(sockets)}")
    print(
        f"   a key login from 127.0.0.2: {alone * 1000:.0f} ms alone, "
        f"{during * 1000:.0f} ms during the flood ({'let in' if ok else 'REFUSED'}; "
        f"ratio {during / alone:.2f})"
    )
    for _, writer in sockets:
        writer.close()


async def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--guesses", type=int, default=11)
    parser.add_argument("--flood", type=int, default=1500)
    parser.add_argument("--lock-after", type=int, default=LoginPolicy.lock_after)
    args = parser.parse_args()
    logging.basicConfig(level=logging.ERROR)
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp)
        mallory = asyncssh.generate_private_key("ssh-ed25519")
        rivera = asyncssh.generate_private_key("ssh-ed25519")
        path = users_path(data)
        add_user(path, "mallory", "student", [mallory.export_public_key().decode()], None)
        add_user(
            path,
            "rivera",
            "instructor",
            [rivera.export_public_key().decode()],
            hash_password(PASSWORD),
        )
        policy = LoginPolicy(lock_after=args.lock_after)
        print(
            f"policy: {policy.first_delay:g} s doubling to {policy.max_delay:g} s; passwords "
            f"locked for {policy.lock_for:g} s after {policy.lock_after} failures; at most "
            f"{policy.max_unauthenticated_per_address} connections not logged in per address, "
            f"{policy.max_unauthenticated} in all; {policy.login_timeout:g} s to log in"
        )
        config = ServerConfig(data, port=0, bind="127.0.0.1", logins=policy, fork_server=False)
        async with LabServer(config) as server:
            await guessing(server.port, args.guesses, mallory, rivera)
            await flood(server.port, args.flood, mallory)


if __name__ == "__main__":
    asyncio.run(main())
