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
  fresh address takes to get in, retrying every half second, from 1 s into the flood and again
  from 10 s in, and counts what the server told the flood's connections it closed;
- ``terminal``: two of mallory's sessions ask for a 65535x65535 terminal and send window
  changes between huge and small sizes without pause (clamped to 500x200, passed on at most
  every 0.1 s, so her apps draw a 500x200 screen ten times a second: as near to pinning a core
  as a student gets);
- ``program-NAME``: mallory loads a hostile VIPLE program of ``tests/program/hostile.py``
  (``merge_spin``, ``join_nesting``, ``join_doubling``, ``number_doubling``, ``record_flood``)
  from her workspace in her app and starts it; the phase notes when her screen said the program
  stopped, if it did.
- ``uploads``: mallory uploads a 4 MB program over and over with OpenSSH's ``sftp`` on three
  connections at once (put, then rm, so her quota never stops her), as fast as they go; the
  phase gives the upload throughput the server kept up (from its log's transfer lines) and,
  before the students start, one 4 MB upload's time with nothing else running.
- ``channels``: mallory opens session channels that ask for nothing, as fast as they open, on
  10 connections (capped at 10 channels each, each closed after the 10 s grace);
- ``sftp-reads``: mallory asks for 64 KiB READs of her own 4.9 MB file on one SFTP channel and
  never reads a reply (the server stops reading her requests while its reply buffer is full);
- ``listings``: mallory lists a folder of 1,500 files of hers without pause on three SFTP
  channels;
- ``keys``: mallory sends her own app 64 KiB of typed keys, waits for her screen to say keys
  were dropped, then types ``p``, over and over, and notes how long her app took to say so and
  to answer the ``p``.

Each phase also gives the server process's peak resident memory (sampled every 0.1 s) beside
what it had at the phase's start.

Usage: ``python bench/ssh_attacks.py [--students 4] [--seconds 20] [--only flood]``.
Figures vary from run to run; the machine is shared by the clients, the server and the apps.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import asyncssh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT))

from ssh_load import Result, Student, free_port, pct, start_server, student_address  # noqa: E402

from tests.integration.sftp_support import raw_sftp_open, sftp_read  # noqa: E402
from tests.integration.ssh_support import open_bare_channel  # noqa: E402
from tests.program import hostile  # noqa: E402
from workbench.door.users import add_user  # noqa: E402
from workbench.files.workspace import workspace_folder  # noqa: E402

PROGRAMS = ("merge_spin", "join_nesting", "join_doubling", "number_doubling", "record_flood")
PHASES = (
    "none",
    "connections",
    "flood",
    "terminal",
    "uploads",
    "channels",
    "sftp-reads",
    "listings",
    "keys",
    *(f"program-{p}" for p in PROGRAMS),
)
UPLOAD = 4_000_000
#: mallory's own upload that ``sftp-reads`` reads, and the folder ``listings`` lists
READ_BACK = 4_900_000
LISTED_FILES = 1500  # with the rest of her files, within the 2,000 files she may keep


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


async def late_login(port: int, address: str) -> tuple[float, int]:
    """Seconds until a new student from ``address`` gets in, retrying every half second, and
    the tries it took."""
    started = time.perf_counter()
    tries = 0
    while True:
        tries += 1
        try:
            conn = await connect(port, "late", LATE_KEY, address)
            await close_all([conn])
            return time.perf_counter() - started, tries
        except (OSError, asyncssh.Error):
            await asyncio.sleep(0.5)


