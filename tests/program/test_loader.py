"""Loading VIPLE program files: containers, hardened XML, links rebuilt and checked."""

from __future__ import annotations

import gzip
import re

import pytest

from tests.program.builder import ProgramBuilder
from workbench.program.kinds import load_kind_map
from workbench.program.loader import load_program
from workbench.program.model import ELSE
from workbench.program.problems import ProgramError


def small_program() -> ProgramBuilder:
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    key = main.add(13, "22")
    data = main.add(3, '"go"')
    var = main.add(1, "mode")
    cond = main.add(6, 'state.mode == "go"', "value > 3")
    show = main.add(28, "")
    other = main.add(28, "")
    b.var("mode", "System.String")
    main.chain(key, data, var, cond, show)
    b.link(cond, other, pin=ELSE)
    b.link(var, other)
    return b


def problems(path) -> list[str]:
    with pytest.raises(ProgramError) as info:
        load_program(path)
    return [str(p) for p in info.value.problems]


@pytest.mark.parametrize(
    "options",
    [
        {"bom": True, "crlf": True},
        {"bom": False, "crlf": False},
        {"bom": True, "crlf": False, "compress": True},
        {"bom": False, "crlf": True, "compress": True},
    ],
)
def test_every_container_gives_the_same_program(tmp_path, options):
    path = small_program().write(tmp_path / "p.viple", **options)
    program = load_program(path)
    assert program.version == "4.0.0.1"
    kinds = sorted(a.kind for a in program.activities.values())
    assert kinds == [1, 3, 6, 13, 19, 28, 28]
    cond = next(a for a in program.activities.values() if a.kind == 6)
    assert cond.values == ('state.mode == "go"', "value > 3")
    # fan-out in file order, and the If's Else pin
    var = next(a for a in program.activities.values() if a.kind == 1)
    assert next(lk.target for lk in program.targets(var.id)) == cond.id
    assert len(program.targets(var.id)) == 2
    assert len(program.targets(cond.id, ELSE)) == 1


def test_version_3_values_without_index_and_digest_of_the_bytes(tmp_path):
    b = ProgramBuilder(version="3.1.0")
    main = b.panel("Main")
    calc = main.add(2, '"Front: " + value')
    main.add(11, "a comment\nover two lines")
    path = b.write(tmp_path / "old.xml", compress=True)
    program = load_program(path)
    assert program.activities[calc].values == ('"Front: " + value',)
    assert len(program.digest) == 64
    assert load_program(path).digest == program.digest


def test_parallel_lists_of_different_length_name_the_activity(tmp_path):
    text = small_program().xml()
    text = text.replace(
        "<OutgoingLines><GraphEdgeID>1</GraphEdgeID></OutgoingLines>", "<OutgoingLines />"
    )
    path = tmp_path / "cut.viple"
    path.write_text(text)
    found = problems(path)
    assert any(
        p.startswith(
            f"{path}: panel Main: activity 2 (kind 13, Key Press Event): NextActivities lists 1"
        )
        and "the two lists must be the same length" in p
        for p in found
    ), found


def test_a_link_seen_from_one_side_only(tmp_path):
    text = (
        small_program()
        .xml()
        .replace(
            "<PreviousActivities><ActivityID>2</ActivityID></PreviousActivities>",
            "<PreviousActivities />",
        )
        .replace("<IncomingLines><GraphEdgeID>1</GraphEdgeID></IncomingLines>", "<IncomingLines />")
    )
    path = tmp_path / "half.viple"
    path.write_text(text)
    found = problems(path)
    assert any("link 1 leaves 1 time(s) and arrives 0 time(s)" in p for p in found), found


