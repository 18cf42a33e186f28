"""Reading a VIPLE program file: container, hardened XML, links rebuilt and checked.

A file is gzip-compressed (VIPLE 3.1, starts ``1f 8b``) or plain UTF-8 XML with or without a
byte order mark (VIPLE 3.5 and 4.x), with CRLF or LF line ends. Sizes are checked before
anything is decompressed or parsed; the XML parser refuses document type declarations (so no
entities and no external references) and stops at a nesting depth or element count no program
needs. Every problem found is collected, so a student sees them all at once.
"""

from __future__ import annotations

import hashlib
import os
import re
import zlib
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass
from xml.etree.ElementTree import Element, ParseError, TreeBuilder

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import XMLParser

from workbench.files.bounded import BoundedFileError, Limits, decode_text, read_bytes
from workbench.files.bounded import position as text_position
from workbench.files.terminal import terminal_problem

from . import kinds as K
from .kinds import KindMap, kind_label
from .model import ELSE, Activity, Link, Panel, Program, Variable
from .problems import Problem, ProgramError, program_problem

#: sizes: the largest real programs are about 35 KB of XML
LIMITS = Limits("a VIPLE program", max_bytes=4 << 20, max_lines=400_000, max_line_length=200_000)
MAX_DEPTH = 12
#: the largest real programs have about 2,000 elements, one or two attributes on each
MAX_ELEMENTS = 150_000
MAX_ATTRIBUTES = 16
MAX_ALL_ATTRIBUTES = 50_000
#: the longest Value (a comment, a text, an expression) and the longest name
MAX_VALUE_LENGTH = 10_000
MAX_NAME_LENGTH = 200
#: activities visited while pairing every While with its End While, all loops together
MAX_LOOP_STEPS = 400_000
MAX_ACTIVITIES = 5_000
MAX_VALUES = 200
MAX_PANELS = 500
MAX_ID = 10_000_000
_GZIP = b"\x1f\x8b"
_SAVE_AGAIN = "open it in VIPLE and save it again, or fix the lists by hand"
_NUMBER = re.compile(r"\s*-?\d{1,9}\s*")
#: the file endings of a VIPLE program, in any case: VIPLE 3.5 and 4.x save ``.viple``,
#: VIPLE 3.1 saved gzip-compressed ``.xml`` (the container is told by the bytes, not the name)
PROGRAM_SUFFIXES = (".viple", ".xml")


def is_program_name(name: str) -> bool:
    """A VIPLE program's file name: ``NAME.viple`` or ``NAME.xml``, in any case."""
    lower = name.strip().lower()
    return any(lower.endswith(s) and len(lower) > len(s) for s in PROGRAM_SUFFIXES)


class _Refused(Exception):
    def __init__(self, message: str, hint: str) -> None:
        self.message = message
        self.hint = hint


class _Tangled(Exception):
    """Pairing the loops took more than :data:`MAX_LOOP_STEPS` steps."""


class _BoundedBuilder(TreeBuilder):
    """A tree builder that stops at :data:`MAX_DEPTH` or :data:`MAX_ELEMENTS`."""

    def __init__(self) -> None:
        super().__init__()
        self.depth = 0
        self.count = 0

    def start(self, tag: str, attrs: dict[str, str], /) -> Element:
        self.depth += 1
        self.count += 1
        if len(attrs) > MAX_ATTRIBUTES:
            raise _Refused(
                f"an element has {len(attrs):,} attributes; a VIPLE program has at most "
                f"{MAX_ATTRIBUTES} on one",
                "check that this is a VIPLE program file",
            )
        if self.depth > MAX_DEPTH:
            raise _Refused(
                f"elements nested more than {MAX_DEPTH} deep; a VIPLE program needs about 6",
                "check that this is a VIPLE program file",
            )
        if self.count > MAX_ELEMENTS:
            raise _Refused(
                f"more than {MAX_ELEMENTS:,} XML elements",
                "check that this is a VIPLE program file",
            )
        return super().start(tag, attrs)

    def end(self, tag: str, /) -> Element:
        self.depth -= 1
        return super().end(tag)


