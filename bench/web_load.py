"""The browser door under load, beside the SSH door in the same run: N students at once.

Starts `workbench serve-web` on loopback (its own process, a throwaway data folder, one user per
student with a password and a key), then N WebSocket clients at the same moment, each from a
loopback address of its own: log in through the form, open the page's WebSocket at 80x24, pass
the names dialog, drive at --hz for --seconds with the pattern of ``ssh_load.py`` and time the
pause key to the screen now and then (PAUSED / running). Then the same N students over SSH
(`workbench serve-ssh`, asyncssh clients), the same way. No browser is needed.

Printed for each door: first screen (login to the names dialog on the screen, p50/p95; for
the browser door also how much of it the login took: the password's scrypt check, where the
SSH round logs in with keys),
key to screen (p50/p95), and the bytes per second each session received (its whole session:
dialog, driving and probes). Targets on loopback on 2 cores: first screen p95 <= 1 s and key to
screen p95 <= 50 ms through the browser door, and no more bytes per second per session than
over SSH. Figures vary from run to run.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import AsyncIterator, Callable
from pathlib import Path

import aiohttp
import asyncssh

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from ssh_load import (  # noqa: E402
    PROBE_EVERY,
    ROOT,
    Result,
    Student,
    free_port,
    met,
    pct,
    start_server,
    student_address,
    wait_for_spares,
)

from workbench.door.passwords import hash_password  # noqa: E402
from workbench.door.users import add_user  # noqa: E402

PASSWORD = "bench-password-1"
#: seconds each browser-door login took (the form, the password's scrypt check, the redirect)
LOGINS: list[float] = []
_CSRF = re.compile(r'name="csrf" value="([^"]+)"')


class WebStudent(Student):
    """A student through the browser door: the login form, then the page's WebSocket."""

    async def log_in(self, session: aiohttp.ClientSession, url: str) -> None:
        async with session.get(f"{url}/login") as form:
            token = _CSRF.search(await form.text())
        assert token is not None
        fields = {"csrf": token.group(1), "user": self.name, "password": PASSWORD}
        async with session.post(f"{url}/login", data=fields,
                                headers={"Origin": url}) as answer:  # fmt: skip
            if answer.url.path != "/":
                raise OSError(f"login refused ({answer.status})")

    @contextlib.asynccontextmanager
    async def terminal(self) -> AsyncIterator[Callable[[bytes], None] | None]:
        url = f"http://127.0.0.1:{self.port}"
        connector = aiohttp.TCPConnector(local_addr=(self.address, 0))
        async with aiohttp.ClientSession(
            connector=connector, cookie_jar=aiohttp.CookieJar(unsafe=True)
        ) as session:
            began = time.perf_counter()
            try:
                if SIGN_ON:  # the sign-on proxy in front names the student
                    async with session.get(f"{url}/", headers={SIGN_ON: self.name}) as page:
                        if page.status != 200:
                            raise OSError(f"sign-on refused ({page.status})")
                else:
                    await self.log_in(session, url)
                LOGINS.append(time.perf_counter() - began)
                socket = await session.ws_connect(f"{url}/ws?cols=80&rows=24", origin=url)
            except (OSError, aiohttp.ClientError, AssertionError) as exc:
                self.result.failures.append(f"{self.name}: cannot connect: {exc}")
                yield None
                return

            async def read() -> None:
                async for message in socket:
                    if message.type == aiohttp.WSMsgType.BINARY:
                        self._feed(message.data)

            reader = asyncio.create_task(read())
            loop = asyncio.get_running_loop()
            yield lambda data: loop.create_task(socket.send_bytes(data))
            reader.cancel()
            await socket.close()


def start_web_server(data: Path, port: int, sessions: int, spares: int = 0) -> subprocess.Popen:
    first = 45000 + (port % 50) * 100
    server = subprocess.Popen(
        [sys.executable, "-m", "workbench", "serve-web", "--bind", "127.0.0.1",
         "--port", str(port), "--data-dir", str(data),
         "--port-range", f"{first}-{first + 2 * sessions + 40}",
         "--max-sessions", str(max(60, sessions)),
         *(["--spare-apps", str(spares)] if spares else []),
         *(["--user-header", SIGN_ON, "--trusted-proxy", "127.0.0.0/8"] if SIGN_ON else [])],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )  # fmt: skip
    log = data / "web.log"
    deadline = time.monotonic() + 60
    while "serving the browser door" not in (log.read_text() if log.exists() else ""):
        if server.poll() is not None or time.monotonic() > deadline:
            raise SystemExit("the browser door did not start")
        time.sleep(0.05)
    wait_for_spares(server.pid, spares)
    return server


