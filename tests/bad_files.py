"""A corpus of hostile input files, one set per kind the workbench reads (maze, FSM, lab,
users), with the message fragment each must be refused with; and good files, with a BOM."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

GRID = "#####\n#S.E#\n#####\n"
GOOD_MAZE = "---\nname: ok\ncell: 1.0\n---\n" + GRID
GOOD_FSM = (
    "name: mine\nsensors:\n  front: {kind: distance, mount: front, port: 2}\n"
    "parameters:\n  near: 1.5\n"
    "initial: Go\nstates:\n  Go:\n    on_enter:\n      - move: 1\n"
    "    transitions:\n      - when: front < near\n        to: Stop\n"
    "  Stop:\n    on_enter:\n      - stop: true\n"
)
GOOD_LAB = (
    "lab: {name}\ntitle: A small lab\nexercises:\n  - id: drive\n    title: Drive\n"
    "    instructions: Drive with the keys.\n    setup:\n      profile: unity\n"
    "      maze: m.txt\n      controller: keys\n    objectives:\n"
    "      - kind: keys\n        text: drove\n"
)
GOOD_USERS = "users:\n  ann:\n    role: student\n    password: {hash}\n"
#: a text that no message may quote back
SECRET = "hunter2-secret"

DEEP_FLOW = "[" * 1_000
DEEP_MAP = "".join(" " * i + "a:\n" for i in range(1, 200))
BOMB = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, 10)
)
DEEP = "nested more than 32 deep"
BOMB_SAYS = "values (an alias counts as a copy"
NOT_FINITE = "not finite (NaN or infinity)"
LONG_LINE = "characters long"


@dataclass(frozen=True)
class BadFile:
    kind: str
    name: str
    data: bytes
    #: a fragment of the message it is refused with
    says: str

    @property
    def filename(self) -> str:
        return f"{self.kind}-{self.name}.{'txt' if self.kind == 'maze' else 'yaml'}"


def _fsm_with(when: str) -> str:
    return GOOD_FSM.replace("front < near", when)


def _mazes() -> list[BadFile]:
    def m(name: str, text: str | bytes, says: str) -> BadFile:
        return BadFile("maze", name, text.encode() if isinstance(text, str) else text, says)

    return [
        m("deep-flow", f"---\nname: {DEEP_FLOW}\n---\n{GRID}", DEEP),
        m("deep-mapping", f"---\nname:\n{DEEP_MAP}---\n{GRID}", DEEP),
        m("alias-bomb", f"---\n{BOMB}---\n{GRID}", BOMB_SAYS),
        m("nul", f"---\nname: {SECRET}\n---\n#####\n#S\0E#\n#####\n", "U+0000"),
        m(
            "non-utf8",
            f"---\nname: {SECRET}\n---\n".encode() + b"#\xff###\n" + GRID.encode(),
            "0xFF",
        ),
        m("nan", f"---\ncell: .nan\n---\n{GRID}", NOT_FINITE),
        m("inf", f"---\ncell: -.inf\n---\n{GRID}", NOT_FINITE),
        m("long-number", f"---\ncell: {'1' * 500}\n---\n{GRID}", "500 digits"),
        m("1000x1000", ("#" * 1000 + "\n") * 1000, "the grid has 1,000 rows"),
        m("3000x3000", ("#" * 3000 + "\n") * 3000, "a maze file is at most 1,048,576"),
        m("1mb-line", SECRET + "Z" * 1_000_000 + "\n", LONG_LINE),
        m("40000-problems", ("Z" * 200 + "\n") * 200, "and 39,980 more problems"),
        m(
            "micromouse-wide",
            "o" + "---o" * 150 + "\n|" + "   |" * 150 + "\no" + "---o" * 150,
            "150",
        ),
        m("num-huge", "0 0 1 1 1 1\n" + f"{'9' * 40} 0 1 1 1 1\n", "40 digits"),
        m("control", f"---\nname: {SECRET}\x1b[2J\n---\n{GRID}", "U+001B"),
        m("binary", bytes(range(256)) * 3, "neither UTF-8 text nor a .maz maze"),
    ]


def _fsms() -> list[BadFile]:
    def f(name: str, text: str | bytes, says: str) -> BadFile:
        return BadFile("fsm", name, text.encode() if isinstance(text, str) else text, says)

    return [
        f("deep-flow", f"name: {DEEP_FLOW}\n", DEEP),
        f("deep-mapping", f"name:\n{DEEP_MAP}", DEEP),
        f("alias-bomb", BOMB, BOMB_SAYS),
        f("nul", GOOD_FSM.replace("mine", SECRET + "\0"), "U+0000"),
        f("non-utf8", GOOD_FSM.encode().replace(b"mine", SECRET.encode() + b"\xc3("), "0xC3"),
        f("nan-parameter", GOOD_FSM.replace("near: 1.5", "near: .nan"), NOT_FINITE),
        f("long-parameter", GOOD_FSM.replace("near: 1.5", f"near: {'7' * 1000}"), "1,000 digits"),
        f("expr-500-terms", _fsm_with("+".join(["1"] * 500) + " < front"), "at most 200"),
        f("expr-500-nots", _fsm_with("not " * 480 + "front"), "nest more than 50 deep"),
        f("expr-unary-minus", _fsm_with("-" * 1_990 + "front < 1"), "nest more than 50 deep"),
        f("expr-100k-minus", _fsm_with("-" * 100_000 + "front < 1"), LONG_LINE),
        f("expr-long", _fsm_with(" + ".join(["1"] * 1_000) + " < front"), "at most 2,000"),
        f("expr-long-number", _fsm_with(f"front < {'5' * 1_000}"), "1,000 digits"),
        f("expr-inf", _fsm_with("front < 1e999"), "not finite"),
        f("1mb-line", SECRET + "x" * 1_000_000, LONG_LINE),
    ]


def _labs() -> list[BadFile]:
    def lab(name: str, text: str | bytes, says: str) -> BadFile:
        return BadFile("lab", name, text.encode() if isinstance(text, str) else text, says)

    good = GOOD_LAB.format(name="lab-x")
    return [
        lab("deep-flow", f"lab: {DEEP_FLOW}\n", DEEP),
        lab("deep-mapping", f"lab:\n{DEEP_MAP}", DEEP),
        lab("alias-bomb", BOMB, BOMB_SAYS),
        lab("nul", good.replace("A small lab", SECRET + "\0"), "U+0000"),
        lab("non-utf8", good.encode().replace(b"A small", b"\xa0" + SECRET.encode()), "0xA0"),
        lab("nan", good + "        max_time: .nan\n", NOT_FINITE),
        lab("1mb-line", SECRET + "y" * 1_000_000, LONG_LINE),
    ]


def _users() -> list[BadFile]:
    def u(name: str, text: str | bytes, says: str) -> BadFile:
        return BadFile("users", name, text.encode() if isinstance(text, str) else text, says)

    return [
        u("deep-flow", f"users: {DEEP_FLOW}\n", DEEP),
        u("deep-mapping", f"users:\n{DEEP_MAP}", DEEP),
        u("alias-bomb", BOMB, BOMB_SAYS),
        u("nul", f"users:\n  {SECRET}\0:\n    role: student\n", "U+0000"),
        u("non-utf8", f"users:\n  {SECRET}:\n".encode() + b"    role: \xe9\n", "0xE9"),
        u("1mb-line", SECRET + "u" * 1_000_000, LONG_LINE),
    ]


def corpus() -> list[BadFile]:
    return [*_mazes(), *_fsms(), *_labs(), *_users()]


def write_corpus(folder: Path) -> list[tuple[BadFile, Path]]:
    """Every bad file written into ``folder`` (a lab's maze beside it), with its path."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "m.txt").write_text(GOOD_MAZE)
    out = []
    for bad in corpus():
        path = folder / bad.filename
        path.write_bytes(bad.data)
        out.append((bad, path))
    return out


# -- running the command line on the corpus -----------------------------------------------------

ROOT = Path(__file__).resolve().parents[1]
#: the commands that read each kind of file ({} is the file)
COMMANDS: dict[str, list[list[str]]] = {
    "maze": [["maze", "check", "{}"], ["run", "--maze", "{}", "--algorithm", "right-wall"]],
    "fsm": [
        ["algorithms", "{}"],
        ["run", "--maze", "mazes/unity-default.txt", "--algorithm", "{}"],
    ],
    "lab": [["labs", "check", "{}"]],
    "users": [["ssh", "list-users", "--users", "{}"]],
}


@dataclass(frozen=True)
class Outcome:
    bad: BadFile
    args: list[str]
    code: int
    output: str
    seconds: float
    #: the peak resident memory of the command's process, in KiB (Linux ru_maxrss)
    max_rss_kib: int


def run_command(bad: BadFile, path: Path, args: list[str], timeout: float = 60.0) -> Outcome:
    """``workbench ARGS`` in a child process, timed, with the child's own peak memory."""
    import os
    import subprocess
    import sys
    import tempfile
    import threading
    import time

    argv = [a.replace("{}", str(path)) for a in args]
    with tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, "-m", "workbench", *argv], cwd=ROOT, stdout=out, stderr=out
        )
        timer = threading.Timer(timeout, proc.kill)
        timer.start()
        try:
            _pid, status, usage = os.wait4(proc.pid, 0)
        finally:
            timer.cancel()
        seconds = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        output = out.read().decode("utf-8", "replace")
    return Outcome(bad, argv, proc.returncode, output, seconds, usage.ru_maxrss)


