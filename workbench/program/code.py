"""Code Activities (kind 44): user C# the workbench never compiles or runs.

One job is common in course programs: a Code Activity takes the raw sensor JSON a Robot Sensor
(kind 52) delivers, ``{"sensors":[{"name":..,"id":..,"value":..}]}``, and returns
``sensors[0].value``. The workbench runs that job as a built-in, but only for a body that is,
token for token, one of the forms in :data:`FORMS` (the same forms are listed in
docs/viple-programs.md): whitespace and comments may differ, and the names marked ``$`` in a
form (the class, its local variables) may be any names. Anything else, however close, is
refused with the first place it differs, since running it as the built-in would give a value
the student's code does not compute.

The check reads the body once into tokens and compares it with each form: time and memory
grow with the body's length, which is bounded by :data:`MAX_BODY`.
"""

from __future__ import annotations

import itertools
import json
import re
from dataclasses import dataclass

from .viple_expr import Value

MAX_JSON = 64 * 1024
#: the longest body read: the forms are about 1.5 KB, so this leaves room for comments
MAX_BODY = 64 * 1024
BUILTIN = "first-sensor-value"


class CodeRefused(ValueError):
    """A Code Activity whose body the workbench does not run."""


def class_name(values: tuple[str, ...]) -> str:
    return values[0].strip() if values and values[0].strip() else "(unnamed)"


# -- the accepted forms ------------------------------------------------------------------------
@dataclass(frozen=True)
class Optional:
    """Code a form may have or leave out."""

    text: str


@dataclass(frozen=True)
class Either:
    """Code a form has in one of these ways."""

    texts: tuple[str, ...]


Piece = str | Optional | Either

_CLASS_HEAD: tuple[Piece, ...] = (
    Optional("[Serializable]"),
    "public class $class : CodeUtilities.CodeBase {",
    Optional("public $class() { }"),
    "public override void Execute() {",
)

#: name -> the form's pieces. Each form may start with any ``using Name.Space;`` lines.
FORMS: dict[str, tuple[Piece, ...]] = {
    # helper classes that read the JSON with .NET's DataContractJsonSerializer
    "data-contract": (
        "public static class MyJsonConverter {"
        "  public static T Deserialize<T>(string body) {"
        "    using (var stream = new MemoryStream())"
        "    using (var writer = new StreamWriter(stream)) {"
        "      writer.Write(body);"
        "      writer.Flush();"
        "      stream.Position = 0;"
        "      return (T)new DataContractJsonSerializer(typeof(T)).ReadObject(stream);"
        "    }"
        "  }",
        Optional(
            "public static string Serialize<T>(T item) {"
            "  using (MemoryStream ms = new MemoryStream()) {"
            "    new DataContractJsonSerializer(typeof(T)).WriteObject(ms, item);"
            "    return Encoding.Default.GetString(ms.ToArray());"
            "  }"
            "}"
        ),
        "}"
        "public class Sensor {"
        "  public string name { get; set; }"
        "  public string id { get; set; }"
        "  public string value { get; set; }"
        "}"
        "public class SensorData {"
        "  public List<Sensor> sensors { get; set; }"
        "}",
        *_CLASS_HEAD,
        "string $text = (string)Input;"
        "var $data = MyJsonConverter.Deserialize<SensorData>($text);"
        "Output = $data.sensors[0].value;"
        "} }",
    ),
    # Json.NET's JObject
    "json-net": (
        *_CLASS_HEAD,
        Either(
            (
                'var $json = JObject.Parse((string)Input); Output = $json["sensors"][0]["value"];',
                'Output = JObject.Parse((string)Input)["sensors"][0]["value"];',
            )
        ),
        "} }",
    ),
}


# -- reading C# into tokens --------------------------------------------------------------------
@dataclass(frozen=True)
class Token:
    text: str
    #: where it starts in the body
    offset: int


