"""Bounded reads: every limit is checked before parsing, with a position and no content."""

from __future__ import annotations

import os

import pytest

from workbench.files.bounded import (
    MAX_PROBLEMS,
    BoundedFileError,
    Limits,
    capped,
    check_text,
    compose_yaml,
    decode_text,
    load_yaml,
    more_problems,
    read_bytes,
    read_text,
)

SMALL = Limits(
    "a test file",
    max_bytes=1000,
    max_lines=10,
    max_line_length=20,
    max_depth=4,
    max_aliases=3,
    max_nodes=30,
)
SECRET = "hunter2-secret"


def refused(data: bytes | str, limits: Limits = SMALL) -> BoundedFileError:
    with pytest.raises(BoundedFileError) as info:
        if isinstance(data, bytes):
            decode_text(data, "f.txt", limits)
        else:
            check_text(data, "f.txt", limits)
    return info.value


def yaml_refused(text: str, limits: Limits = SMALL, first_line: int = 1) -> BoundedFileError:
    with pytest.raises(BoundedFileError) as info:
        compose_yaml(text, "f.yaml", limits, first_line)
    return info.value


# -- plain text ----------------------------------------------------------------------------


def test_text_within_the_limits_is_returned_unchanged():
    text = "a\tb\r\nc\n"
    assert decode_text(text.encode(), "f.txt", SMALL) == text


def test_a_leading_bom_is_dropped_and_one_later_is_kept():
    assert decode_text(b"\xef\xbb\xbfabc", "f.txt", SMALL) == "abc"
    assert check_text("\ufeffabc", "f.txt", SMALL) == "abc"
    assert check_text("a\ufeffb", "f.txt", SMALL) == "a\ufeffb"


def test_size_is_checked_first_without_reading_a_larger_file(tmp_path):
    path = tmp_path / "big.txt"
    path.write_bytes(b"x\n" * 2000)
    with pytest.raises(BoundedFileError) as info:
        read_bytes(path, SMALL)
    err = info.value
    assert err.message == "the file is 4,000 bytes; a test file is at most 1,000"
    assert err.line is None and str(err).startswith(f"{path}: the file is 4,000 bytes")


def test_too_many_lines_names_the_first_line_over_the_limit():
    err = refused("a\n" * 11 + "b")
    assert (err.line, err.message) == (11, "the file has 12 lines; a test file has at most 10")
    assert check_text("a\n" * 10, "f.txt", SMALL) == "a\n" * 10  # a final line break is no line


def test_a_long_line_is_refused_at_the_column_past_the_limit():
    err = refused("short\n" + SECRET * 5 + "\nshort")
    assert (err.line, err.column) == (2, 21)
    assert err.message == "the line is 70 characters long; a test file has lines of at most 20"
    assert SECRET not in str(err)


@pytest.mark.parametrize(
    ("data", "line", "column", "code"),
    [
        (b"ab\x00c", 1, 3, "U+0000"),
        (b"ok\r\nx\x07", 2, 2, "U+0007"),
        (b"ok\n\x1b[31m", 2, 1, "U+001B"),
        (b"a\x7f", 1, 2, "U+007F"),
        ("a\u0085b".encode(), 1, 2, "U+0085"),
        ("ab\u2028".encode(), 1, 3, "U+2028"),
        (b"a\x0cb", 1, 2, "U+000C"),
    ],
)
def test_control_characters_are_named_by_code_point_and_position(data, line, column, code):
    err = refused(data)
    assert (err.line, err.column) == (line, column)
    assert err.message == f"character {code} is a control character"


def test_bytes_that_are_not_utf8_are_named_with_their_position():
    err = refused("héllo\nwo".encode() + b"\xffrld")
    assert (err.line, err.column) == (2, 3)
    assert err.message == "byte 0xFF is not UTF-8 text"
    assert "UTF-8" in err.hint


def test_no_message_quotes_the_file():
    for data in (
        SECRET.encode() + b"\x00",
        SECRET.encode() + b"\xfe",
        (SECRET * 3).encode(),
        (SECRET + "\n") * 20,
    ):
        assert SECRET not in str(refused(data))


