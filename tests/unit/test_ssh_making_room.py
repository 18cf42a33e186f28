"""Connections that sit on their place at the login make room for new ones once the places are
full (or a new one would be dropped at random): which one goes, after how long, and what its
source is charged (all on an injected clock)."""

from __future__ import annotations

from dataclasses import dataclass

from tests.clocks import Clock
from workbench.door.logins import Admission, ConnectionGate, LoginPolicy, Stage


@dataclass(eq=False)
class Conn:
    """A connection as the server hands it to the gate (known by identity)."""

    address: str


def small_gate(**numbers) -> tuple[ConnectionGate[Conn], Clock]:
    numbers = {
        "max_unauthenticated": 6,
        "max_unauthenticated_per_address": 3,
        "unauthenticated_start": 6,
        "unauthenticated_grace": 5.0,
        "seed": 1,
        **numbers,
    }
    clock = Clock()
    return ConnectionGate(LoginPolicy(**numbers), clock), clock


def arrive(gate: ConnectionGate[Conn], address: str) -> tuple[Conn, Admission[Conn]]:
    conn = Conn(address)
    return conn, gate.admit(conn, address)


def fill(gate: ConnectionGate[Conn], clock: Clock, addresses: list[str]) -> list[Conn]:
    """One connection from each of ``addresses`` in turn, a second apart; all let in."""
    conns = []
    for address in addresses:
        conn, admission = arrive(gate, address)
        assert admission == Admission()
        conns.append(conn)
        clock.now += 1
    return conns


def test_a_full_gate_refuses_while_every_place_is_within_its_grace():
    gate, clock = small_gate()
    fill(gate, clock, ["10.6.6.1"] * 3 + ["10.6.6.2"] * 3)  # the last came at 5 s
    clock.now = 5.0  # the first has held its place for exactly the grace
    _, admission = arrive(gate, "10.0.0.7")
    assert admission.refused == "6 connections have not logged in yet"
    assert admission.evicted is None
    assert gate.unauthenticated.total() == 6


def test_the_oldest_of_the_source_holding_the_most_places_makes_room():
    gate, clock = small_gate()
    a1, b1, *_ = fill(gate, clock, ["10.6.6.1", "10.6.6.2"] * 2 + ["10.6.6.2", "10.6.6.3"])
    clock.now = 30.0  # all past their grace
    student, admission = arrive(gate, "10.0.0.7")
    assert admission.refused is None
    evicted = admission.evicted
    assert evicted is not None
    # 10.6.6.2 holds three places: its oldest goes, not the older a1 of 10.6.6.1
    assert (evicted.key, evicted.source, evicted.held) == (b1, "10.6.6.2", 29.0)
    assert gate.unauthenticated == {"10.6.6.1": 2, "10.6.6.2": 2, "10.6.6.3": 1, "10.0.0.7": 1}
    # now 10.6.6.1 and 10.6.6.2 hold two each: the oldest of both goes
    assert arrive(gate, "10.0.0.8")[1].evicted.key is a1
    # the place freed is gone for good: its connection closing later changes nothing
    assert gate.settled(b1, logged_in=False) is False
    assert gate.unauthenticated.total() == 6
    assert gate.settled(student) is False  # the student logged in
    assert gate.unauthenticated.total() == 5


def test_a_place_within_its_grace_never_makes_room_whatever_its_source_holds():
    gate, clock = small_gate(max_unauthenticated_per_address=5)
    old, *newer = fill(gate, clock, ["10.6.6.9"] + ["10.6.6.1"] * 5)  # at 0 s, then 1-5 s
    clock.now = 7.0  # only the first (7 s) and second (6 s) are past the grace
    assert arrive(gate, "10.0.0.7")[1].evicted.key is newer[0]  # its source holds the most
    assert arrive(gate, "10.0.0.8")[1].evicted.key is old
    _, admission = arrive(gate, "10.0.0.9")
    assert admission.refused is not None  # the rest are within the grace: nobody goes
    assert gate.unauthenticated == {"10.6.6.1": 4, "10.0.0.7": 1, "10.0.0.8": 1}


def test_connections_that_began_to_log_in_make_room_after_those_that_only_hold_a_socket():
    gate, clock = small_gate()
    typing, checking, *idle = fill(
        gate, clock, ["10.0.0.7", "10.0.0.8", "10.6.6.1", "10.6.6.1", "10.6.6.2", "10.6.6.3"]
    )
    gate.progressed(typing, Stage.AUTHENTICATING)  # at a password prompt
    gate.progressed(checking, Stage.CHECKING)  # a password waiting out its delay
    clock.now = 60.0
    order = [arrive(gate, f"10.1.0.{n}")[1].evicted for n in range(6)]
    # first the sockets (10.6.6.1 holds two places, the others one), then those that began
    assert [e.key for e in order] == [*idle, typing, checking]
    _, admission = arrive(gate, "10.1.0.9")
    assert admission.refused is not None  # the newcomers are within their grace
    gate.progressed(typing, Stage.CHECKING)  # gone: nothing to mark
    assert gate.unauthenticated.total() == 6


def test_a_source_whose_places_keep_making_room_is_soon_refused():
    gate, clock = small_gate(penalty_least=20, penalty_longest=120)
    fill(gate, clock, ["10.6.6.1"] * 3 + ["10.6.6.2"] * 3)
    clock.now = 11.0  # the first places were held 11, 10, 9 s and then 8, 7, 6 s
    charged = [arrive(gate, f"10.0.0.{n}")[1].evicted for n in range(1, 4)]
    assert [(e.source, e.held) for e in charged] == [
        ("10.6.6.1", 11.0),
        ("10.6.6.2", 8.0),
        ("10.6.6.1", 10.0),
    ]
    assert [e.penalized for e in charged] == [False, False, True]  # 21 s owed: refused
    refused = arrive(gate, "10.6.6.1")[1].refused
    assert refused == (
        "refused for another 21 s: connections from 10.6.6.1 held places at the login without "
        "logging in"
    )
    clock.now = 20.0
    assert arrive(gate, "10.6.6.1")[1].refused is not None  # 12 s more
    assert arrive(gate, "10.6.6.2")[1].refused is None  # it owes less


def test_a_connection_that_would_be_dropped_at_random_takes_a_stale_place_instead():
    gate, clock = small_gate(max_unauthenticated=10, unauthenticated_start=3, start_drop=1.0)
    idle = fill(gate, clock, ["10.6.6.1"] * 3)
    _, admission = arrive(gate, "10.0.0.7")  # certain to be dropped, none past the grace
    assert admission.refused == "dropped at random: 3 connections have not logged in yet"
    clock.now = 10.0
    _, admission = arrive(gate, "10.0.0.7")
    assert admission.refused is None and admission.evicted.key is idle[0]
    assert gate.unauthenticated.total() == 3  # no more places taken than before


def test_with_a_grace_as_long_as_the_login_timeout_nobody_makes_room():
    gate, clock = small_gate(unauthenticated_grace=30.0, login_timeout=30.0)
    idle = fill(gate, clock, ["10.6.6.1"] * 3 + ["10.6.6.2"] * 3)
    clock.now = 30.0  # the first would time out now
    assert arrive(gate, "10.0.0.7")[1].refused is not None
    gate.settled(idle[0], logged_in=False)  # it did
    assert arrive(gate, "10.0.0.7")[1] == Admission()