def read_program_text(path: str | os.PathLike, source: str | None = None) -> tuple[str, str]:
    """The XML text of a program file and the SHA-256 of its bytes (gunzipped if needed)."""
    source = str(path) if source is None else source
    data = read_bytes(path, LIMITS, source)
    digest = hashlib.sha256(data).hexdigest()
    if data.startswith(_GZIP):
        data = _gunzip(data, source)
    return decode_text(data, source, LIMITS), digest


def _gunzip(data: bytes, source: str) -> bytes:
    inflater = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        out = inflater.decompress(data, LIMITS.max_bytes + 1)
    except zlib.error:
        raise BoundedFileError(
            source,
            "the file starts like gzip but does not decompress",
            "the file is damaged: save it again from VIPLE",
        ) from None
    if len(out) > LIMITS.max_bytes:
        raise BoundedFileError(
            source,
            f"the file decompresses to more than {LIMITS.max_bytes:,} bytes",
            "check that this is a VIPLE program file",
        )
    if not inflater.eof:
        raise BoundedFileError(
            source, "the gzip data is cut short", "the file is damaged: save it again from VIPLE"
        )
    return out


def _count_marks(text: str, source: str) -> None:
    """Refuse a text with more tags or attributes than the caps allow, before it is parsed
    (counting characters is quick; building a tree of them is not)."""
    tags = text.count("<")
    if tags > 2 * MAX_ELEMENTS + 10:
        raise BoundedFileError(
            source,
            f"the file has {tags:,} tags; a VIPLE program has at most {MAX_ELEMENTS:,} elements",
            "check that this is a VIPLE program file",
        )
    attributes = text.count("='") + text.count('="') + text.count("= ")
    if attributes > MAX_ALL_ATTRIBUTES:
        raise BoundedFileError(
            source,
            f"the file has about {attributes:,} attributes; a VIPLE program has at most "
            f"{MAX_ALL_ATTRIBUTES:,}",
            "check that this is a VIPLE program file",
        )


#: a character reference (``&#155;``, ``&#x9b;``): how a control character gets past the file's
#: own check into a name
_CHAR_REF = re.compile(r"&#(x[0-9a-fA-F]{1,8}|[0-9]{1,10});")


def _refuse_control_refs(text: str, source: str) -> None:
    """Refuse a character reference to a control character a terminal acts on (DEL, the C1
    controls; XML refuses the C0 ones itself, tab and line breaks aside), at its place."""
    for found in _CHAR_REF.finditer(text):
        ref = found.group(1)
        code = int(ref[1:], 16) if ref.startswith("x") else int(ref)
        if code in (0x09, 0x0A, 0x0D) or code > 0x10FFFF:
            continue
        problem = terminal_problem(chr(code), f"the character reference {found.group()}")
        if problem:
            line, column = text_position(text, found.start())
            raise BoundedFileError(
                source, problem, "remove the reference: write the text without it", line, column
            )


def parse_xml(text: str, source: str) -> Element:
    _count_marks(text, source)
    _refuse_control_refs(text, source)
    builder = _BoundedBuilder()
    parser = XMLParser(target=builder, forbid_dtd=True)
    try:
        parser.feed(text)
        return parser.close()
    except _Refused as exc:
        raise BoundedFileError(source, exc.message, exc.hint) from None
    except DefusedXmlException:
        raise BoundedFileError(
            source,
            "the file declares a document type or entities",
            "VIPLE programs have none: remove the <!DOCTYPE ...> part",
        ) from None
    except ParseError as exc:
        line, column = exc.position
        raise BoundedFileError(
            source,
            "the XML is not well formed",
            "the file is damaged or not a VIPLE program",
            line,
            column + 1,
        ) from None


def load_program(
    path: str | os.PathLike, kinds: KindMap | None = None, source: str | None = None
) -> Program:
    """Load and check a program file; every problem is in the :class:`ProgramError`."""
    source = str(path) if source is None else source
    try:
        text, digest = read_program_text(path, source)
        root = parse_xml(text, source)
    except BoundedFileError as exc:
        raise ProgramError([program_problem(source, _bounded_message(exc), exc.hint)]) from None
    return build_program(root, source, digest, kinds or {})


