"""Bounded reads of untrusted input files: limits checked before anything is parsed.

Every file the workbench reads (mazes, FSM files, lab files, the SSH users file) passes through
here first. The size in bytes, the number of lines and the longest line are checked before the
text is parsed; UTF-8 is decoded strictly; control characters other than tab, CR and LF are
refused; a leading byte order mark is dropped. YAML is composed with limits on nesting depth,
aliases and the number of values, counted while it is read, so a hostile file never recurses
deeply or expands into a huge tree. Numbers in YAML must be finite and of at most
:data:`MAX_DIGITS` digits.

Errors never quote the file's content: a student may be able to point the workbench at a
file they may not read, so a message names at most a position and a code point.
"""

from __future__ import annotations

import math
import os
import re
import stat
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, TypeVar

import yaml
from yaml.constructor import SafeConstructor
from yaml.events import AliasEvent
from yaml.nodes import Node, ScalarNode

from .terminal import FIX as TERMINAL_FIX
from .terminal import terminal_problem

BOM = "\ufeff"
#: a number in a file (YAML or an FSM expression) has at most this many digits
MAX_DIGITS = 30
#: a list of problems shown to a person stops after this many, then says how many more
MAX_PROBLEMS = 20

#: control characters (C0 except tab, LF, CR; DEL; C1), line separators and non-characters
_REFUSED_CHARS = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\u2028\u2029\ufffe\uffff]")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_FLOAT_TAG = "tag:yaml.org,2002:float"
_INT_TAG = "tag:yaml.org,2002:int"


@dataclass(frozen=True)
class Limits:
    """What one kind of input file may hold; ``kind`` names it in messages ("a maze file")."""

    kind: str
    max_bytes: int = 1 << 20
    max_lines: int = 20_000
    max_line_length: int = 5_000
    #: YAML: mappings and lists inside each other
    max_depth: int = 32
    #: YAML: ``*name`` references to an ``&name`` anchor
    max_aliases: int = 50
    #: YAML: scalars, lists and mappings, an alias counting as a copy of what it names
    max_nodes: int = 50_000


MAZE_LIMITS = Limits("a maze file", max_lines=12_000, max_line_length=2_000)
FSM_LIMITS = Limits("an FSM file")
LAB_LIMITS = Limits("a lab file")
USERS_LIMITS = Limits("a users file", max_lines=50_000, max_nodes=100_000)