def test_read_text_and_a_missing_file(tmp_path):
    path = tmp_path / "ok.txt"
    path.write_bytes(b"\xef\xbb\xbfhello\n")
    assert read_text(path, SMALL) == "hello\n"
    with pytest.raises(BoundedFileError, match=r"missing\.txt: cannot read the file: No such"):
        read_text(tmp_path / "missing.txt", SMALL)
    with pytest.raises(BoundedFileError, match="cannot read the file: it is a folder"):
        read_text(tmp_path, SMALL)


def test_a_named_pipe_is_refused_at_once_instead_of_waiting_for_a_writer(tmp_path):
    pipe = tmp_path / "maze.txt"
    os.mkfifo(pipe)
    with pytest.raises(
        BoundedFileError, match=r"maze\.txt: cannot read the file: it is a named pipe"
    ):
        read_text(pipe, SMALL)


# -- YAML ----------------------------------------------------------------------------------


def test_yaml_within_the_limits_loads():
    assert load_yaml("a: [1, {b: 2.5}]\nc: &x hi\nd: *x\n", "f.yaml", SMALL) == {
        "a": [1, {"b": 2.5}],
        "c": "hi",
        "d": "hi",
    }
    assert compose_yaml("", "f.yaml", SMALL) is None


@pytest.mark.parametrize(
    "text", ["[" * 10_000, "a:\n" + "".join(" " * i + "a:\n" for i in range(1, 40))]
)
def test_deep_nesting_is_refused_at_the_level_past_the_limit(text):
    limits = Limits("a test file", max_line_length=20_000)
    err = yaml_refused(text, limits)
    assert err.message == "lists and mappings nested more than 32 deep"
    assert err.line is not None and err.line <= 33


def test_nesting_line_numbers_count_from_first_line():
    err = yaml_refused("x: 1\ny: [[[[[1]]]]]\n", first_line=5)
    assert (err.line, err.column) == (6, 7)


def test_aliases_are_limited_in_number():
    err = yaml_refused("a: &a 1\nb: [*a, *a, *a, *a]\n")
    assert err.message.startswith("more than 3 aliases (*name)")
    assert (err.line, err.column) == (2, 17)


def test_an_alias_counts_as_a_copy_so_a_billion_laughs_is_refused():
    lol = "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a]\n"
    err = yaml_refused(lol)
    assert err.message.startswith("more than 30 values (an alias counts as a copy")
    assert err.line == 2
    big = Limits("a lab file")
    bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, 9)
    )
    assert "values" in yaml_refused(bomb, big).message


def test_an_alias_inside_its_own_anchor_is_refused():
    err = yaml_refused("a: &a [1, *a]\n")
    assert "inside the value its anchor" in err.message and err.line == 1


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (".nan", "a number that is not finite (NaN or infinity)"),
        ("-.inf", "a number that is not finite (NaN or infinity)"),
        ("1.0e+999", "a number that is not finite (NaN or infinity)"),
        ("1" * 40, "a number with 40 digits; numbers have at most 30"),
        ("1.5" + "0" * 40, "a number with 42 digits; numbers have at most 30"),
    ],
)
def test_numbers_must_be_finite_and_short(value, message):
    limits = Limits("a test file")
    err = yaml_refused(f"a: 1\nb: {value}\n", limits)
    assert (err.line, err.column, err.message) == (2, 4, message)


def test_quoted_numbers_are_text_and_pass():
    assert load_yaml("a: '.nan'\nb: '" + "1" * 40 + "'\n", "f.yaml", SMALL)["a"] == ".nan"


def test_a_control_character_reaching_yaml_is_refused_with_its_position():
    err = yaml_refused("a: 1\nb: x\x00\n")
    assert (err.line, err.column, err.message) == (
        2,
        5,
        "character U+0000 cannot appear in YAML",
    )


def test_yaml_syntax_errors_stay_yaml_errors():
    import yaml

    with pytest.raises(yaml.YAMLError):
        compose_yaml("a: [1\n", "f.yaml", SMALL)


# -- lists of problems -----------------------------------------------------------------------


def test_a_long_list_of_problems_is_cut_with_a_count():
    items = [str(i) for i in range(100)]
    out = capped(items, more_problems)
    assert len(out) == MAX_PROBLEMS + 1
    assert out[-1] == "and 80 more problems"
    assert capped(items[:20], more_problems) == items[:20]
    assert more_problems(1) == "and 1 more problem"
