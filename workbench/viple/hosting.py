"""The VIPLE endpoints an interactive front end hosts on its live session (the app: on its lab
station, which takes the robot for a connected program and keeps its clock at 1x).

Unlike ``workbench serve``, a front end keeps running when an endpoint cannot start (a port
in use, say): the reason is shown in the status line instead.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from workbench.sim.session import Session

from .link import Cockpit, LinkStatus, Seat
from .tcp_server import EndpointError, TcpConfig, TcpServer
from .ws_client import WsClient, WsConfig


@dataclass
class Endpoints:
    tcp: TcpServer | None = None
    ws: WsClient | None = None
    seat: Seat = field(default_factory=Seat)
    #: endpoints that could not start, with the reason
    problems: list[str] = field(default_factory=list)
    #: the last summary, with the statuses and problems it says (worded again when they change)
    _summary: tuple[list[LinkStatus], list[str], str] | None = field(
        default=None, init=False, repr=False, compare=False
    )

    @classmethod
    async def open(
        cls, robot: Session | Cockpit, tcp: TcpConfig | None = None, ws: WsConfig | None = None
    ) -> Endpoints:
        hosted = cls()
        if tcp is not None:
            await hosted.start_tcp(robot, tcp)
        if ws is not None:
            await hosted.start_ws(robot, ws)
        return hosted

    async def start_tcp(self, robot: Session | Cockpit, config: TcpConfig) -> bool:
        """Listen for VIPLE (Unity-simulator role) unless already listening; False if it cannot."""
        if self.tcp is not None:
            return True
        server = TcpServer(robot, config, self.seat)
        try:
            await server.start()
        except EndpointError as exc:
            problem = f"VIPLE tcp not listening: {exc}"
            if problem not in self.problems:
                self.problems.append(problem)
            return False
        self.problems = [p for p in self.problems if not p.startswith("VIPLE tcp")]
        self.tcp = server
        return True

    async def start_ws(self, robot: Session | Cockpit, config: WsConfig) -> None:
        """Keep connecting to VIPLE's WebSocket server (Web-Simulator role), unless already."""
        if self.ws is None:
            self.ws = WsClient(robot, config, self.seat)
            await self.ws.start()

    @property
    def active(self) -> list[TcpServer | WsClient]:
        return [e for e in (self.tcp, self.ws) if e is not None]

    def statuses(self) -> list[LinkStatus]:
        return [e.status for e in self.active]

    def summary(self) -> str:
        """One line for a status bar: each endpoint, its peer and its counters."""
        statuses = self.statuses()
        kept = self._summary
        if kept is not None and kept[0] == statuses and kept[1] == self.problems:
            return kept[2]
        text = " | ".join([describe(s) for s in statuses] + self.problems)
        self._summary = (statuses, list(self.problems), text)
        return text

    async def close(self) -> None:
        for endpoint in self.active:
            await endpoint.close()
        self.tcp = self.ws = None


def describe(status: LinkStatus) -> str:
    if status.peer is None:
        where = "listening on" if status.role == "tcp" else "waiting for"
        line = f"VIPLE {status.role} {where} {status.address}"
    else:
        line = (
            f"VIPLE {status.role} {status.peer}: in {status.messages_in} out {status.messages_out}"
        )
    if status.idled:
        line += f", {status.idled} idle driver{'s' if status.idled > 1 else ''} cut off"
    if status.invalid:
        line += f", {status.invalid} rejected"
        if status.last_rejection:
            line += f" (last: {status.last_rejection})"
    return line