_SPACE = re.compile(r"\s+")
_WORD = re.compile(r"[^\W\d]\w*")
_SLOT = re.compile(r"\$[^\W\d]\w*")
_NUMBER = re.compile(r"\d+(?:\.\d+)?(?:[eE][+-]?\d+)?[A-Za-z]*")
_STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"|@"(?:[^"]|"")*"|\'(?:[^\'\\\n]|\\.)*\'')
_OPERATOR = re.compile(r"=>|==|!=|<=|>=|&&|\|\||\+\+|--|[-+*/%&|^]=|<<=?|\?\?=?|::|->")


def _where(source: str, offset: int) -> str:
    line = source.count("\n", 0, offset) + 1
    column = offset - (source.rfind("\n", 0, offset) + 1) + 1
    return f"line {line}, column {column}"


def tokens(source: str, slots: bool = False) -> list[Token]:
    """The C# tokens of ``source`` (comments and whitespace dropped); CodeRefused for a comment
    or string that is not closed. With ``slots``, ``$name`` is one token (in the forms)."""
    out: list[Token] = []
    pos, end = 0, len(source)
    while pos < end:
        space = _SPACE.match(source, pos)
        if space:
            pos = space.end()
            continue
        if source.startswith("//", pos):
            newline = source.find("\n", pos)
            pos = end if newline < 0 else newline + 1
            continue
        if source.startswith("/*", pos):
            close = source.find("*/", pos + 2)
            if close < 0:
                raise CodeRefused(f"the comment at {_where(source, pos)} is not closed")
            pos = close + 2
            continue
        found = (
            (slots and _SLOT.match(source, pos))
            or _WORD.match(source, pos)
            or _NUMBER.match(source, pos)
            or _STRING.match(source, pos)
            or _OPERATOR.match(source, pos)
        )
        if found:
            text = found.group()
        elif source[pos] in "\"'" or source.startswith('@"', pos):
            raise CodeRefused(f"the text at {_where(source, pos)} is not closed")
        else:
            text = source[pos]
        out.append(Token(text, pos))
        pos += len(text)
    return out


def _variants(pieces: tuple[Piece, ...]) -> list[tuple[str, ...]]:
    """Every token sequence a form allows."""
    choices: list[tuple[str, ...]] = []
    for piece in pieces:
        if isinstance(piece, str):
            choices.append((piece,))
        elif isinstance(piece, Optional):
            choices.append((piece.text, ""))
        else:
            choices.append(piece.texts)
    return [
        tuple(t.text for text in combo for t in tokens(text, slots=True))
        for combo in itertools.product(*choices)
    ]


_VARIANTS: list[tuple[str, ...]] = [v for form in FORMS.values() for v in _variants(form)]
_CSHARP_KEYWORDS = (
    "abstract as base bool break byte case catch char checked class const continue decimal "
    "default delegate do double dynamic else enum event explicit extern false finally fixed "
    "float for foreach goto if implicit in int interface internal is lock long namespace new "
    "null object operator out override params private protected public readonly ref return "
    "sbyte sealed short sizeof stackalloc static string struct switch this throw true try "
    "typeof uint ulong unchecked unsafe ushort using var virtual void volatile while"
)
_FORM_NAMES = ("Input", "Output", "CodeUtilities", "MyJsonConverter", "Sensor", "SensorData")
#: names a ``$`` name may not take: C# keywords, and the names the forms' code reads, which a
#: class or variable of the same name would hide
_TAKEN = frozenset(_CSHARP_KEYWORDS.split()).union(_FORM_NAMES, ("JObject", "List"))


# -- matching ------------------------------------------------------------------------------------
def _skip_usings(body: list[Token]) -> int:
    """The index after the leading ``using Name.Space;`` directives."""
    i = 0
    while i < len(body) and body[i].text == "using":
        j = i + 1
        while j + 1 < len(body) and _WORD.fullmatch(body[j].text) and body[j + 1].text == ".":
            j += 2
        if j + 1 < len(body) and _WORD.fullmatch(body[j].text) and body[j + 1].text == ";":
            i = j + 2
        else:
            break
    return i


def _compare(body: list[Token], start: int, form: tuple[str, ...]) -> tuple[int, str]:
    """How many of the form's tokens ``body[start:]`` matches, and what the next one should be
    ("" when the whole body matched)."""
    names: dict[str, str] = {}
    for n, want in enumerate(form):
        i = start + n
        if i >= len(body):
            return n, want
        got = body[i].text
        if want.startswith("$"):
            bound = names.get(want)
            if bound is None:
                fits = (
                    _WORD.fullmatch(got) is not None
                    and got not in _TAKEN
                    and got not in names.values()
                )
                if not fits:
                    return n, "a name of your own"
                names[want] = got
            elif got != bound:
                return n, bound
        elif got != want:
            return n, want
    if start + len(form) < len(body):
        return len(form), "the end of the code"
    return len(form), ""


def recognise(values: tuple[str, ...]) -> str:
    """The built-in a Code Activity's body is a form of (:data:`BUILTIN`), else CodeRefused
    saying where the body leaves the forms."""
    name = class_name(values)[:40]
    source = values[1] if len(values) > 1 else ""
    head = f"the C# class {name!r} is not run"
    if len(source) > MAX_BODY:
        raise CodeRefused(
            f"{head}: its code is {len(source):,} characters, more than the "
            f"{MAX_BODY:,} the sensor-JSON forms the workbench runs may take"
        )
    try:
        body = tokens(source)
    except CodeRefused as exc:
        raise CodeRefused(f"{head}: {exc}") from None
    start = _skip_usings(body)
    matched, wanted = max((_compare(body, start, v) for v in _VARIANTS), key=lambda m: m[0])
    if not wanted:
        return BUILTIN
    expected = wanted if wanted.startswith(("a name", "the end")) else repr(wanted)
    at = start + matched
    if at >= len(body):
        place = f"the code ends where the closest form goes on with {expected}"
    else:
        found = body[at].text
        shown = found if len(found) <= 30 else found[:27] + "..."
        where = _where(source, body[at].offset)
        place = f"at {where} it has {shown!r} where the closest form has {expected}"
    raise CodeRefused(
        f"{head}: it is none of the sensor-JSON forms the workbench runs as a built-in "
        f"(it never compiles C#): {place}"
    )


def first_sensor_value(message: Value) -> Value:
    """``sensors[0].value`` of a raw sensor report (a JSON text)."""
    if not isinstance(message, str):
        raise ValueError("the Code Activity expects the sensor JSON text as its input")
    if len(message) > MAX_JSON:
        raise ValueError("the sensor JSON is too long")
    try:
        data = json.loads(message)
        value = data["sensors"][0]["value"]
    except (ValueError, KeyError, IndexError, TypeError):
        raise ValueError("the input is not sensor JSON with a first sensor value") from None
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError("the first sensor's value is not a number or text")
    return value