def run_corpus(folder: Path, jobs: int = 8, *, forked: bool = False) -> list[Outcome]:
    """Every command of :data:`COMMANDS` on every bad file written into ``folder``, ``jobs``
    at a time: each in a process started afresh, or with ``forked`` each in a process forked
    from one that has imported the command line already (tests/cli_forker.py: the same code
    on the same file, its own process and output, without the interpreter's start)."""
    work = [(bad, path, args) for bad, path in write_corpus(folder) for args in COMMANDS[bad.kind]]
    if forked:
        return _run_forked(folder, work, jobs)
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(lambda job: run_command(*job), work))


def _run_forked(
    folder: Path, work: list[tuple[BadFile, Path, list[str]]], jobs: int, timeout: int = 60
) -> list[Outcome]:
    import json
    import subprocess
    import sys

    outputs = folder / "outputs"
    outputs.mkdir(exist_ok=True)
    argvs = [[a.replace("{}", str(path)) for a in args] for _bad, path, args in work]
    specs = [{"argv": argv, "out": str(outputs / f"{n}.out")} for n, argv in enumerate(argvs)]
    jobs_file, results_file = folder / "jobs.json", folder / "results.json"
    jobs_file.write_text(json.dumps(specs))
    done = subprocess.run(
        [sys.executable, "-m", "tests.cli_forker", str(jobs_file), str(results_file),
         "--jobs", str(jobs), "--timeout", str(timeout)],
        cwd=ROOT, capture_output=True, text=True, timeout=timeout * len(work),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    results = json.loads(results_file.read_text())
    return [
        Outcome(
            bad,
            argv,
            result["code"],
            Path(spec["out"]).read_bytes().decode("utf-8", "replace"),
            result["seconds"],
            result["max_rss_kib"],
        )
        for (bad, _path, _args), argv, spec, result in zip(work, argvs, specs, results, strict=True)
    ]
