"""The server's own bounds, part by part: the typed-key budget, the server log's size, and an
out-of-memory error in a callback said in one line."""

from __future__ import annotations

import asyncio
import logging

from tests.clocks import Clock
from workbench.door.serverlog import setup_logging
from workbench.ssh.openfiles import quiet_accept_errors
from workbench.tui.serving.key_budget import KeyBudget, dropped_message


def test_typed_keys_past_the_burst_are_dropped_and_the_rate_lets_more_through_later():
    clock = Clock()
    budget = KeyBudget(burst=256, rate=50, clock=clock)
    assert budget.take(65536) == 256
    assert budget.take(1) == 0
    assert budget.told() == 65536 - 256 + 1
    assert budget.told() == 0  # told once
    clock.now = 1.0  # a second later: fifty more
    assert budget.take(100) == 50
    clock.now = 100.0  # a long pause fills the budget up to the burst, never past it
    assert budget.take(1000) == 256
    assert "744 typed keys were dropped" in dropped_message(744)
    assert "1 typed key was dropped" in dropped_message(1)


def test_the_server_log_is_kept_within_its_size_and_one_older_log(tmp_path):
    logger = logging.getLogger("workbench.ssh")
    before = list(logger.handlers)
    try:
        path = setup_logging(tmp_path, stream=False, size=20_000)
        for n in range(2000):
            logger.warning("refused %d: %s", n, "x" * 60)
    finally:
        for handler in logger.handlers[len(before) :]:
            handler.close()
            logger.removeHandler(handler)
    assert path.stat().st_size <= 20_000
    older = path.with_name("ssh.log.1")
    assert older.stat().st_size <= 20_000
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("ssh.log")) == [
        "ssh.log",
        "ssh.log.1",
    ]
    assert "refused 1999" in path.read_text()


def test_out_of_memory_in_a_callback_is_one_line_not_a_traceback():
    said: list[tuple[str, str]] = []

    def run_out() -> None:
        raise MemoryError

    async def main() -> None:
        loop = asyncio.get_running_loop()
        previous = quiet_accept_errors(loop, lambda key, line: said.append((key, line)))
        try:
            for _ in range(3):
                loop.call_soon(run_out)
            await asyncio.sleep(0.01)
        finally:
            loop.set_exception_handler(previous)

    asyncio.run(main())
    assert [key for key, _ in said] == ["out of memory"] * 3  # say() keeps repeats quiet
    assert said[0][1].startswith("out of memory (Exception in callback")
