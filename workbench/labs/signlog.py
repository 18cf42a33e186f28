"""The sign-off log: signed records chained by hashes, and its head.

Every entry has a sequence number (1, 2, 3, ... with no gaps) and the hash of the entry before
it (``prev``; the first entry's is :data:`GENESIS`). A record signed since the log was chained
(format ``workbench-signoff/2``) has its ``seq`` and ``prev`` inside the signed bytes, so an
entry cannot be moved, copied or left out without breaking either a signature or a link. An
entry's hash covers its sequence number, its ``prev``, the SHA-256 of its signed bytes and its
signature. The last entry's sequence number and hash are the log's *head*: whoever keeps a head
can later tell a log that was cut short or rolled back from one that only grew.

Everything hashed or signed is canonical JSON of the entry's fields (sorted keys, no spaces,
UTF-8): the database only stores the fields, so the same log can live in any database.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

RECORD_FORMAT = "workbench-signoff/2"
LEGACY_RECORD_FORMAT = "workbench-signoff/1"
ENTRY_FORMAT = "workbench-signoff-entry/1"
GENESIS = "sha256:" + "0" * 64

# The signed fields, in the names the records and the database use.
FIELDS = (
    "student",
    "partner",
    "driver",
    "lab",
    "exercise",
    "instructor",
    "signed_at",
    "note",
    "override",
)

_HASH = re.compile(r"(?:sha256:)?([0-9a-f]{64})")
_SEQ = re.compile(r"[0-9]{1,18}")


class LogError(ValueError):
    """A head or an entry that cannot be read; the message says where and why."""


def canonical_json(value: Any) -> str:
    """Sorted keys, no spaces, UTF-8 text as is; NaN and infinities are refused."""
    return json.dumps(
        value, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
    )


def parse_metrics(text: str) -> Any:
    """Stored metrics (canonical JSON text) as signed; text that is not JSON the workbench
    writes (not JSON, NaN, nested too deep) as ``{"unreadable": text}``."""
    try:
        return json.loads(text, parse_constant=_no_constant, parse_float=_finite)
    except (ValueError, RecursionError):
        return {"unreadable": text}


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text} is too large")
    return value


def signed_payload(
    fields: Mapping[str, Any],
    evidence: Mapping[str, Any],
    seq: int | None,
    prev: str | None,
) -> bytes:
    """The bytes an instructor signs: the record's fields and evidence, and for a chained
    record (``seq`` given) its place in the log; ``seq=None`` gives a legacy record's bytes."""
    data: dict[str, Any] = {name: fields[name] for name in FIELDS}
    data["override"] = bool(data["override"])
    data["evidence"] = {
        "run_record": evidence["run_record"],
        "digest": evidence["digest"],
        "metrics": evidence["metrics"],
    }
    if seq is None:
        data["format"] = LEGACY_RECORD_FORMAT
    else:
        data.update(format=RECORD_FORMAT, seq=seq, prev=prev)
    return canonical_json(data).encode("utf-8")


def entry_hash(seq: int, prev: str, signed: bytes, signature: str) -> str:
    """The hash of one entry of the log, ``sha256:`` and 64 hex digits."""
    body = {
        "format": ENTRY_FORMAT,
        "seq": seq,
        "prev": prev,
        "record_sha256": hashlib.sha256(signed).hexdigest(),
        "signature": signature,
    }
    return "sha256:" + hashlib.sha256(canonical_json(body).encode("utf-8")).hexdigest()


@dataclass(frozen=True)
class Head:
    """The last entry of a log: its sequence number and hash (``0`` and GENESIS when empty)."""

    seq: int
    hash: str

    def __str__(self) -> str:
        return f"{self.seq}:{self.hash.removeprefix('sha256:')}"

    @classmethod
    def parse(cls, text: str, where: str = "the head") -> Head:
        """``SEQ:HASH`` as printed by verify and export (the hash with or without
        ``sha256:``)."""
        seq_text, _, hash_text = text.strip().partition(":")
        match = _HASH.fullmatch(hash_text.strip().lower())
        if not _SEQ.fullmatch(seq_text.strip()) or not match:
            raise LogError(
                f"{where} {text.strip()[:80]!r} is not SEQ:HASH (a number, a colon and 64 hex "
                "digits, as 'workbench signoff verify' prints it)"
            )
        return cls(int(seq_text), "sha256:" + match.group(1))


EMPTY_HEAD = Head(0, GENESIS)


