"""Other students' key-to-screen times while one student (or someone without an account)
attacks the SSH lab server, measured on loopback.

Starts ``workbench serve-ssh`` (default limits) in a session of its own, as ``ssh_load.py``
does, with --students honest students who log in from addresses of their own, pass the names
dialog and drive at 20 keys a second, probing key-to-screen time every 2 s (``p`` until
``PAUSED`` shows, ``p`` until ``running`` shows). Each phase runs one attack beside them for
--seconds:

- ``none``: no attack (the baseline);
- ``connections``: mallory opens logged-in connections without sessions as fast as she can
  (the server caps her at --max-connections-per-user, default 10);
- ``flood``: 10 addresses hold 10 idle connections each (the caps on connections not logged in)
  and open new ones as the old ones close; the phase also times how long a new student from a
  fresh address takes to get in, retrying every half second;
- ``terminal``: two of mallory's sessions ask for a 65535x65535 terminal and send window
  changes between huge and small sizes without pause (clamped to 500x200, passed on at most
  every 0.1 s, so her apps draw a 500x200 screen ten times a second: as near to pinning a core
  as a student gets).

Usage: ``python bench/ssh_attacks.py [--students 4] [--seconds 20] [--only flood]``.
Figures vary from run to run; the machine is shared by the clients, the server and the apps.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import sys
import tempfile
import time
from pathlib import Path

import asyncssh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT))

from ssh_load import Result, Student, free_port, pct, start_server, student_address  # noqa: E402

from workbench.ssh.users import add_user  # noqa: E402

PHASES = ("none", "connections", "flood", "terminal")


async def drive(student: Student, seconds: float, ready: asyncio.Event) -> None:
    """Log in, reach the main screen, then drive and probe for ``seconds``."""
    async with student.terminal() as write:
        if write is None:
            return
        if not await student.wait_for(b"Who is at this robot", 0, 120):
            student.result.failures.append(f"{student.name}: no names dialog")
            return
        mark = len(student.buffer)
        write(b"\r")
        if not await student.wait_for(b"running", mark, 60):
            student.result.failures.append(f"{student.name}: no main screen")
            return
        ready.set()
        end = time.perf_counter() + seconds
        step = 0
        next_probe = time.perf_counter() + 1.0
        while time.perf_counter() < end:
            if time.perf_counter() >= next_probe:
                await student.probe(write)
                next_probe = time.perf_counter() + 2.0
            write(b"wwwwawwwwdww wwwwdwwwwaww "[step % 26 : step % 26 + 1])
            step += 1
            await asyncio.sleep(0.05)


# -- the attacks ---------------------------------------------------------------------------------
async def connect(port: int, name: str, key, address: str = "127.0.0.1", **kw):
    return await asyncssh.connect(
        "127.0.0.1", port, username=name, client_keys=[key], known_hosts=None,
        agent_path=None, local_addr=(address, 0), connect_timeout=10, **kw,
    )  # fmt: skip


async def close_all(conns: list[asyncssh.SSHClientConnection]) -> None:
    for conn in conns:
        conn.close()
    await asyncio.gather(*(conn.wait_closed() for conn in conns))


async def hog_connections(port: int, key, notes: list[str]) -> None:
    held, refused = [], 0
    try:
        while True:
            try:
                held.append(await connect(port, "mallory", key, "127.0.8.1"))
            except (OSError, asyncssh.Error):
                refused += 1
            await asyncio.sleep(0)
    finally:
        open_ = [c for c in held if not c.is_closed()]
        refused += len(held) - len(open_)  # let in, then closed with the reason
        notes.append(f"mallory held {len(open_)} connections; {refused} more refused")
        await close_all(held)


async def let_go(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    """Close a connection that never logged in, and wait until the server has let go of it:
    our end of the stream is shut, and the server, seeing that, drops the connection (and
    its place at the login) and closes its end, which reads here as the end of the stream."""
    with contextlib.suppress(OSError):
        if not writer.is_closing():
            writer.write_eof()
            while await asyncio.wait_for(reader.read(4096), RELEASE_TIMEOUT):
                pass
    writer.close()
    with contextlib.suppress(OSError):
        await writer.wait_closed()


async def flood(port: int, notes: list[str]) -> None:
    held: set[tuple[asyncio.StreamReader, asyncio.StreamWriter]] = set()

    async def hold(address: str) -> None:
        while True:
            try:
                pair = await asyncio.open_connection("127.0.0.1", port, local_addr=(address, 0))
            except OSError:
                await asyncio.sleep(0.1)
                continue
            held.add(pair)
            reader, writer = pair
            with contextlib.suppress(OSError):
                while await reader.read(4096):
                    pass
            held.discard(pair)
            writer.close()

    tasks = [asyncio.create_task(hold(f"127.0.9.{a}")) for a in range(1, 11) for _ in range(10)]
    started = time.perf_counter()
    tries = 0
    try:
        await asyncio.sleep(1.0)  # the places are full
        started = time.perf_counter()
        while True:
            tries += 1
            try:
                conn = await connect(port, "late", LATE_KEY, "127.0.10.1")
                await close_all([conn])
                break
            except (OSError, asyncssh.Error):
                await asyncio.sleep(0.5)
        notes.append(
            f"a new student got in after {time.perf_counter() - started:.1f} s ({tries} tries)"
        )
        await asyncio.Event().wait()
    finally:
        if not notes:
            notes.append(
                f"a new student did not get in within {time.perf_counter() - started:.1f} s "
                f"({tries} tries)"
            )
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        # the next phase's logins find the places at the login free again
        await asyncio.gather(*(let_go(*pair) for pair in held))


async def storm_terminal(port: int, key, notes: list[str]) -> None:
    conns, changes = [], 0
    try:
        procs = []
        for n in range(2):
            conn = await connect(port, "mallory", key, f"127.0.8.{n + 2}")
            conns.append(conn)
            procs.append(
                await conn.create_process(
                    term_type="xterm-256color", term_size=(65535, 65535), encoding=None
                )
            )
        for proc in procs:
            proc.stdin.write(b"\r")  # past the names dialog
        while True:
            for proc in procs:
                size = (65535, 65535) if changes % 2 else (81 + changes % 50, 30)
                proc.change_terminal_size(*size)
                changes += 1
            await asyncio.sleep(0.01)
    finally:
        notes.append(f"mallory sent {changes} window changes")
        await close_all(conns)


LATE_KEY = asyncssh.generate_private_key("ssh-ed25519")
#: seconds the server has to let go of a connection the bench closes (it takes milliseconds)
RELEASE_TIMEOUT = 30.0


async def phase(name: str, port: int, students: list[Student], keys, seconds: float):
    for student in students:
        student.result = Result()
        student.buffer.clear()
    notes: list[str] = []
    attacks = {
        "none": None,
        "connections": lambda: hog_connections(port, keys["mallory"], notes),
        "flood": lambda: flood(port, notes),
        "terminal": lambda: storm_terminal(port, keys["mallory"], notes),
    }
    readies = [asyncio.Event() for _ in students]
    drivers = [
        asyncio.create_task(drive(s, seconds, r)) for s, r in zip(students, readies, strict=True)
    ]
    # every student drives (or one could not: that is reported, not waited for)
    waits = [asyncio.create_task(r.wait()) for r in readies]
    for ready, driver in zip(waits, drivers, strict=True):
        await asyncio.wait([ready, driver], timeout=180, return_when=asyncio.FIRST_COMPLETED)
    for wait in waits:
        wait.cancel()
    if not all(r.is_set() for r in readies):
        failures = [f for s in students for f in s.result.failures] or ["no main screen in 180 s"]
        for driver in drivers:
            driver.cancel()
        await asyncio.gather(*drivers, return_exceptions=True)
        raise SystemExit(f"{name}: not every student got to drive: {failures[:3]}")
    attack = attacks[name]
    task = asyncio.create_task(attack()) if attack else None
    await asyncio.gather(*drivers)
    if task is not None:
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await task
    latency = [t for s in students for t in s.result.latency]
    failures = [f for s in students for f in s.result.failures]
    print(
        f"{name:12} key to screen p50 {pct(latency, 0.5) * 1000:5.0f} ms, "
        f"p95 {pct(latency, 0.95) * 1000:5.0f} ms ({len(latency)} probes); "
        f"{'; '.join(notes) or '-'}" + (f"; failures: {failures[:3]}" if failures else "")
    )


async def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=4)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--only", choices=PHASES, action="append")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "data"
        users = data / "ssh-users.yaml"
        keys = {}
        names = [f"s{n:02d}" for n in range(args.students)] + ["mallory"]
        for name in names:
            keys[name] = asyncssh.generate_private_key("ssh-ed25519")
            add_user(users, name, "student", [keys[name].export_public_key().decode()])
        add_user(users, "late", "student", [LATE_KEY.export_public_key().decode()])
        port = free_port()
        server = start_server(data, port, args.students + 4, fork=True)
        try:
            students = [
                Student(name, keys[name], port, Result(), student_address(n), "asyncssh", Path())
                for n, name in enumerate(names[:-1])
            ]
            for name in args.only or PHASES:
                await phase(name, port, students, keys, args.seconds)
        finally:
            server.terminate()
            server.wait(30)


if __name__ == "__main__":
    asyncio.run(main())
