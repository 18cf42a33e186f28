"""Writing small VIPLE program files for the tests, in the layout VIPLE 4.x saves."""

from __future__ import annotations

import gzip
import itertools
from dataclasses import dataclass, field
from xml.sax.saxutils import escape

#: kinds whose Values VIPLE writes with an Index attribute
_INDEXED = {6, 7, 13, 19, 20, 22, 23, 25, 52, 0, 4}


@dataclass
class _Act:
    id: int
    kind: int
    values: tuple[str, ...]
    name: str | None


@dataclass
class PanelBuilder:
    name: str
    program: ProgramBuilder
    inputs: list[tuple[str, str]] = field(default_factory=list)
    acts: list[_Act] = field(default_factory=list)

    def add(self, kind: int, *values: str, name: str | None = None) -> int:
        aid = self.program.next_id()
        self.acts.append(_Act(aid, kind, tuple(values), name))
        return aid

    def chain(self, *ids: int) -> None:
        for a, b in itertools.pairwise(ids):
            self.program.link(a, b)


class ProgramBuilder:
    def __init__(self, version: str = "4.0.0.1") -> None:
        self.version = version
        self.panels: list[PanelBuilder] = []
        self.globals: list[tuple[str, str]] = []
        self.links: list[tuple[int, int, int, int, int]] = []  # edge, src, pin, dst, in_pin
        self._id = 0
        self._edge = 0

    def next_id(self) -> int:
        self._id += 1
        return self._id

    def panel(self, name: str = "Main", inputs: tuple[tuple[str, str], ...] = ()) -> PanelBuilder:
        panel = PanelBuilder(name, self, list(inputs))
        self.panels.append(panel)
        if name != "Main":
            panel.pin_in = panel.add(-1, "")
            panel.pin_out = panel.add(-2, "")
            panel.pin_event = panel.add(-3, "")
        return panel

    def var(self, name: str, vtype: str = "System.Int32") -> None:
        self.globals.append((name, vtype))

    def link(self, src: int, dst: int, pin: int = 0, in_pin: int = 0) -> int:
        self._edge += 1
        self.links.append((self._edge, src, pin, dst, in_pin))
        return self._edge

    def robot(self, panel: PanelBuilder) -> int:
        return panel.add(19, "localhost", "8124", "WSS", "3000")

    # -- writing -------------------------------------------------------------------------
    def xml(self) -> str:
        self._into: dict[int, list] = {}
        self._from: dict[int, list] = {}
        for lk in self.links:
            self._into.setdefault(lk[3], []).append(lk)
            self._from.setdefault(lk[1], []).append(lk)
        out = ['<?xml version="1.0" encoding="utf-8"?>', '<Program VIPLE_Type="1">']
        out.append(f"  <Version>{self.version}</Version>")
        for panel in self.panels:
            out.append(f'  <ProgrammingPanel Name="{escape(panel.name)}">')
            out.append(_variables(panel.inputs, "    "))
            for act in panel.acts:
                out.append(self._activity(act))
            out.append("  </ProgrammingPanel>")
        out.append(_variables(self.globals, "  "))
        names = "".join(
            f"<CustomActivityName>{escape(p.name)}</CustomActivityName>"
            for p in self.panels
            if p.name != "Main"
        )
        out.append(f"  <UsedCustomActivityNames>{names}</UsedCustomActivityNames>")
        out.append("</Program>")
        return "\n".join(out) + "\n"

    def bytes(self, bom: bool = True, crlf: bool = True, compress: bool = False) -> bytes:
        text = self.xml()
        if crlf:
            text = text.replace("\n", "\r\n")
        data = (b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8")
        return gzip.compress(data, mtime=0) if compress else data

    def write(self, path, **kwargs) -> str:
        path.write_bytes(self.bytes(**kwargs))
        return str(path)

    def _activity(self, act: _Act) -> str:
        name = f' Name="{escape(act.name)}"' if act.name is not None else ""
        lines = [f'    <Activity{name} IsFlipped="false">']
        lines.append(f"      <ActivityNameInt>{act.kind}</ActivityNameInt>")
        lines.append(f"      <ActivityID>{act.id}</ActivityID>")
        incoming = self._into.get(act.id, [])
        leaving = self._from.get(act.id, [])
        outgoing = [lk for lk in leaving if lk[2] >= 0]
        alternate = [lk for lk in leaving if lk[2] < 0]
        in_pins = sorted({lk[4] for lk in incoming})
        indexed_in = act.kind == 4
        lines += _groups("PreviousActivities", "ActivityID", incoming, 4, 1, in_pins, indexed_in)
        out_pins = sorted({lk[2] for lk in outgoing})
        indexed_out = act.kind in (6, 7)
        lines += _groups("NextActivities", "ActivityID", outgoing, 2, 3, out_pins, indexed_out)
        lines.append(_group("AlternateNextActivities", "ActivityID", [lk[3] for lk in alternate]))
        lines += _groups("IncomingLines", "GraphEdgeID", incoming, 4, 0, in_pins, indexed_in)
        lines += _groups("OutgoingLines", "GraphEdgeID", outgoing, 2, 0, out_pins, indexed_out)
        lines.append(_group("AlternateOutgoingLines", "GraphEdgeID", [lk[0] for lk in alternate]))
        lines.append("      <Location><Left>10</Left><Top>20</Top></Location>")
        if act.values:
            vals = []
            for i, v in enumerate(act.values):
                index = f' Index="{i}"' if act.kind in _INDEXED else ""
                vals.append(f"<Value{index}>{escape(v)}</Value>")
            lines.append(f"      <Values>{''.join(vals)}</Values>")
        else:
            lines.append("      <Values />")
        lines.append("    </Activity>")
        return "\n".join(lines)


def _variables(items, indent: str) -> str:
    if not items:
        return f"{indent}<Variables />"
    body = "".join(
        f"<Variable><VariableName>{escape(n)}</VariableName>"
        f"<VariableType>{escape(t)}</VariableType></Variable>"
        for n, t in items
    )
    return f"{indent}<Variables>{body}</Variables>"


def _group(tag: str, child: str, ids, index: int | None = None) -> str:
    attr = f' Index="{index}"' if index is not None else ""
    if not ids:
        return f"      <{tag}{attr} />"
    return f"      <{tag}{attr}>" + "".join(f"<{child}>{i}</{child}>" for i in ids) + f"</{tag}>"


def _groups(tag, child, links, pin_at, value_at, pins, indexed) -> list[str]:
    if not pins:
        return [_group(tag, child, [])]
    return [
        _group(
            tag,
            child,
            [lk[value_at] for lk in links if lk[pin_at] == pin],
            pin if indexed else None,
        )
        for pin in pins
    ]