def load_program_text(text: str, source: str, kinds: KindMap | None = None) -> Program:
    """Load a program from its XML text (tests, and files already read)."""
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    try:
        root = parse_xml(decode_text(text.encode("utf-8"), source, LIMITS), source)
    except BoundedFileError as exc:
        raise ProgramError([program_problem(source, _bounded_message(exc), exc.hint)]) from None
    return build_program(root, source, digest, kinds or {})


def _bounded_message(exc: BoundedFileError) -> str:
    if exc.line is None:
        return exc.message
    where = f"line {exc.line}" + (f", column {exc.column}" if exc.column is not None else "")
    return f"{where}: {exc.message}"


# -- the element tree -> a program -----------------------------------------------------------


@dataclass
class _Raw:
    """One activity as read, before its links are checked."""

    activity: Activity
    next: dict[int, list[int]]
    out: dict[int, list[int]]
    prev: dict[int, list[int]]
    inc: dict[int, list[int]]


class _Builder:
    def __init__(self, source: str, kinds: KindMap) -> None:
        self.source = source
        self.kinds = kinds
        self.problems: list[Problem] = []
        self.loop_steps = 0

    def problem(
        self, message: str, hint: str = "", panel: str | None = None, act: Activity | None = None
    ) -> None:
        if act is not None:
            what = kind_label(act.kind, self.kinds)
            if act.name:
                what += f" {act.name}"
            self.problems.append(
                program_problem(self.source, message, hint, act.panel, act.id, act.kind, what)
            )
        else:
            self.problems.append(program_problem(self.source, message, hint, panel))

    # -- elements ------------------------------------------------------------------------
    def number(self, elem: Element | None, what: str, panel: str, owner: str) -> int | None:
        text = (elem.text or "") if elem is not None else ""
        if elem is None or not _NUMBER.fullmatch(text):
            self.problem(
                f"{owner}: {what} is missing or not a whole number",
                "the file is damaged: save it again from VIPLE",
                panel,
            )
            return None
        return int(text)

    def id_lists(
        self, elem: Element, tag: str, child: str, panel: str, act: Activity
    ) -> dict[int, list[int]] | None:
        out: dict[int, list[int]] = {}
        for group in elem.findall(tag):
            index = group.get("Index")
            if index is None:
                pin = 0
            elif _NUMBER.fullmatch(index) and 0 <= int(index) < MAX_VALUES:
                pin = int(index)
            else:
                self.problem(f"{tag} has the Index {index[:20]!r}", _SAVE_AGAIN, act=act)
                return None
            if pin in out:
                self.problem(f"{tag} appears twice with the Index {pin}", _SAVE_AGAIN, act=act)
                return None
            ids = []
            for item in group:
                if item.tag != child or not _NUMBER.fullmatch(item.text or ""):
                    self.problem(f"{tag} holds something other than {child}s", _SAVE_AGAIN, act=act)
                    return None
                ids.append(int(item.text or ""))
            out[pin] = ids
        return out

    def values(self, elem: Element | None, act_id: int, panel: str) -> tuple[str, ...] | None:
        """The Values in their Index order; None when one is too long (said as a problem)."""
        if elem is None:
            return ()
        items = elem.findall("Value")
        if len(items) > MAX_VALUES:
            self.problem(
                f"activity {act_id} has {len(items)} values; at most {MAX_VALUES}", "", panel
            )
            items = items[:MAX_VALUES]
        placed: dict[int, str] = {}
        for position, item in enumerate(items):
            if len(item.text or "") > MAX_VALUE_LENGTH:
                self.problem(
                    f"activity {act_id}: Values[{position}] is {len(item.text or ''):,} "
                    f"characters long; at most {MAX_VALUE_LENGTH:,}",
                    "shorten it (a long text can be built by a Calculate)",
                    panel,
                )
                return None
            index_text = item.get("Index")
            index = position
            if index_text is not None:
                if not _NUMBER.fullmatch(index_text) or not 0 <= int(index_text) < MAX_VALUES:
                    self.problem(f"activity {act_id}: a Value has a bad Index", _SAVE_AGAIN, panel)
                    continue
                index = int(index_text)
            if index in placed:
                self.problem(
                    f"activity {act_id}: two Values have the Index {index}", _SAVE_AGAIN, panel
                )
            placed[index] = item.text or ""
        size = max(placed, default=-1) + 1
        return tuple(placed.get(i, "") for i in range(size))

    def variables(self, elem: Element | None, panel: str | None) -> tuple[Variable, ...]:
        out = []
        seen = set()
        for item in elem.findall("Variable") if elem is not None else ():
            name = (item.findtext("VariableName") or "").strip()
            vtype = (item.findtext("VariableType") or "").strip()
            if not name:
                self.problem("a variable has no name", "name it in VIPLE's Variables dialog", panel)
                continue
            if len(name) > MAX_NAME_LENGTH:
                self.problem(
                    f"a variable's name is {len(name):,} characters; at most {MAX_NAME_LENGTH}",
                    "give it a shorter name",
                    panel,
                )
                continue
            if name.lower() in seen:
                self.problem(f"the variable {name!r} is declared twice", "remove one", panel)
            seen.add(name.lower())
            out.append(Variable(name, vtype))
        return tuple(out)

    # -- the whole program ---------------------------------------------------------------
    def build(self, root: Element, digest: str) -> Program:
        if root.tag != "Program":
            self.problem(
                f"the document is a <{root.tag[:40]}>, not a VIPLE <Program>",
                "open a .viple file saved by VIPLE",
            )
            raise ProgramError(self.problems)
        version = (root.findtext("Version") or "").strip()
        if not version:
            self.problem("the program has no <Version>", "save it again from VIPLE")
        elif not version.startswith(("3.", "4.")):
            self.problem(
                f"VIPLE version {version[:20]!r} is not one the workbench reads",
                "save it with VIPLE 3.x or 4.x",
            )
        panels_xml = root.findall("ProgrammingPanel")
        if not panels_xml:
            self.problem(
                "the program has no diagram (ProgrammingPanel)", "save it again from VIPLE"
            )
        if len(panels_xml) > MAX_PANELS:
            self.problem(f"more than {MAX_PANELS} panels", "check that this is the right file")
            raise ProgramError(self.problems)
        raws: dict[int, _Raw] = {}
        panels: dict[str, Panel] = {}
        count = 0
        for pxml in panels_xml:
            name = pxml.get("Name") or ""
            if not name:
                self.problem("a panel has no Name", "save it again from VIPLE")
                continue
            if len(name) > MAX_NAME_LENGTH:
                self.problem(
                    f"a panel's Name is {len(name):,} characters; at most {MAX_NAME_LENGTH}",
                    "give the custom activity a shorter name",
                )
                continue
            if name in panels:
                self.problem(f"two panels are named {name!r}", "rename one", name)
                continue
            ids = []
            for axml in pxml.findall("Activity"):
                count += 1
                if count > MAX_ACTIVITIES:
                    self.problem(
                        f"more than {MAX_ACTIVITIES:,} activities",
                        "check that this is the right file",
                    )
                    raise ProgramError(self.problems)
                raw = self.activity(axml, name)
                if raw is None:
                    continue
                aid = raw.activity.id
                if aid in raws:
                    self.problem(
                        f"activity ID {aid} is used twice "
                        f"(also in panel {raws[aid].activity.panel})",
                        "IDs are unique in the whole file: save it again from VIPLE",
                        name,
                    )
                    continue
                raws[aid] = raw
                ids.append(aid)
            panels[name] = Panel(name, self.variables(pxml.find("Variables"), name), tuple(ids))
        if panels and "Main" not in panels:
            self.problem("the program has no Main panel", "save it again from VIPLE")
        globals_ = self.variables(root.find("Variables"), None)
        activities = {aid: raw.activity for aid, raw in raws.items()}
        program = Program(
            source=self.source,
            version=version,
            digest=digest,
            panels=panels,
            activities=activities,
            globals=globals_,
            links=(),
            kinds=self.kinds,
        )
        self.links(program, raws)
        self.kinds_and_pins(program)
        self.blocks(program)
        self.loops(program)
        self.partners(program)
        if self.problems:
            raise ProgramError(self.problems)
        return program

    def activity(self, axml: Element, panel: str) -> _Raw | None:
        owner = "an activity"
        aid = self.number(axml.find("ActivityID"), "ActivityID", panel, owner)
        if aid is not None:
            owner = f"activity {aid}"
        kind = self.number(axml.find("ActivityNameInt"), "ActivityNameInt", panel, owner)
        if aid is None or kind is None:
            return None
        if not 0 <= aid <= MAX_ID:
            self.problem(f"activity ID {aid} is out of range", _SAVE_AGAIN, panel)
            return None
        if len(axml.get("Name") or "") > MAX_NAME_LENGTH:
            self.problem(
                f"{owner}: its Name is {len(axml.get('Name') or ''):,} characters; "
                f"at most {MAX_NAME_LENGTH}",
                "give it a shorter name",
                panel,
            )
            return None
        values = self.values(axml.find("Values"), aid, panel)
        if values is None:
            return None
        act = Activity(aid, kind, panel, (axml.get("Name") or "").strip(), values)
        lists = [
            self.id_lists(axml, "NextActivities", "ActivityID", panel, act),
            self.id_lists(axml, "OutgoingLines", "GraphEdgeID", panel, act),
            self.id_lists(axml, "PreviousActivities", "ActivityID", panel, act),
            self.id_lists(axml, "IncomingLines", "GraphEdgeID", panel, act),
            self.id_lists(axml, "AlternateNextActivities", "ActivityID", panel, act),
            self.id_lists(axml, "AlternateOutgoingLines", "GraphEdgeID", panel, act),
        ]
        present = [x for x in lists if x is not None]
        if len(present) < len(lists):
            return None
        nxt, out, prev, inc, alt_next, alt_out = present
        if alt_next.get(0) or alt_out.get(0):
            nxt[ELSE] = alt_next.get(0, [])
            out[ELSE] = alt_out.get(0, [])
        return _Raw(act, nxt, out, prev, inc)

    # -- links ---------------------------------------------------------------------------
    def links(self, program: Program, raws: dict[int, _Raw]) -> None:
        leaving: dict[int, list[tuple[int, int, int]]] = defaultdict(list)
        entering: dict[int, list[tuple[int, int, int]]] = defaultdict(list)
        for raw in raws.values():
            act = raw.activity
            if self._paired(act, raw.next, raw.out, "NextActivities", "OutgoingLines"):
                for pin, targets in raw.next.items():
                    for target, edge in zip(targets, raw.out[pin], strict=True):
                        leaving[edge].append((act.id, pin, target))
            if self._paired(act, raw.prev, raw.inc, "PreviousActivities", "IncomingLines"):
                for pin, sources in raw.prev.items():
                    for src, edge in zip(sources, raw.inc[pin], strict=True):
                        entering[edge].append((src, pin, act.id))
        acts = program.activities
        links: list[Link] = []
        for edge in sorted(set(leaving) | set(entering)):
            outs, ins = leaving.get(edge, []), entering.get(edge, [])
            first = acts[(outs or ins)[0][0] if outs else ins[0][2]]
            if len(outs) != 1 or len(ins) != 1:
                self.problem(
                    f"link {edge} leaves {len(outs)} time(s) and arrives {len(ins)} time(s); "
                    "every link leaves one activity and enters one",
                    _SAVE_AGAIN,
                    act=first,
                )
                continue
            (src, pin, target), (src2, in_pin, target2) = outs[0], ins[0]
            if src != src2 or target != target2:
                self.problem(
                    f"link {edge} goes to activity {target} but activity {target2} says it comes "
                    f"from activity {src2}",
                    _SAVE_AGAIN,
                    act=acts[src],
                )
                continue
            if target not in acts:
                self.problem(
                    f"link {edge} goes to activity {target}, which does not exist",
                    _SAVE_AGAIN,
                    act=acts[src],
                )
                continue
            if acts[target].panel != acts[src].panel:
                self.problem(
                    f"link {edge} goes to activity {target} in panel {acts[target].panel}; "
                    "links stay inside one panel",
                    _SAVE_AGAIN,
                    act=acts[src],
                )
                continue
            links.append(Link(edge, src, pin, target, in_pin))
        program.links = tuple(links)
        outputs: dict[int, dict[int, list[Link]]] = defaultdict(lambda: defaultdict(list))
        inputs: dict[int, list[Link]] = defaultdict(list)
        order = {aid: i for i, aid in enumerate(acts)}
        for link in sorted(links, key=lambda k: (order[k.source], k.pin, k.edge)):
            outputs[link.source][link.pin].append(link)
        for link in sorted(links, key=lambda k: (order[k.target], k.in_pin, k.edge)):
            inputs[link.target].append(link)
        # fan-out keeps the order the file lists the targets in
        for raw in raws.values():
            for pin, targets in raw.next.items():
                got = outputs.get(raw.activity.id, {}).get(pin)
                if got:
                    rank = {t: i for i, t in enumerate(targets)}
                    got.sort(key=lambda k: rank.get(k.target, 0))
        program.outputs = {
            a: {p: tuple(ls) for p, ls in pins.items()} for a, pins in outputs.items()
        }
        program.inputs = {a: tuple(ls) for a, ls in inputs.items()}

    def _paired(
        self, act: Activity, ids: dict[int, list[int]], edges: dict[int, list[int]], a: str, b: str
    ) -> bool:
        ok = True
        for pin in sorted(set(ids) | set(edges)):
            n, m = len(ids.get(pin, [])), len(edges.get(pin, []))
            if n != m:
                side = "Else" if pin == ELSE else f"pin {pin}"
                self.problem(
                    f"{a} lists {n} activities but {b} lists {m} links ({side}); "
                    "the two lists must be the same length",
                    _SAVE_AGAIN,
                    act=act,
                )
                ok = False
        return ok

    # -- kinds, pins and blocks ----------------------------------------------------------
    def kinds_and_pins(self, program: Program) -> None:
        for act in program.activities.values():
            if act.kind not in K.KNOWN and act.kind not in self.kinds:
                self.problem(
                    f"kind {act.kind} is not known to the workbench",
                    "if you know which VIPLE service it is, name it in a kinds mapping file "
                    "(--kinds FILE, see docs/viple-programs.md)",
                    act=act,
                )
            if act.kind in (K.INPUT_PIN, K.OUTPUT_PIN, K.EVENT_PIN) and act.panel == "Main":
                self.problem(
                    "an input, output or event pin belongs in a custom activity's panel, not Main",
                    "delete it",
                    act=act,
                )
        for name, panel in program.panels.items():
            if name == "Main":
                continue
            for kind, what in (
                (K.INPUT_PIN, "input"),
                (K.OUTPUT_PIN, "output"),
                (K.EVENT_PIN, "event"),
            ):
                count = sum(program.activities[a].kind == kind for a in panel.activities)
                if count > 1 or (kind == K.INPUT_PIN and count == 0):
                    self.problem(
                        f"the custom activity has {count} {what} pins; it needs exactly one",
                        "open the activity in VIPLE and save it again",
                        name,
                    )

    def blocks(self, program: Program) -> None:
        for act in program.activities.values():
            if act.kind != K.BLOCK:
                continue
            panel = program.panels.get(act.name)
            if not act.name or panel is None or act.name == "Main":
                self.problem(
                    f"the activity block names the panel {act.name!r}, which the file lacks",
                    "the custom activity was deleted: remove the block or add the activity again",
                    act=act,
                )
                continue
            if len(act.values) % 2:
                self.problem(
                    "its parameter values are not in name/value pairs",
                    _SAVE_AGAIN,
                    act=act,
                )
                continue
            params = {v.name.lower() for v in panel.inputs}
            for name in act.values[0::2]:
                if name.strip() and name.strip().lower() not in params:
                    self.problem(
                        f"it sets the parameter {name[:40]!r}, which the activity {act.name} "
                        "does not have",
                        f"its parameters are: {', '.join(v.name for v in panel.inputs) or 'none'}",
                        act=act,
                    )

    # -- loops ---------------------------------------------------------------------------
    def loops(self, program: Program) -> None:
        acts = program.activities
        self.loop_steps = 0
        for act in acts.values():
            if act.kind != K.WHILE:
                continue
            try:
                ends, breaks = self._loop_body(program, act.id)
            except _Tangled:
                self.problem(
                    f"following the While loops' bodies took more than {MAX_LOOP_STEPS:,} "
                    "steps: the loops are too tangled to pair each While with its End While",
                    "give each While a body that leads to its own End While",
                    act=act,
                )
                return
            if len(ends) == 1:
                end = ends[0]
                if end in program.loop_start:
                    self.problem(
                        f"its End While {end} also closes While {program.loop_start[end]}",
                        "give each While its own End While",
                        act=act,
                    )
                    continue
                program.loop_end[act.id] = end
                program.loop_start[end] = act.id
                for brk in breaks:
                    program.break_loop.setdefault(brk, act.id)
            elif not ends:
                self.problem(
                    "no End While is reached from its body",
                    "connect the loop's last activity to an End While",
                    act=act,
                )
            else:
                self.problem(
                    f"its body reaches {len(ends)} End Whiles ({', '.join(map(str, ends))})",
                    "a loop has exactly one End While: join the branches with a Merge first",
                    act=act,
                )
        for act in acts.values():
            if act.kind == K.END_WHILE and act.id not in program.loop_start:
                self.problem(
                    "no While leads to this End While",
                    "connect a While's output to the loop body that ends here",
                    act=act,
                )
            if act.kind == K.BREAK and act.id not in program.break_loop:
                self.problem(
                    "the Break is not inside a While loop", "move it into a loop body", act=act
                )

    def _loop_body(self, program: Program, start: int) -> tuple[list[int], list[int]]:
        acts = program.activities
        ends: list[int] = []
        breaks: list[int] = []
        seen: set[tuple[int, int]] = set()
        stack = [(link.target, 0) for link in program.targets(start, 0)]
        while stack:
            aid, depth = stack.pop()
            if (aid, depth) in seen or depth > MAX_DEPTH * 4 or aid == start:
                continue
            seen.add((aid, depth))
            self.loop_steps += 1
            if self.loop_steps > MAX_LOOP_STEPS:
                raise _Tangled()
            kind = acts[aid].kind
            if kind == K.END_WHILE:
                if depth == 0:
                    if aid not in ends:
                        ends.append(aid)
                    continue
                depth -= 1
            elif kind == K.WHILE:
                depth += 1
            elif kind == K.BREAK and depth == 0:
                breaks.append(aid)
                continue
            for links in program.outputs.get(aid, {}).values():
                stack.extend((link.target, depth) for link in links)
        return sorted(ends), breaks

    def partners(self, program: Program) -> None:
        robots = [a for a in program.activities.values() if a.kind == K.ROBOT]
        for act in program.activities.values():
            index = partner_index(act.kind, self.kinds)
            if index is None:
                continue
            if not robots:
                self.problem(
                    "it uses a robot, but the program has no Robot activity",
                    "add a Robot (Robot/IoT Controller) activity",
                    act=act,
                )
            elif len(robots) > 1 and resolve_partner(act.value(index), len(robots)) is None:
                self.problem(
                    f"its robot {act.value(index)[:40]!r} matches none of the "
                    f"{len(robots)} Robot activities",
                    "choose the robot again in the activity's settings",
                    act=act,
                )


def partner_index(kind: int, mapping: KindMap) -> int | None:
    """Which Value of a robot service names its Robot, or None for other activities."""
    if kind == K.DRIVE:
        return 2
    if kind in (K.TOUCH, K.DISTANCE, K.OTHER_SENSOR, K.RAW_SENSOR):
        return 0
    return None


def resolve_partner(name: str, robots: int) -> int | None:
    """The robot (0-based, in file order) a service's partner name points to: the trailing
    number of the display name ("My Robot 0", "Robot/IoT Controller 1")."""
    text = name.rstrip()
    digits = len(text) - len(text.rstrip("0123456789"))
    if not digits:
        return 0 if robots == 1 else None
    index = int(text[-min(digits, 6) :])
    return index if index < robots else None


def build_program(root: Element, source: str, digest: str, kinds: KindMap) -> Program:
    return _Builder(source, kinds).build(root, digest)


def problems_of(items: Iterable[Problem]) -> list[str]:
    return [str(p) for p in items]