def test_links_never_cross_panels(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    block = b.panel("Go")
    data = main.add(3, "1")
    b.link(data, block.pin_out)
    main.add(0, name="Go")
    found = problems(b.write(tmp_path / "x.viple"))
    assert any("in panel Go; links stay inside one panel" in p for p in found), found


def test_unknown_kinds_by_number_and_id_then_named_by_a_mapping_file(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    move = main.add(47, "0.5", "Robot/IoT Controller 0")
    path = b.write(tmp_path / "plus.viple")
    found = problems(path)
    assert found == [
        f"{path}: panel Main: activity {move} (kind 47, unknown): kind 47 is not known to the "
        "workbench (if you know which VIPLE service it is, name it in a kinds mapping file "
        "(--kinds FILE, see docs/viple-programs.md))"
    ]
    mapping = tmp_path / "kinds.yaml"
    mapping.write_text("kinds:\n  47: {activity: move-at-power, value: 0}\n")
    program = load_program(path, load_kind_map(mapping))
    assert program.label(program.activities[move]) == "Robot+ Move at Power"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("kinds: {47: fly}", "activity 'fly' is not one the workbench runs"),
        ("kinds: {6: ignore}", "kind 6 is already known (If)"),
        ("kinds: {47: {activity: ignore, value: -1}}", "value must be a Value index"),
        ("kind: {}", "the file must hold one mapping 'kinds'"),
    ],
)
def test_bad_mapping_files(tmp_path, text, message):
    from workbench.files.bounded import BoundedFileError

    path = tmp_path / "kinds.yaml"
    path.write_text(text)
    with pytest.raises(BoundedFileError, match=re.escape(message)):
        load_kind_map(path)


def test_while_pairs_with_its_end_while_and_break(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(3, "0")
    loop = main.add(8, "value < 3")
    inner = main.add(8, "false")
    inner_end = main.add(10, "")
    cond = main.add(6, "value == 2")
    brk = main.add(9, "")
    calc = main.add(2, "value + 1")
    end = main.add(10, "")
    main.chain(start, loop, inner, inner_end, cond, calc, end)
    b.link(cond, brk, pin=ELSE)
    program = load_program(b.write(tmp_path / "w.viple"))
    assert program.loop_end == {loop: end, inner: inner_end}
    assert program.break_loop == {brk: loop}


def test_loop_problems_all_at_once(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    loop = main.add(8, "true")
    calc = main.add(2, "1")
    main.chain(loop, calc)
    stray = main.add(10, "")
    brk = main.add(9, "")
    path = b.write(tmp_path / "w.viple")
    found = problems(path)
    assert (
        f"{path}: panel Main: activity {loop} (kind 8, While): no End While is reached" in found[0]
    )
    assert any(f"activity {stray} (kind 10, End While): no While leads" in p for p in found)
    assert any(f"activity {brk} (kind 9, Break): the Break is not inside" in p for p in found)


def test_blocks_bind_to_panels_and_parameters(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.panel("Straight", inputs=(("time", "System.Int32"),))
    good = main.add(0, "time", "value", name="Straight")
    bad = main.add(0, "speed", "1", name="Straight")
    gone = main.add(0, name="Vanished")
    path = b.write(tmp_path / "b.viple")
    found = problems(path)
    assert not any(f"activity {good} " in p for p in found)
    assert any(
        f"activity {bad} (kind 0, Activity Block Straight): it sets the parameter 'speed'" in p
        and "its parameters are: time" in p
        for p in found
    ), found
    assert any(f"activity {gone} (kind 0, Activity Block Vanished)" in p for p in found)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (
            b'<?xml version="1.0"?><!DOCTYPE p [<!ENTITY a "aaaa">]><Program>&a;</Program>',
            "declares a document type or entities",
        ),
        (b"<Program>" + b"<a>" * 40 + b"</a>" * 40 + b"</Program>", "nested more than 12 deep"),
        (b"<Program><Version>4.0</Version>", "line 1, column 32: the XML is not well formed"),
        (b"\x1f\x8b\x08\x00garbage", "the gzip data is cut short"),
        (b"<Program>\x00</Program>", "control character"),
        (b"<Root/>", "the document is a <Root>, not a VIPLE <Program>"),
    ],
)
def test_hostile_and_damaged_files_are_refused_with_a_reason(tmp_path, data, message):
    path = tmp_path / "bad.viple"
    path.write_bytes(data)
    found = problems(path)
    assert len(found) == 1 and message in found[0], found
    assert found[0].startswith(f"{path}: ")


def test_a_gzip_bomb_stops_at_the_size_limit(tmp_path):
    path = tmp_path / "bomb.xml"
    path.write_bytes(gzip.compress(b"<Program>" + b" " * (5 << 20) + b"</Program>"))
    found = problems(path)
    assert "decompresses to more than" in found[0]


def test_a_missing_file_is_a_problem_not_a_crash(tmp_path):
    found = problems(tmp_path / "nowhere.viple")
    assert "cannot read the file" in found[0]