def next_place(numbered: Sequence[tuple[int, str]]) -> tuple[int, str]:
    """Where the next record goes (its sequence number and ``prev``), given the stored
    ``(seq, entry hash)`` of every numbered record in the order of their sequence numbers:
    after the run of consecutive numbers that starts with the lowest one from 1 (the log as it
    grew), so a record planted with a far-off number (``999999999999999999``, or one below 1)
    is stepped over rather than followed; verify names it. The place is free, as the run stops
    before the first number not taken."""
    numbered = [(seq, stored) for seq, stored in numbered if seq >= 1]
    if not numbered:
        return 1, GENESIS
    last_seq, last_hash = numbered[0]
    for seq, stored in numbered[1:]:
        if seq != last_seq + 1:
            break
        last_seq, last_hash = seq, stored
    return last_seq + 1, last_hash


@dataclass(frozen=True)
class Entry:
    """What the chain check needs of one stored record."""

    id: int
    seq: int | None
    prev: str
    stored_hash: str
    legacy: bool
    signed: bytes
    signature: str

    def computed_hash(self) -> str:
        return entry_hash(self.seq or 0, self.prev, self.signed, self.signature)


@dataclass(frozen=True)
class ChainReport:
    """Problems with the log as a whole, and those of single entries by their row id."""

    head: Head
    breaks: tuple[str, ...]
    by_row: Mapping[int, tuple[str, ...]]

    @property
    def ok(self) -> bool:
        return not self.breaks and not any(self.by_row.values())


def check_chain(entries: Sequence[Entry], kept: Head | None = None) -> ChainReport:
    """Check that ``entries`` (in the order of their sequence numbers) form one unbroken log,
    and, given the head an instructor kept, that the log still holds that head."""
    breaks: list[str] = []
    by_row: dict[int, list[str]] = {e.id: [] for e in entries}
    prev_hash = head_hash = GENESIS
    expected_seq = 1
    seen_chained = False
    signatures: dict[str, int] = {}
    for e in entries:
        problems = by_row[e.id]
        if e.seq is None:
            problems.append("it has no place in the log (no sequence number)")
            continue
        if e.seq < expected_seq:
            problems.append(f"sequence number {e.seq} appears again (a copied or inserted record)")
        elif e.seq > expected_seq:
            missing = (
                f"{expected_seq}" if e.seq == expected_seq + 1 else f"{expected_seq}-{e.seq - 1}"
            )
            breaks.append(
                f"the log breaks before sequence {e.seq}: record(s) {missing} are missing (deleted)"
            )
        if e.prev != prev_hash:
            problems.append(
                f"it does not follow the record before it (its link is {_short(e.prev)}, the "
                f"record before hashes to {_short(prev_hash)}): records were removed, "
                "reordered or inserted"
            )
        actual = e.computed_hash()
        if e.stored_hash != actual:
            problems.append("its stored hash does not match its contents")
        if e.legacy and seen_chained:
            problems.append(
                "a legacy record (signed before the log was chained) after chained ones: "
                "legacy records can only come first"
            )
        seen_chained = seen_chained or not e.legacy
        if e.signature in signatures:
            problems.append(f"it is a copy of the record with id {signatures[e.signature]}")
        signatures.setdefault(e.signature, e.id)
        # the next record links to this one's stored hash, so a record changed in place
        # fails alone; one changed and re-hashed breaks the next record's link as well
        prev_hash = e.stored_hash or actual
        head_hash = actual
        expected_seq = max(expected_seq, e.seq + 1)
    last = entries[-1] if entries else None
    head = Head(last.seq or 0, head_hash) if last is not None else EMPTY_HEAD
    if kept is not None:
        breaks.extend(_check_kept(entries, head, kept))
    return ChainReport(head, tuple(breaks), {k: tuple(v) for k, v in by_row.items()})


def _check_kept(entries: Sequence[Entry], head: Head, kept: Head) -> list[str]:
    if kept.seq == 0:
        return [] if kept.hash == GENESIS else [f"the kept head {kept} is not a head of any log"]
    if head.seq < kept.seq:
        return [
            f"the log ends at sequence {head.seq} but the kept head is at {kept.seq}: "
            "records were removed from the end, or the database was rolled back to an older copy"
        ]
    at = [e for e in entries if e.seq == kept.seq]
    if not any(e.computed_hash() == kept.hash for e in at):
        return [
            f"the record at sequence {kept.seq} is not the one the kept head {kept} names: "
            "the log was rewritten from there, or this is another log"
        ]
    return []


def _short(value: str) -> str:
    return value.removeprefix("sha256:")[:12] or "(none)"