async def flood(port: int, notes: list[str]) -> None:
    held: set[tuple[asyncio.StreamReader, asyncio.StreamWriter]] = set()
    #: what the server told the flood's connections it closed
    told: Counter[str] = Counter()

    async def hold(address: str) -> None:
        while True:
            try:
                pair = await asyncio.open_connection("127.0.0.1", port, local_addr=(address, 0))
            except OSError:
                await asyncio.sleep(0.1)
                continue
            held.add(pair)
            reader, writer = pair
            said = b""
            with contextlib.suppress(OSError):
                while chunk := await reader.read(4096):
                    said = (said + chunk)[-400:]
            held.discard(pair)
            writer.close()
            if b"to make room" in said:
                told["closed to make room"] += 1
            elif b"too many connections waiting" in said:
                told["turned away at once"] += 1
            else:
                told["closed otherwise"] += 1

    tasks = [asyncio.create_task(hold(f"127.0.9.{a}")) for a in range(1, 11) for _ in range(10)]
    began = time.perf_counter()
    try:
        await asyncio.sleep(1.0)  # the places are full
        seconds, tries = await late_login(port, "127.0.10.1")
        notes.append(f"a new student got in after {seconds:.1f} s ({tries} tries)")
        await asyncio.sleep(max(0.0, began + 10.0 - time.perf_counter()))
        seconds, tries = await late_login(port, "127.0.10.2")
        notes.append(f"another, 10 s into the flood, after {seconds:.1f} s ({tries} tries)")
        await asyncio.Event().wait()
    finally:
        if not notes:
            notes.append(
                f"a new student did not get in within {time.perf_counter() - began - 1:.1f} s"
            )
        tally = ", ".join(f"{n} {what}" for what, n in told.most_common())
        notes.append(f"the flood's connections: {tally}")
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


async def run_program(port: int, key, name: str, notes: list[str]) -> None:
    """Mallory loads ``~/NAME.viple`` in the algorithm dialog and starts it, then watches."""
    mallory = Student("mallory", key, port, Result(), "127.0.8.9", "asyncssh", Path())
    stage = "logging in"
    began = time.perf_counter()
    try:
        async with mallory.terminal() as write:
            if write is None or not await mallory.wait_for(b"Who is at this robot", 0, 60):
                return
            write(b"\r")
            if not await mallory.wait_for(b"running", 0, 60):
                return
            stage = "opening the algorithm dialog"
            mark = len(mallory.buffer)
            write(b"g")
            if not await mallory.wait_for(b"Built-in", mark, 10):
                return
            write(b"\t")
            await asyncio.sleep(0.3)
            stage = "loading the program"
            mark = len(mallory.buffer)
            write(f"~/{name}.viple\r".encode())
            if not await mallory.wait_for(b"runs it", mark, 30):  # "Start (or x) runs it"
                return
            await asyncio.sleep(0.5)  # the Start button has the focus
            stage = "running the program"
            mark = len(mallory.buffer)
            started = time.perf_counter()
            write(b"\r")  # Start
            if await mallory.wait_for(b"stopped", mark, 3600):  # the program, or its record
                line = re.search(rb"(program|recording) stopped[^\x1b]{0,60}", mallory.buffer)
                said = line.group().decode(errors="replace").strip() if line else "stopped"
                stage = f"{said!r} {time.perf_counter() - started:.1f} s after it started"
            await asyncio.Event().wait()
    finally:
        shown = re.sub(rb"\x1b\[[0-9;?]*[A-Za-z]", b" ", bytes(mallory.buffer[-3000:]))
        tail = "" if "after it started" in stage else f"; her screen ends {shown[-200:]!r}"
        notes.append(f"mallory's program: {stage} ({time.perf_counter() - began:.0f} s){tail}")


def sftp_argv(port: int, key_file: Path, batch: Path, address: str) -> list[str]:
    return [
        "sftp", "-F", "/dev/null", "-i", str(key_file), "-P", str(port),
        "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
        "-o", "BatchMode=yes", "-o", "LogLevel=ERROR", "-o", f"BindAddress={address}",
        "-b", str(batch), "mallory@127.0.0.1",
    ]  # fmt: skip


def upload_files(folder: Path, streams: int) -> tuple[Path, list[Path]]:
    """A 4 MB program and, for each stream, a batch putting and removing it 500 times."""
    big = folder / "big.viple"
    big.write_bytes(os.urandom(UPLOAD))
    batches = []
    for s in range(streams):
        batch = folder / f"batch-{s}"
        lines = [f"put {big} u{s}-{i}.viple\nrm u{s}-{i}.viple" for i in range(500)]
        batch.write_text("\n".join(lines) + "\n")
        batches.append(batch)
    one = folder / "batch-one"
    one.write_text(f"put {big} one.viple\nrm one.viple\n")
    return one, batches


