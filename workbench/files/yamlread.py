"""Reading a composed YAML tree into typed values, collecting every problem with its place.

The FSM files, lab files and the SSH users file are YAML composed by the bounded composer
(:func:`~workbench.files.bounded.compose_yaml`); each is then read node by node with a
:class:`NodeReader`. A problem is recorded with its file, line and column and a hint; the part
being read (an exercise, a user, a state) is then left out and reading goes on with the next
one, so a person fixing a file sees all of its problems at once. :meth:`NodeReader.check`
raises the file kind's error with every problem found.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import NoReturn, TypeVar

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from .bounded import BoundedFileError, capped, more_problems
from .problems import Problem

T = TypeVar("T")
E = TypeVar("E", bound=Exception)

_NULL = "tag:yaml.org,2002:null"


def file_problem(file: str, line: int, column: int, message: str, hint: str = "") -> Problem:
    """A problem of a file read here: where (line and column from 1; 0 when it is the whole
    file), what is wrong, and how to fix it, written ``file:line:column: what (hint: fix)``."""
    return Problem(message, hint, file, line, column, hint_word="hint")


def refused_problem(exc: BoundedFileError) -> Problem:
    """The problem of a file the bounded reader refused."""
    line, column = exc.line or 0, exc.column or (1 if exc.line else 0)
    return file_problem(exc.path, line, column, exc.message, exc.hint)


def syntax_problem(file: str, exc: yaml.YAMLError, hint: str = "") -> Problem:
    """The problem of text that is not valid YAML, at the parser's mark, with a hint for the
    usual slips (``hint`` when none fits)."""
    if not isinstance(exc, yaml.MarkedYAMLError):
        return file_problem(file, 1, 1, f"YAML syntax: {exc}", hint)
    mark = exc.problem_mark or exc.context_mark
    message = exc.problem or "cannot be parsed"
    if exc.context:
        message = f"{exc.context}: {message}"
    line, column = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
    return file_problem(
        file, line, column, f"YAML syntax: {message}", _syntax_hint(message) or hint
    )


def _syntax_hint(message: str) -> str:
    if "\t" in message or "'\\t'" in message:
        return "indent with spaces, not tabs"
    if "mapping values are not allowed" in message:
        return "put quotes around a value that contains ': '"
    if "expected a single document" in message or "but found another document" in message:
        return "one document per file: remove the extra '---'"
    if "could not find expected ':'" in message:
        return "each entry must be 'key: value'; check the indentation of this line"
    return ""


def problem_list(problems: Iterable[Problem]) -> list[Problem]:
    """``problems``, cut after :data:`~workbench.files.bounded.MAX_PROBLEMS` saying how many
    more."""
    problems = list(problems)
    file = problems[0].source if problems else "<text>"
    hint = "fix the problems above first"
    return capped(problems, lambda n: file_problem(file, 0, 0, more_problems(n), hint))


class Skip(Exception):
    """The part being read has a problem (already recorded): leave it out and go on."""


class NodeReader:
    """Typed access to the nodes of one file; every problem is kept in :attr:`problems`."""

    def __init__(self, source: str) -> None:
        #: the file's name as problems show it
        self.source = source
        self.problems: list[Problem] = []

    # -- problems ------------------------------------------------------------------------------
    def note(self, node: Node | None, where: str, message: str, hint: str = "") -> None:
        """Record a problem at ``node`` (``where`` names the part, e.g. ``users.ana.role``)."""
        line, column = (
            (node.start_mark.line + 1, node.start_mark.column + 1) if node is not None else (1, 1)
        )
        prefix = f"{where}: " if where else ""
        self.problems.append(file_problem(self.source, line, column, prefix + message, hint))

    def fail(self, node: Node | None, where: str, message: str, hint: str = "") -> NoReturn:
        """Record a problem and leave the part being read out (see :meth:`each`)."""
        self.note(node, where, message, hint)
        raise Skip

    def each(self, nodes: Iterable[Node], read: Callable[[Node], T]) -> list[T]:
        """``read`` each node; the ones with a problem are left out, the others kept."""
        out = []
        for node in nodes:
            try:
                out.append(read(node))
            except Skip:
                continue
        return out

    def check(self, error: Callable[[list[Problem]], E]) -> None:
        """Raise ``error(problems)`` when any problem was found, in the file's order."""
        if self.problems:
            ordered = sorted(self.problems, key=lambda p: (p.line, p.column))
            raise error(problem_list(ordered))

    # -- typed access ----------------------------------------------------------------------
    def pairs(self, node: Node, where: str, what: str) -> list[tuple[str, Node, Node]]:
        """The (key, key node, value node) pairs of a mapping, each key once."""
        if not isinstance(node, MappingNode):
            self.fail(node, where, f"must be {what}", "write 'key: value' lines")
        out: list[tuple[str, Node, Node]] = []
        seen: set[str] = set()
        for key_node, value in node.value:
            if not isinstance(key_node, ScalarNode):
                self.note(key_node, where, "a key must be a plain name", "write 'name:'")
                continue
            key = str(key_node.value)
            if key in seen:
                self.note(key_node, where, f"{key!r} is given twice", "keep one of them")
                continue
            seen.add(key)
            out.append((key, key_node, value))
        return out

    def mapping(
        self, node: Node, where: str, required: tuple[str, ...], optional: tuple[str, ...] = ()
    ) -> dict[str, Node]:
        """A mapping with these keys only; a missing required key leaves the part out."""
        allowed = required + optional
        out: dict[str, Node] = {}
        for key, key_node, value in self.pairs(node, where, "a mapping of 'key: value' lines"):
            if key not in allowed:
                self.note(
                    key_node, where, f"unknown key {key!r}", f"use one of {', '.join(allowed)}"
                )
                continue
            out[key] = value
        missing = [key for key in required if key not in out]
        if missing:
            self.fail(node, where, f"missing key {missing[0]!r}", f"add '{missing[0]}: ...'")
        return out

    def text(self, node: Node, where: str, hint: str = "write it on the same line") -> str:
        if not isinstance(node, ScalarNode) or not str(node.value).strip():
            self.fail(node, where, "must be a non-empty text", hint)
        return str(node.value)

    def number(self, node: Node, where: str, minimum: float = 0.0) -> float:
        value = yaml.safe_load(yaml.serialize(node)) if isinstance(node, ScalarNode) else None
        if isinstance(value, bool) or not isinstance(value, int | float) or value < minimum:
            shown = repr(node.value) if isinstance(node, ScalarNode) else "this"
            self.fail(node, where, f"{shown} is not a number of at least {minimum:g}")
        return float(value)

    def items(self, node: Node, where: str) -> list[Node]:
        """The items of a list (one plain value counts as a list of one)."""
        if isinstance(node, ScalarNode) and not is_null(node):
            return [node]
        if not isinstance(node, SequenceNode) or not node.value:
            self.fail(node, where, "must be a list with at least one item", "write [a, b]")
        return list(node.value)

    def texts(self, node: Node, where: str) -> tuple[str, ...]:
        return tuple(self.text(n, where) for n in self.items(node, where))

    def choice(self, node: Node, where: str, allowed: Iterable[str], what: str) -> str:
        allowed = tuple(allowed)
        value = self.text(node, where)
        if value not in allowed:
            self.fail(node, where, f"unknown {what} {value!r}", f"use one of {', '.join(allowed)}")
        return value


def is_null(node: Node | None) -> bool:
    """An empty value (nothing after the colon, ``~`` or ``null``)."""
    return node is None or (isinstance(node, ScalarNode) and node.tag == _NULL)
