"""The login guard: delays per account and per address, account locks, and the caps on
connections that have not logged in (all on an injected clock)."""

from __future__ import annotations

from tests.clocks import Clock
from workbench.door.logins import ConnectionGate, LoginGuard, LoginPolicy, QuietLog

STUDENT_PC = "10.0.0.7"


def arrive(gate: ConnectionGate, address: str) -> tuple[object, str | None]:
    """A new connection from ``address``: its key, and why it was refused (None: let in)."""
    key = object()
    return key, gate.admit(key, address).refused


def guard(**numbers) -> tuple[LoginGuard, Clock]:
    clock = Clock()
    return LoginGuard(LoginPolicy(**numbers), clock), clock


def test_wrong_passwords_for_an_account_are_answered_ever_more_slowly_from_any_address():
    g, _ = guard(lock_after=100)
    assert g.delay("rivera", STUDENT_PC) == 0
    waits = []
    for n in range(7):
        g.password_failed("rivera", f"10.0.1.{n}")  # a new address each time
        waits.append(g.delay("rivera", "10.0.9.9"))
    assert waits == [0.5, 1, 2, 4, 8, 8, 8]
    assert g.delay("someone-else", "10.0.9.9") == 0


def test_a_success_on_another_account_does_not_forget_the_guesses():
    g, _ = guard()
    for _ in range(4):
        g.password_failed("rivera", STUDENT_PC)
        g.password_succeeded("mallory")  # the guesser's own login, between guesses
    assert g.account_failures("rivera") == 4
    assert g.delay("rivera", STUDENT_PC) == 4.0
    assert g.address_failures(STUDENT_PC) == 4
    g.password_succeeded("rivera")  # the owner's own password clears only that account
    assert g.delay("rivera", "10.0.0.8") == 0
    assert g.delay("rivera", STUDENT_PC) == 0.5  # the address is still one past its allowance


def test_guesses_spread_over_accounts_slow_the_address_past_its_allowance():
    g, _ = guard()
    for n in range(6):
        g.password_failed(f"user{n}", STUDENT_PC)
    assert g.delay("user99", STUDENT_PC) == 2.0  # 3 past the allowance of 3: 0.5 doubled twice
    assert g.delay("user99", "10.0.0.8") == 0


def test_an_account_takes_no_passwords_for_a_while_after_too_many_failures():
    g, clock = guard(lock_after=10, lock_for=900)
    locks = [g.password_failed("rivera", STUDENT_PC) for _ in range(10)]
    assert locks == [False] * 9 + [True]
    assert g.locked_for("rivera") == 900
    clock.now = 600
    assert g.password_failed("rivera", STUDENT_PC) is False  # a try while locked: no new lock
    assert g.locked_for("rivera") == 300  # and the lock is not made longer
    clock.now = 900
    assert g.locked_for("rivera") == 0
    assert g.delay("rivera", "10.0.0.8") == 0  # a lock served forgets the account's count


def test_failures_are_forgotten_after_a_quiet_period():
    g, clock = guard(quiet=600)
    g.password_failed("rivera", STUDENT_PC)
    g.key_failed(STUDENT_PC)
    clock.now = 599
    assert g.account_failures("rivera") == 1 and g.address_failures(STUDENT_PC) == 2
    clock.now = 600
    assert g.account_failures("rivera") == 0 and g.address_failures(STUDENT_PC) == 0


def test_connections_not_logged_in_are_capped_per_address_and_in_all():
    gate = ConnectionGate(LoginPolicy(max_unauthenticated=5, max_unauthenticated_per_address=3))
    keys = []
    for _ in range(3):
        key, refused = arrive(gate, STUDENT_PC)
        assert refused is None
        keys.append(key)
    assert "3 connections from this address" in arrive(gate, STUDENT_PC)[1]
    for host in ("10.0.0.8", "10.0.0.9"):
        assert arrive(gate, host)[1] is None
    assert "5 connections have not logged in" in arrive(gate, "10.0.0.10")[1]
    assert gate.settled(keys[0]) is False  # one of them logged in
    assert arrive(gate, "10.0.0.10")[1] is None
    assert "5 connections have not logged in" in arrive(gate, STUDENT_PC)[1]
    gate.settled(keys[1])
    assert arrive(gate, STUDENT_PC)[1] is None


def test_password_attempts_waiting_at_once_are_capped():
    gate = ConnectionGate(LoginPolicy(max_waiting=3, max_waiting_per_address=2))
    assert gate.start_waiting(STUDENT_PC) and gate.start_waiting(STUDENT_PC)
    assert not gate.start_waiting(STUDENT_PC)
    assert gate.start_waiting("10.0.0.8")
    assert not gate.start_waiting("10.0.0.9")  # three in all
    gate.stop_waiting(STUDENT_PC)
    assert gate.start_waiting("10.0.0.9")


