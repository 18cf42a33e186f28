"""The VIPLE endpoints' status line: worded from each link's figures, and again when they change."""

from __future__ import annotations

from workbench.sim.mazefile import parse_maze
from workbench.sim.session import Session
from workbench.viple.hosting import Endpoints
from workbench.viple.link import Link

ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")
MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'


class Endpoint:
    """An endpoint as the status line sees it: its link's status."""

    def __init__(self, link: Link) -> None:
        self.link = link

    @property
    def status(self):
        return self.link.status


def test_the_status_line_follows_every_change_of_a_link_and_keeps_its_words_between():
    session = Session(ROOM, "unity", noise="off")
    link = Link(session, "tcp", "127.0.0.1:1350")
    hosted = Endpoints(tcp=Endpoint(link))  # type: ignore[arg-type]
    assert hosted.summary() == "VIPLE tcp listening on 127.0.0.1:1350"
    assert link.status is link.status  # nothing changed: the same status, not a new one
    assert link.connect("127.0.0.1:50312")
    assert hosted.summary() == "VIPLE tcp 127.0.0.1:50312: in 0 out 0"
    assert link.apply(MOVE)
    assert hosted.summary() == "VIPLE tcp 127.0.0.1:50312: in 1 out 0"
    first = hosted.summary()
    assert hosted.summary() is first  # asked again with nothing new: the same words
    assert not link.apply("not json")
    assert hosted.summary().startswith("VIPLE tcp 127.0.0.1:50312: in 2 out 0, 1 rejected")
    hosted.problems.append("VIPLE ws not connecting: refused")
    assert hosted.summary().endswith(" | VIPLE ws not connecting: refused")
    link.disconnect()
    assert hosted.summary().startswith("VIPLE tcp listening on 127.0.0.1:1350")
