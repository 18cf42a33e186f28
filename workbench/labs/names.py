"""People's names as the labs keep them: students, partners and instructors.

A name is normalised to Unicode NFKC (so a full-width "Ａｎａ" is "Ana") and then refused if it
could pass for another name: invisible or format characters (zero-width spaces, joiners, bidi
controls, fillers), control characters, two spaces in a row, or letters of scripts that are
not used together in one name (Latin with a Cyrillic "і", say). One name keeps to one script,
except for the combinations the languages need: Latin may appear with Han, Hiragana, Katakana,
Bopomofo or Hangul as in Japanese, Chinese and Korean names. Digits, punctuation, spaces and
combining accents belong to every script.
"""

from __future__ import annotations

import unicodedata

MAX_STUDENT_NAME = 40

# Characters that show nothing: Unicode's default-ignorable code points outside the format
# category (which is refused as a whole), and blanks that are letters or symbols.
_INVISIBLE = (
    (0x034F, 0x034F),  # combining grapheme joiner
    (0x115F, 0x1160),  # Hangul choseong / jungseong fillers
    (0x17B4, 0x17B5),  # Khmer inherent vowels
    (0x180B, 0x180F),  # Mongolian variation selectors
    (0x2800, 0x2800),  # braille pattern blank
    (0x3164, 0x3164),  # Hangul filler
    (0xFE00, 0xFE0F),  # variation selectors
    (0xFFA0, 0xFFA0),  # half-width Hangul filler
    (0xE0100, 0xE01EF),  # variation selectors supplement
)

# Categories refused outright: controls, format characters (zero-width space and joiners,
# bidi controls, soft hyphen, byte order mark), surrogates, private use, unassigned, and the
# line and paragraph separators.
_REFUSED_CATEGORIES = {
    "Cc": "control characters",
    "Cf": "invisible formatting characters",
    "Cs": "unpaired surrogates",
    "Co": "private-use characters",
    "Cn": "unassigned characters",
    "Zl": "line separators",
    "Zp": "paragraph separators",
}

# The first word of a letter's Unicode name is its script, under another name for a few.
_SCRIPT_ALIASES = {"CJK": "HAN", "KATAKANA-HIRAGANA": "KATAKANA", "IDEOGRAPHIC": "HAN"}
_EAST_ASIAN = (
    {"LATIN", "HAN", "HIRAGANA", "KATAKANA"},
    {"LATIN", "HAN", "BOPOMOFO"},
    {"LATIN", "HAN", "HANGUL"},
)


class NameProblem(ValueError):
    """A name cannot be used; the message says why."""


def _invisible(code: int) -> bool:
    return any(lo <= code <= hi for lo, hi in _INVISIBLE)


def script_of(char: str) -> str | None:
    """The script of a letter or of a mark that belongs to one (e.g. ``"LATIN"``); ``None``
    for characters every script shares (digits, punctuation, spaces, combining accents)."""
    category = unicodedata.category(char)
    if category[0] not in "LM":
        return None
    name = unicodedata.name(char, "")
    if not name or name.startswith(("COMBINING ", "MODIFIER LETTER ")):
        return None
    word = name.split(" ", 1)[0]
    return _SCRIPT_ALIASES.get(word, word)


def scripts_of(name: str) -> set[str]:
    return {s for s in map(script_of, name) if s is not None}


def _scripts_fit(scripts: set[str]) -> bool:
    return len(scripts) <= 1 or any(scripts <= allowed for allowed in _EAST_ASIAN)


def clean_name(raw: str, what: str, max_len: int) -> str:
    """``raw`` in NFKC with outer spaces removed, or :class:`NameProblem` saying what is wrong
    with it; ``what`` names the person in the message (e.g. "the student's name")."""
    name = unicodedata.normalize("NFKC", raw).strip()
    if not name:
        raise NameProblem(f"{what} is empty: type a name")
    if len(name) > max_len:
        raise NameProblem(f"{what} is longer than {max_len} characters")
    for position, char in enumerate(name, 1):
        code = ord(char)
        category = unicodedata.category(char)
        if category in _REFUSED_CATEGORIES:
            raise NameProblem(
                f"{what} has {_REFUSED_CATEGORIES[category]} (U+{code:04X} at position "
                f"{position}): type it again with plain letters"
            )
        if _invisible(code) or (category == "Zs" and char != " "):
            raise NameProblem(
                f"{what} has an invisible character (U+{code:04X} at position "
                f"{position}): type it again with plain letters"
            )
    if "  " in name:
        raise NameProblem(f"{what} has two spaces in a row: leave one")
    scripts = scripts_of(name)
    if not _scripts_fit(scripts):
        listed = ", ".join(sorted(s.title() for s in scripts))
        raise NameProblem(
            f"{what} mixes letters of different scripts ({listed}), so it could pass for "
            "another name: type it in one script"
        )
    return name


def check_student(name: str, what: str = "student") -> str:
    """A student's name, normalised: 1-40 characters, one script, nothing invisible."""
    return clean_name(name, f"the {what}'s name", MAX_STUDENT_NAME)


def check_pair(student: str, partner: str = "") -> tuple[str, str]:
    """The student and the (optional, possibly empty) partner, checked."""
    student = check_student(student)
    partner = check_student(partner, "partner") if partner.strip() else ""
    if partner and partner.casefold() == student.casefold():
        raise NameProblem("the partner is the student: leave the partner empty when alone")
    return student, partner


def name_key(name: str) -> str:
    """How names are matched: case and spacing do not count ("alice  DOE" is "Alice Doe")."""
    return " ".join(name.split()).casefold()
