"""``serve-ssh`` and ``serve-web`` take the options that mean the same under the same names:
the caps on sessions and on connections not logged in yet (the early drop, the penalties)."""

from __future__ import annotations

import argparse

from workbench.cli import build_parser
from workbench.cli.doors import login_policy
from workbench.door.logins import LoginPolicy

SHARED = [
    "--max-sessions", "--max-per-user", "--idle-timeout", "--login-timeout",
    "--max-unauthenticated", "--max-unauthenticated-per-address", "--unauthenticated-start",
    "--unauthenticated-grace", "--penalty-min", "--penalty-max", "--password-lock-after",
    "--password-lock-for", "--max-terminal", "--app-memory", "--no-fork-server",
]  # fmt: skip


def options_of(command: str) -> dict[str, argparse.Action]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {o: a for a in sub.choices[command]._actions for o in a.option_strings}


def test_both_doors_take_the_shared_options_with_the_same_defaults():
    ssh, web = options_of("serve-ssh"), options_of("serve-web")
    for option in SHARED:
        assert option in ssh and option in web, option
        assert ssh[option].default == web[option].default, option


def test_serve_web_gives_the_login_rules_it_is_told():
    parser = build_parser()
    args = parser.parse_args([
        "serve-web", "--login-timeout", "12", "--max-unauthenticated", "40",
        "--max-unauthenticated-per-address", "3", "--unauthenticated-start", "20",
        "--unauthenticated-grace", "2", "--penalty-min", "30", "--penalty-max", "0",
    ])  # fmt: skip
    policy = login_policy(args)
    assert isinstance(policy, LoginPolicy)
    assert (policy.login_timeout, policy.max_unauthenticated) == (12, 40)
    assert (policy.max_unauthenticated_per_address, policy.unauthenticated_start) == (3, 20)
    assert (policy.unauthenticated_grace, policy.penalty_least, policy.penalty_longest) == (
        2, 30, 0,
    )  # fmt: skip
    bad = parser.parse_args(["serve-web", "--max-unauthenticated-per-address", "0"])
    assert "--max-unauthenticated-per-address" in str(login_policy(bad))
