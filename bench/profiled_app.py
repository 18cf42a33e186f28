"""The workbench app with a profiler that the bench switches on and off from outside.

``python bench/profiled_app.py STATS_FILE [app options...]`` runs the app of the current folder
as ``python -m workbench`` would; SIGUSR1 starts cProfile on the app's main thread (where
Textual and the simulation run), SIGUSR2 stops it and writes the stats to STATS_FILE. So a
profile holds only the stretch the bench measures (driving, or sitting idle), not the start-up.
:func:`from_start` is the other way round, an entry point for a fork server (``bench/startup.py``):
the profile runs from the fork until SIGUSR2 and goes to ``$WORKBENCH_PROFILE_TO``.
Times are the main thread's CPU time, not wall time: other processes on a busy machine do not
show up in them.
"""

from __future__ import annotations

import cProfile
import os
import signal
import sys
import time


def run(stats_file: str, options: list[str]) -> int:
    # the workbench of the folder it is started in (bench/tui_cpu.py --compare starts it in an
    # older revision's), as ``python -m workbench`` would import it
    sys.path.insert(0, os.getcwd())
    from workbench.cli import main

    profiler = cProfile.Profile(time.thread_time)

    def start(*_: object) -> None:
        nonlocal profiler
        profiler = cProfile.Profile(time.thread_time)
        profiler.enable()

    def stop(*_: object) -> None:
        profiler.disable()
        profiler.dump_stats(stats_file)

    signal.signal(signal.SIGUSR1, start)
    signal.signal(signal.SIGUSR2, stop)
    return main(options)


def from_start(settings: object) -> int:
    """The app as a fork server runs it (with its settings, a JSON object), profiled from here
    (just after the fork) to SIGUSR2."""
    from workbench.cli.served import main

    profiler = cProfile.Profile(time.thread_time)

    def stop(*_: object) -> None:
        profiler.disable()
        profiler.dump_stats(os.environ["WORKBENCH_PROFILE_TO"])

    signal.signal(signal.SIGUSR2, stop)
    profiler.enable()
    return main(settings)


if __name__ == "__main__":
    raise SystemExit(run(sys.argv[1], sys.argv[2:]))