class BoundedFileError(ValueError):
    """An input file refused before or while it was parsed; positions are 1-based."""

    def __init__(
        self,
        path: str,
        message: str,
        hint: str = "",
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        self.path = path
        self.message = message
        self.hint = hint
        self.line = line
        self.column = column
        super().__init__(str(self))

    def __str__(self) -> str:
        where = self.path
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        return f"{where}: {self.message}" + (f" ({self.hint})" if self.hint else "")


# -- plain text -------------------------------------------------------------------------------


def read_bytes(path: str | os.PathLike, limits: Limits, source: str | None = None) -> bytes:
    """The bytes of ``path``, refused unread when the file is larger than ``limits`` allow."""
    source = str(path) if source is None else source
    try:
        # Opened without blocking, so that a pipe or a device named as a file is refused at
        # once instead of holding the caller until something writes to it.
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        _refuse_unless_plain(fd, source)
        with open(fd, "rb") as fh:
            size = os.fstat(fh.fileno()).st_size
            if size > limits.max_bytes:
                raise _too_big(source, size, limits)
            data = fh.read(limits.max_bytes + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise BoundedFileError(
            source, f"cannot read the file: {reason}", "check the path"
        ) from None
    if len(data) > limits.max_bytes:
        raise _too_big(source, len(data), limits)
    return data


def _refuse_unless_plain(fd: int, source: str) -> None:
    """Nothing for a regular file; otherwise closes ``fd`` and names what it is."""
    mode = os.fstat(fd).st_mode
    if stat.S_ISREG(mode):
        return
    os.close(fd)
    raise BoundedFileError(
        source, f"cannot read the file: it is {_kind(mode)}", "give the path of a plain file"
    )


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a plain file"


def read_text(path: str | os.PathLike, limits: Limits, source: str | None = None) -> str:
    """The checked text of ``path`` (see :func:`decode_text`)."""
    source = str(path) if source is None else source
    return decode_text(read_bytes(path, limits, source), source, limits)


def strip_bom(data: bytes) -> bytes:
    return data[3:] if data.startswith(BOM.encode()) else data


def decode_text(data: bytes, source: str, limits: Limits) -> str:
    """``data`` as text: size checked, a leading BOM dropped, strict UTF-8, then
    :func:`check_text`."""
    if len(data) > limits.max_bytes:
        raise _too_big(source, len(data), limits)
    data = strip_bom(data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        head = data[: exc.start].decode("utf-8")
        line, column = position(head, len(head))
        raise BoundedFileError(
            source,
            f"byte 0x{data[exc.start]:02X} is not UTF-8 text",
            "save the file as UTF-8 text",
            line,
            column,
        ) from None
    return check_text(text, source, limits)


def check_text(text: str, source: str, limits: Limits) -> str:
    """``text`` without a leading BOM, or :class:`BoundedFileError` for the first of: a
    refused character, too many lines, a line too long."""
    text = text.removeprefix(BOM)
    if len(text) > limits.max_bytes:
        raise _too_big(source, len(text.encode("utf-8", "surrogatepass")), limits)
    bad = _REFUSED_CHARS.search(text)
    if bad is not None:
        line, column = position(text, bad.start())
        raise BoundedFileError(
            source,
            f"character U+{ord(bad.group()):04X} is a control character",
            "remove it: only tab and line breaks may appear besides printable text",
            line,
            column,
        )
    start, number = 0, 1
    for brk in _LINE_BREAK.finditer(text):
        _check_line(source, limits, number, brk.start() - start)
        start, number = brk.end(), number + 1
        if number > limits.max_lines and start < len(text):
            count = len(text.splitlines())
            raise BoundedFileError(
                source,
                f"the file has {count:,} lines; {limits.kind} has at most {limits.max_lines:,}",
                "check that this is the right file",
                number,
            )
    _check_line(source, limits, number, len(text) - start)
    return text


def _check_line(source: str, limits: Limits, number: int, length: int) -> None:
    if length > limits.max_line_length:
        raise BoundedFileError(
            source,
            f"the line is {length:,} characters long; {limits.kind} has lines of at most "
            f"{limits.max_line_length:,}",
            "check that this is the right file, or break the line",
            number,
            limits.max_line_length + 1,
        )


def _too_big(source: str, size: int, limits: Limits) -> BoundedFileError:
    return BoundedFileError(
        source,
        f"the file is {size:,} bytes; {limits.kind} is at most {limits.max_bytes:,}",
        "check that this is the right file",
    )


def position(text: str, index: int) -> tuple[int, int]:
    """The 1-based (line, column) of ``text[index]``; CR LF, CR and LF end a line."""
    breaks = list(_LINE_BREAK.finditer(text, 0, index))
    line_start = breaks[-1].end() if breaks else 0
    return len(breaks) + 1, index - line_start + 1


# -- lists of problems ------------------------------------------------------------------------

T = TypeVar("T")


def capped(items: list[T], more: Callable[[int], T], limit: int = MAX_PROBLEMS) -> list[T]:
    """The first ``limit`` items, then ``more(n)`` standing for the ``n`` left out."""
    if len(items) <= limit:
        return list(items)
    return [*items[:limit], more(len(items) - limit)]


def more_problems(count: int) -> str:
    return f"and {count:,} more problem{'s' if count != 1 else ''}"


# -- numbers ----------------------------------------------------------------------------------


def digits_problem(text: str) -> str | None:
    """Why the number written ``text`` has too many digits to be read, or None."""
    digits = sum(ch.isdigit() for ch in text)
    if digits > MAX_DIGITS:
        return f"a number with {digits:,} digits; numbers have at most {MAX_DIGITS}"
    return None


def finite_problem(value: float) -> str | None:
    """Why ``value`` read from a file is refused (NaN or infinite), or None."""
    if isinstance(value, float) and not math.isfinite(value):
        return "a number that is not finite (NaN or infinity)"
    return None


# -- YAML -------------------------------------------------------------------------------------


class _Mark(Protocol):
    """A place in the text, as both PyYAML's Python and C parsers mark it (0-based)."""

    line: int
    column: int


class _BoundedLoader(yaml.SafeLoader):
    """A safe loader that counts nesting, aliases and values while it composes."""

    def __init__(self, text: str, source: str, limits: Limits, first_line: int) -> None:
        super().__init__(text)
        self.source = source
        self.limits = limits
        self.first_line = first_line
        self.depth = 0
        self.aliases = 0
        self.nodes = 0
        #: anchor -> number of values under it, so an alias counts as a copy
        self.sizes: dict[str, int] = {}

    def refuse(self, mark: _Mark | None, message: str, hint: str) -> BoundedFileError:
        line = mark.line + self.first_line if mark is not None else None
        column = mark.column + 1 if mark is not None else None
        return BoundedFileError(self.source, message, hint, line, column)

    def compose_node(self, parent: Node | None, index: object) -> Node | None:
        event = self.peek_event()
        kind = self.limits.kind
        if isinstance(event, AliasEvent):
            self.aliases += 1
            if self.aliases > self.limits.max_aliases:
                raise self.refuse(
                    event.start_mark,
                    f"more than {self.limits.max_aliases} aliases (*name); {kind} needs few",
                    "write the values out instead of repeating an anchor",
                )
            anchor = str(event.anchor)
            if anchor in self.anchors and anchor not in self.sizes:
                raise self.refuse(
                    event.start_mark,
                    "an alias (*name) inside the value its anchor (&name) names",
                    "a value cannot contain itself: write it out",
                )
            self.count(event.start_mark, self.sizes.get(anchor, 1))
            # PyYAML passes a mapping value's key node as its index; the stub says int
            return super().compose_node(parent, index)  # type: ignore[arg-type]
        if self.depth >= self.limits.max_depth:
            raise self.refuse(
                event.start_mark,
                f"lists and mappings nested more than {self.limits.max_depth} deep",
                f"{kind} needs only a few levels: check the brackets and indentation",
            )
        before = self.nodes
        self.count(event.start_mark, 1)
        self.depth += 1
        try:
            node = super().compose_node(parent, index)  # type: ignore[arg-type]  # as above
        finally:
            self.depth -= 1
        named = getattr(event, "anchor", None)
        if named is not None:
            self.sizes[str(named)] = self.nodes - before
        if isinstance(node, ScalarNode) and node.tag in (_INT_TAG, _FLOAT_TAG):
            reason = digits_problem(node.value)
            if reason is None and node.tag == _FLOAT_TAG:
                reason = finite_problem(self.construct_yaml_float(node))
            if reason is not None:
                raise self.refuse(node.start_mark, reason, "write a plain finite number")
        if isinstance(node, ScalarNode):
            field = f"{index.value[:40]!r}" if isinstance(index, ScalarNode) else "a value"
            problem = terminal_problem(str(node.value), field, multiline=True)
            if problem:
                raise self.refuse(node.start_mark, problem, TERMINAL_FIX)
        return node

    def count(self, mark: _Mark | None, nodes: int) -> None:
        self.nodes += nodes
        if self.nodes > self.limits.max_nodes:
            raise self.refuse(
                mark,
                f"more than {self.limits.max_nodes:,} values (an alias counts as a copy of "
                f"what it names); {self.limits.kind} holds far fewer",
                "check that this is the right file",
            )


def compose_yaml(text: str, source: str, limits: Limits, first_line: int = 1) -> Node | None:
    """The node tree of one YAML document within ``limits``; None for an empty document.

    Limits are :class:`BoundedFileError` (line numbers start at ``first_line``); syntax errors
    stay :class:`yaml.YAMLError` for the caller to word in its own style.
    """
    loader = None
    try:
        loader = _BoundedLoader(text, source, limits, first_line)
        return loader.get_single_node()
    except yaml.reader.ReaderError as exc:
        line, column = position(text, exc.position)
        raise BoundedFileError(
            source,
            f"character U+{exc.character:04X} cannot appear in YAML"
            if isinstance(exc.character, int)
            else "a character that cannot appear in YAML",
            "remove it",
            line + first_line - 1,
            column,
        ) from None
    finally:
        if loader is not None:
            loader.dispose()


def load_yaml(text: str, source: str, limits: Limits, first_line: int = 1) -> object:
    """Plain Python values of one YAML document within ``limits`` (None when empty)."""
    node = compose_yaml(text, source, limits, first_line)
    if node is None:
        return None
    return SafeConstructor().construct_document(node)