def test_a_repeated_warning_is_said_once_per_period_with_the_count_held_back():
    clock = Clock()
    quiet = QuietLog(every=10, clock=clock)
    assert quiet.due("flood") == 0
    assert [quiet.due("flood") for _ in range(5)] == [None] * 5
    assert quiet.due("other") == 0
    clock.now = 10
    assert quiet.due("flood") == 5


def test_sources_are_ipv4_addresses_and_ipv6_networks_of_64():
    from workbench.door.sources import source_of

    assert source_of("10.0.0.7") == "10.0.0.7"
    assert source_of("::ffff:10.0.0.7") == "10.0.0.7"
    assert (
        source_of("2001:db8:1:2::5")
        == source_of("2001:db8:1:2:ffff:1:2:3")
        == ("2001:db8:1:2::/64")
    )
    assert source_of("2001:db8:1:3::5") != source_of("2001:db8:1:2::5")
    assert source_of("fe80::1%eth0") == "fe80::/64"
    assert source_of("?") == "?"


def test_one_ipv6_network_is_capped_as_one_address():
    gate = ConnectionGate(LoginPolicy(max_unauthenticated=50, max_unauthenticated_per_address=3))
    for n in range(3):
        assert arrive(gate, f"2001:db8:0:1::{n + 1}")[1] is None
    why = arrive(gate, "2001:db8:0:1:abcd::99")[1]  # a fresh address of the same /64
    assert why == "3 connections from 2001:db8:0:1::/64 have not logged in yet"
    assert arrive(gate, "2001:db8:0:2::1")[1] is None


def test_past_the_start_new_connections_are_dropped_ever_more_often_the_same_way_per_seed():
    def fill(seed: int) -> list[bool]:
        policy = LoginPolicy(
            max_unauthenticated=40, max_unauthenticated_per_address=40, unauthenticated_start=10,
            start_drop=0.3, seed=seed,
        )  # fmt: skip
        gate = ConnectionGate(policy)
        let_in = []
        for n in range(200):
            let_in.append(arrive(gate, f"10.1.{n // 250}.{n % 250}")[1] is None)
        return let_in

    first = fill(seed=3)
    assert first[:10] == [True] * 10  # below the start, everyone
    assert first == fill(seed=3)  # the same seed, the same drops
    assert first != fill(seed=4)
    assert first[10:].count(False) > 0 and sum(first) == 40  # still fills up, in the end
    drops_early = first[10:40].count(False)
    assert 0 < drops_early < 30


def test_a_source_holding_places_without_logging_in_is_refused_for_a_while():
    clock = Clock()
    policy = LoginPolicy(penalty_least=90, penalty_longest=600)
    gate = ConnectionGate(policy, clock)
    # a lab behind one address: one student gave up at the password prompt after 30 s
    key, _ = arrive(gate, STUDENT_PC)
    clock.now = 30
    assert gate.settled(key, logged_in=False) is False
    key, refused = arrive(gate, STUDENT_PC)
    assert refused is None
    clock.now = 70
    assert gate.settled(key, logged_in=True) is False  # logged in: no charge
    # ten idle connections that time out after 30 s each
    idle = [arrive(gate, "10.6.6.6")[0] for _ in range(10)]
    clock.now = 100
    starts = [gate.settled(key, logged_in=False) for key in idle]
    assert starts == [False, False, True] + [False] * 7
    assert "refused for another 300 s" in arrive(gate, "10.6.6.6")[1]
    assert arrive(gate, STUDENT_PC)[1] is None
    clock.now = 399
    assert arrive(gate, "10.6.6.6")[1] is not None
    clock.now = 400
    assert arrive(gate, "10.6.6.6")[1] is None  # served: let in again


def test_penalties_last_at_most_their_longest_and_can_be_turned_off():
    clock = Clock()
    gate = ConnectionGate(LoginPolicy(penalty_least=10, penalty_longest=60), clock)
    off = ConnectionGate(LoginPolicy(penalty_longest=0), clock)
    idle = [arrive(gate, "10.6.6.6")[0] for _ in range(10)]
    idle_off = [arrive(off, "10.6.6.6")[0] for _ in range(10)]
    clock.now = 30
    for key in idle:
        gate.settled(key, logged_in=False)
    assert "another 60 s" in arrive(gate, "10.6.6.6")[1]
    assert [off.settled(key, logged_in=False) for key in idle_off] == [False] * 10
    assert arrive(off, "10.6.6.6")[1] is None