def uploaded(log: Path, since: int) -> int:
    """Bytes of mallory's uploads done, in the server's log after offset ``since``."""
    text = log.read_text(errors="replace")[since:]
    return sum(int(n) for n in re.findall(r"sftp: mallory write /\S+: (\d+) bytes: done", text))


async def upload_flood(port: int, folder: Path, data: Path, notes: list[str]) -> None:
    log = data / "ssh.log"
    since = len(log.read_text(errors="replace"))
    started = time.perf_counter()
    procs = [
        subprocess.Popen(
            sftp_argv(port, folder / "mallory.key", folder / f"batch-{s}", f"127.0.8.{s + 5}"),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        for s in range(3)
    ]
    try:
        await asyncio.Event().wait()
    finally:
        for proc in procs:
            proc.terminate()
            proc.wait()
        seconds = time.perf_counter() - started
        done = uploaded(log, since)
        notes.append(
            f"mallory uploaded {done / 1e6:.0f} MB in {seconds:.0f} s on 3 connections: "
            f"{done / 1e6 / seconds:.1f} MB/s"
        )


def upload_alone(port: int, folder: Path) -> float:
    """Seconds one 4 MB upload (and its rm) takes with nothing else running."""
    started = time.perf_counter()
    argv = sftp_argv(port, folder / "mallory.key", folder / "batch-one", "127.0.8.9")
    subprocess.run(argv, check=True, capture_output=True, timeout=120)
    return time.perf_counter() - started


async def flood_channels(port: int, key, notes: list[str]) -> None:
    conns = [await connect(port, "mallory", key, f"127.0.8.{20 + n}") for n in range(10)]
    held: list = []
    opened = refused = 0
    try:
        while True:
            for conn in conns:
                try:
                    held.append(await open_bare_channel(conn))
                    opened += 1
                except asyncssh.ChannelOpenError:
                    refused += 1
            held = [(chan, s) for chan, s in held if not s.closed.is_set()]
            await asyncio.sleep(0)
    finally:
        notes.append(
            f"mallory opened {opened} channels ({len(held)} open at the end), {refused} refused"
        )
        await close_all(conns)


async def read_never_read_back(port: int, key, notes: list[str]) -> None:
    conn = await connect(port, "mallory", key, "127.0.8.30")
    chan, _, handle = await raw_sftp_open(conn, b"/read-back.bin")
    chan.pause_reading()
    sent = 0
    try:
        while True:
            if chan.get_write_buffer_size() < 1_000_000:  # the client's own side bounded
                for _ in range(100):
                    offset = (sent * 65536) % (READ_BACK - 65536)
                    chan.write(sftp_read(3 + sent, handle, offset, 65536))
                    sent += 1
            await asyncio.sleep(0.01)
    finally:
        waiting = chan.get_write_buffer_size()
        notes.append(f"mallory asked for {sent} reads of 64 KiB ({waiting} bytes not yet taken)")
        await close_all([conn])


async def list_without_pause(port: int, key, notes: list[str]) -> None:
    conns = [await connect(port, "mallory", key, f"127.0.8.{40 + n}") for n in range(3)]
    listings = 0

    async def lister(conn) -> None:
        nonlocal listings
        async with conn.start_sftp_client() as sftp:
            while True:
                await sftp.listdir("/many")
                listings += 1

    tasks = [asyncio.create_task(lister(c)) for c in conns]
    try:
        await asyncio.Event().wait()
    finally:
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        notes.append(f"mallory listed {LISTED_FILES} files {listings} times on 3 channels")
        await close_all(conns)


async def key_flood(port: int, key, notes: list[str]) -> None:
    mallory = Student("mallory", key, port, Result(), "127.0.8.50", "asyncssh", Path())
    answers: list[tuple[float, float]] = []
    try:
        async with mallory.terminal() as write:
            if write is None or not await mallory.wait_for(b"Who is at this robot", 0, 60):
                return
            write(b"\r")
            if not await mallory.wait_for(b"running", 0, 60):
                return
            paused = False
            while True:
                mark = len(mallory.buffer)
                started = time.perf_counter()
                write(b"z" * 65536)
                if not await mallory.wait_for(b"dropped", mark, 300):  # the line may wrap
                    return
                told = time.perf_counter() - started
                mark = len(mallory.buffer)
                started = time.perf_counter()
                write(b"p")
                paused = not paused
                if not await mallory.wait_for(b"PAUSED" if paused else b"running", mark, 300):
                    return
                answers.append((told, time.perf_counter() - started))
    finally:
        shown = ", ".join(f"{t:.2f}/{a:.2f}" for t, a in answers[:6])
        notes.append(
            f"mallory sent {len(answers)} floods of 64 KiB of keys; her app said keys were "
            f"dropped / answered her next key after {shown or '-'} s"
        )


def resident_mb(pid: int) -> float:
    """The resident memory of process ``pid`` in MB (0 when it cannot be read)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1000
    except OSError:
        pass
    return 0.0


async def peak_memory(pid: int, peak: list[float]) -> None:
    while True:
        peak[0] = max(peak[0], resident_mb(pid))
        await asyncio.sleep(0.1)


LATE_KEY = asyncssh.generate_private_key("ssh-ed25519")
#: seconds the server has to let go of a connection the bench closes (it takes milliseconds)
RELEASE_TIMEOUT = 30.0


async def phase(
    name: str,
    port: int,
    students: list[Student],
    keys,
    seconds: float,
    folder: Path,
    data: Path,
    server_pid: int,
):
    for student in students:
        student.result = Result()
        student.buffer.clear()
    notes: list[str] = []
    attacks = {
        "none": None,
        "connections": lambda: hog_connections(port, keys["mallory"], notes),
        "flood": lambda: flood(port, notes),
        "terminal": lambda: storm_terminal(port, keys["mallory"], notes),
        "uploads": lambda: upload_flood(port, folder, data, notes),
        "channels": lambda: flood_channels(port, keys["mallory"], notes),
        "sftp-reads": lambda: read_never_read_back(port, keys["mallory"], notes),
        "listings": lambda: list_without_pause(port, keys["mallory"], notes),
        "keys": lambda: key_flood(port, keys["mallory"], notes),
    }
    for program in PROGRAMS:
        attacks[f"program-{program}"] = lambda program=program: run_program(
            port, keys["mallory"], program, notes
        )
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
    at_start = resident_mb(server_pid)
    peak = [at_start]
    sampler = asyncio.create_task(peak_memory(server_pid, peak))
    task = asyncio.create_task(attack()) if attack else None
    await asyncio.gather(*drivers)
    if task is not None:
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await task
    sampler.cancel()
    notes.append(f"server memory {at_start:.0f} MB at the start, peak {peak[0]:.0f} MB")
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
        workspace = workspace_folder(data, "mallory")
        workspace.mkdir(parents=True, exist_ok=True)
        for program in PROGRAMS:
            (workspace / f"{program}.viple").write_text(getattr(hostile, program)())
        keys["mallory"].write_private_key(Path(tmp) / "mallory.key")
        (Path(tmp) / "mallory.key").chmod(0o600)
        upload_files(Path(tmp), 3)
        (workspace / "read-back.bin").write_bytes(os.urandom(READ_BACK))
        (workspace / "many").mkdir()
        for n in range(LISTED_FILES):
            (workspace / "many" / f"f{n:04d}.txt").write_text("x")
        port = free_port()
        server = start_server(data, port, args.students + 4, fork=True)
        try:
            if "uploads" in (args.only or PHASES):
                alone = upload_alone(port, Path(tmp))
                print(f"one 4 MB upload alone (sftp put and rm): {alone:.2f} s")
            students = [
                Student(name, keys[name], port, Result(), student_address(n), "asyncssh", Path())
                for n, name in enumerate(names[:-1])
            ]
            for name in args.only or PHASES:
                await phase(name, port, students, keys, args.seconds, Path(tmp), data, server.pid)
        finally:
            server.terminate()
            server.wait(30)


if __name__ == "__main__":
    asyncio.run(main())
