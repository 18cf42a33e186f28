"""Run ``python -m workbench ARGS`` many times without paying the interpreter's start each time.

``python -m tests.cli_forker JOBS RESULTS`` imports the command line once, then forks one
child per job of the JSON file JOBS (``[{"argv": [...], "out": path}, ...]``), at most
``--jobs`` at a time. Each child is what ``python -m workbench`` would be after its imports:
it runs the package's ``__main__`` with ``sys.argv`` set, its stdout and stderr going to the
job's ``out`` file, and ends with the exit code the interpreter would give (an uncaught
exception prints its traceback and gives 1). A child still running after ``--timeout``
seconds is killed by its own alarm. RESULTS gets, per job in order, the exit status, the
seconds from fork to exit, and the child's peak resident memory (``ru_maxrss``, KiB).
"""

from __future__ import annotations

import argparse
import json
import os
import runpy
import signal
import sys
import time
import traceback


def _child(argv: list[str], out: str, timeout: int) -> None:
    """In the forked child: run the command line as ``python -m workbench`` does; never
    returns."""
    code = 1
    try:
        signal.alarm(timeout)  # its default action ends the process
        fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(fd, 1)
        os.dup2(fd, 2)
        os.close(fd)
        sys.argv = ["workbench", *argv]
        try:
            runpy.run_module("workbench", run_name="__main__", alter_sys=True)
            code = 0
        except SystemExit as exc:  # as the interpreter turns SystemExit into an exit code
            if exc.code is None:
                code = 0
            elif isinstance(exc.code, int):
                code = exc.code
            else:
                print(exc.code, file=sys.stderr)
                code = 1
        except BaseException:
            traceback.print_exc()
            code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def run_jobs(jobs: list[dict], parallel: int, timeout: int) -> list[dict]:
    results: list[dict] = [{} for _ in jobs]
    started: dict[int, tuple[int, float]] = {}
    waiting = list(enumerate(jobs))
    while waiting or started:
        while waiting and len(started) < parallel:
            index, job = waiting.pop(0)
            sys.stdout.flush()
            sys.stderr.flush()
            pid = os.fork()
            if pid == 0:
                _child(job["argv"], job["out"], timeout)
            started[pid] = (index, time.perf_counter())
        pid, status, usage = os.wait4(-1, 0)
        index, start = started.pop(pid)
        results[index] = {
            "code": os.waitstatus_to_exitcode(status),
            "seconds": time.perf_counter() - start,
            "max_rss_kib": usage.ru_maxrss,
        }
    return results


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("jobs")
    parser.add_argument("results")
    parser.add_argument("--jobs", type=int, default=2, dest="parallel")
    parser.add_argument("--timeout", type=int, default=60)
    args = parser.parse_args()
    import workbench.cli  # noqa: F401  (what ``python -m workbench`` imports first)

    with open(args.jobs, encoding="utf-8") as f:
        jobs = json.load(f)
    results = run_jobs(jobs, max(1, args.parallel), args.timeout)
    with open(args.results, "w", encoding="utf-8") as f:
        json.dump(results, f)


if __name__ == "__main__":
    main()