async def one_door(
    door: str, n: int, seconds: float, hz: float, spares: int = 0
) -> tuple[Result, list[float]]:
    with tempfile.TemporaryDirectory(prefix=f"{door}-load-") as tmp:
        data = Path(tmp)
        keys = {}
        hashed = hash_password(PASSWORD)
        for i in range(n):
            name = f"s{i:02d}"
            keys[name] = asyncssh.generate_private_key("ssh-ed25519")
            add_user(data / "ssh-users.yaml", name, "student",
                     [keys[name].export_public_key().decode()], hashed)  # fmt: skip
        port = free_port()
        if door == "web":
            server = start_web_server(data, port, n, spares)
        else:
            server = start_server(data, port, n, True, spares)
        kind = WebStudent if door == "web" else Student
        result = Result()
        students = [
            kind(name, key, port, result, student_address(i), "asyncssh", data / "unused")
            for i, (name, key) in enumerate(keys.items())
        ]
        t0 = time.perf_counter()
        start = t0 + max(10.0, 0.6 * n)
        spans: list[float] = []

        async def timed(student: Student, i: int) -> None:
            began = time.perf_counter()
            await student.run(start, seconds, hz, offset=(i % 20) * PROBE_EVERY / 20, arrive=t0)
            spans.append(len(student.buffer) / (time.perf_counter() - began))

        try:
            await asyncio.gather(*(timed(s, i) for i, s in enumerate(students)))
        finally:
            server.terminate()
            server.wait(30)
    return result, spans


#: the header a sign-on proxy names the student in (--sign-on; "": logins by password)
SIGN_ON = ""
#: the browser round's bytes per second per session, for the SSH round's comparison
WEB_RATES: list[float] = []


def report(door: str, n: int, result: Result, rates: list[float], spares: int) -> None:
    print(f"{door}: N={n} at once" + (f", {spares} spare apps started ahead" if spares else ""))
    print(
        f"  first screen     p50 {pct(result.first_screen, 0.5):.2f} s   "
        f"p95 {pct(result.first_screen, 0.95):.2f} s"
    )
    print(
        f"  key to screen    p50 {1000 * pct(result.latency, 0.5):.0f} ms   "
        f"p95 {1000 * pct(result.latency, 0.95):.0f} ms   ({len(result.latency)} presses)"
    )
    if door == "web" and LOGINS:
        how = ("named by the sign-on header" if SIGN_ON else
               "a password checked with scrypt; the SSH round logs in with keys")  # fmt: skip
        print(
            f"  of which login   p50 {pct(LOGINS, 0.5):.2f} s   p95 {pct(LOGINS, 0.95):.2f} s"
            f"   ({how})"
        )
    if rates:
        print(f"  bytes/s/session  mean {statistics.mean(rates):.0f}   max {max(rates):.0f}")
    if result.failures:
        print(f"  FAILED           {len(result.failures)}: {result.failures[:3]}")
    if door == "web":
        met(pct(result.first_screen, 0.95) <= 1.0, "first screen p95 <= 1 s")
        met(pct(result.latency, 0.95) <= 0.050, "key to screen p95 <= 50 ms")
    elif rates and WEB_RATES:
        met(statistics.mean(WEB_RATES) <= statistics.mean(rates), "web bytes/s <= SSH's")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sessions", type=int, default=30)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--hz", type=float, default=20.0)
    parser.add_argument("--web-only", action="store_true", help="leave out the SSH round")
    parser.add_argument(
        "--spare-apps", type=int, default=0, metavar="N",
        help="each server keeps N apps started ahead (--spare-apps), at rest before the "
        "students come (default 0)",
    )  # fmt: skip
    parser.add_argument(
        "--sign-on", action="store_true",
        help="the browser door behind a sign-on proxy (--user-header X-Forwarded-User, trusted "
        "from loopback): the students come named by the proxy, no password checked",
    )  # fmt: skip
    args = parser.parse_args()
    if args.sign_on:
        global SIGN_ON
        SIGN_ON = "X-Forwarded-User"
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    for door in ("web",) if args.web_only else ("web", "ssh"):
        result, rates = asyncio.run(
            one_door(door, args.sessions, args.seconds, args.hz, args.spare_apps)
        )
        if door == "web":
            WEB_RATES.extend(rates)
        report(door, args.sessions, result, rates, args.spare_apps)


if __name__ == "__main__":
    main()
