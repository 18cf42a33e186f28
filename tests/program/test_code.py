"""Code Activities: the sensor-JSON forms run as the built-in; any change to what they compute
is refused at load with the activity, kind 44, the class and the place it differs."""

from __future__ import annotations

import contextlib
import re
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.program.code import BUILTIN, MAX_BODY, CodeRefused, recognise, tokens
from workbench.program.compiled import compile_program
from workbench.program.interp import ProgramController
from workbench.program.keys import parse_key_script
from workbench.program.loader import load_program
from workbench.program.problems import ProgramError

WEB_MAZE = str(Path(__file__).resolve().parents[2] / "mazes" / "web.txt")

#: the helper-class form laid out as a student might type it, with comments of our own
DATA_CONTRACT = """\
using System;
using System.IO;
using System.Collections.Generic;
using System.Runtime.Serialization.Json;
using System.Text;

// reads a JSON text into an object of type T
public static class MyJsonConverter
{
    public static T Deserialize<T>(string body)
    {
        using (var stream = new MemoryStream())
        using (var writer = new StreamWriter(stream))
        {
            writer.Write(body);
            writer.Flush();
            stream.Position = 0;
            return (T)new DataContractJsonSerializer(typeof(T)).ReadObject(stream);
        }
    }

    public static string Serialize<T>(T item)
    {
        using (MemoryStream ms = new MemoryStream())
        {
            new DataContractJsonSerializer(typeof(T)).WriteObject(ms, item);
            return Encoding.Default.GetString(ms.ToArray());
        }
    }
}

/* one entry of the report */
public class Sensor
{
    public string name { get; set; }
    public string id { get; set; }
    public string value { get; set; }
}

public class SensorData
{
    public List<Sensor> sensors { get; set; }
}

[Serializable]
public class Parse : CodeUtilities.CodeBase
{
    public Parse()
    {
    }

    public override void Execute()
    {
        string raw = (string)Input;
        var report = MyJsonConverter.Deserialize<SensorData>(raw);
        Output = report.sensors[0].value;
    }
}
"""

JSON_NET = """\
using Newtonsoft.Json.Linq;
public class Reader : CodeUtilities.CodeBase {
    public override void Execute() {
        var o = JObject.Parse((string)Input);
        Output = o["sensors"][0]["value"];
    }
}
"""

RETURN_LINE = "Output = report.sensors[0].value;"

MUTATIONS = {
    "upper case": "Output = report.sensors[0].value.ToUpper();",
    "text added": 'Output = report.sensors[0].value + "x";',
    "doubled": "Output = int.Parse(report.sensors[0].value) * 2;",
    "second sensor": "Output = report.sensors[1].value;",
    "the name": "Output = report.sensors[0].name;",
    "extra statement": RETURN_LINE + " PrintLine(raw);",
}


def refusal(body: str, name: str = "Parse") -> str:
    with pytest.raises(CodeRefused) as info:
        recognise((name, body))
    return str(info.value)


def test_the_documented_forms_run_as_the_builtin():
    assert recognise(("Parse", DATA_CONTRACT)) == BUILTIN
    assert recognise(("Reader", JSON_NET)) == BUILTIN
    one_line = JSON_NET.replace(
        'var o = JObject.Parse((string)Input);\n        Output = o["sensors"][0]["value"];',
        'Output = JObject.Parse((string)Input)["sensors"][0]["value"];',
    )
    assert recognise(("Reader", one_line)) == BUILTIN


@pytest.mark.parametrize("change", sorted(MUTATIONS))
def test_a_changed_result_is_refused_naming_the_place(change):
    body = DATA_CONTRACT.replace(RETURN_LINE, MUTATIONS[change])
    message = refusal(body)
    assert message.startswith("the C# class 'Parse' is not run: it is none of the sensor-JSON")
    line = DATA_CONTRACT.splitlines().index("        " + RETURN_LINE) + 1
    assert f"at line {line}, column " in message


def test_changes_outside_the_return_are_refused_too():
    for old, new in [
        ("stream.Position = 0;", "stream.Position = 1;"),
        ("public string value { get; set; }", "public string value { get; private set; }"),
        ("string raw = (string)Input;", "string raw = ((string)Input).Trim();"),
        ("using System.Text;", "using static System.Math;"),
        ("[Serializable]", "[Obsolete]"),
    ]:
        assert old in DATA_CONTRACT
        refusal(DATA_CONTRACT.replace(old, new))
    refusal(JSON_NET.replace('["value"]', '["name"]'), "Reader")
    refusal(JSON_NET + "public class Extra { }", "Reader")
    assert "the code ends where the closest form goes on with '}'" in refusal(
        JSON_NET.rstrip().removesuffix("}"), "Reader"
    )


def test_names_of_ones_own_may_change_but_not_hide_the_forms_names():
    renamed = DATA_CONTRACT.replace("raw", "text").replace("report", "data")
    assert recognise(("Parse", renamed)) == BUILTIN
    # the constructor must carry the class's name
    assert "where the closest form has 'Parse'" in refusal(
        DATA_CONTRACT.replace("public Parse()", "public Other()")
    )
    # a variable named Output would hide the activity's output
    assert "where the closest form has a name of your own" in refusal(
        DATA_CONTRACT.replace("report", "Output")
    )
    # one name for both variables
    refusal(DATA_CONTRACT.replace("raw", "report"))


@pytest.mark.parametrize(
    "edit",
    [
        lambda s: re.sub(r"\s+", " ", re.sub("//[^\n]*", "", s)),  # all on one line
        lambda s: s.replace("\n", "\r\n"),
        lambda s: s.replace("    ", "\t"),
        lambda s: s.replace("(string)Input", "( string ) Input /* the report */"),
        lambda s: s.replace(RETURN_LINE, "// Output = 1;\n" + RETURN_LINE + " // first sensor"),
        lambda s: s.replace("[Serializable]\n", "").replace("public Parse()\n    {\n    }", ""),
        lambda s: s.replace("using System.Text;\n", ""),
        lambda s: "// a header comment\n" + s + "\n/* trailing */\n",
    ],
)
def test_whitespace_comments_and_optional_parts_do_not_matter(edit):
    assert recognise(("Parse", edit(DATA_CONTRACT))) == BUILTIN


def test_unclosed_comments_and_texts_and_huge_bodies_are_refused():
    assert "the comment at line 2, column 1 is not closed" in refusal(
        "using System;\n/* never closed"
    )
    assert "the text at line 1, column 12 is not closed" in refusal('var s = 1; "open')
    assert "more than the 65,536" in refusal(" " * (MAX_BODY + 1))


def test_tokens_drop_comments_and_keep_texts_whole():
    source = 'a /* x */ b // y\n"c // d" @"e ""f""" \'g\' => ==\n'
    assert [t.text for t in tokens(source)] == [
        "a",
        "b",
        '"c // d"',
        '@"e ""f"""',
        "'g'",
        "=>",
        "==",
    ]


@settings(
    max_examples=300, suppress_health_check=[HealthCheck.too_slow], deadline=None, database=None
)
@given(st.text(max_size=3000))
def test_any_text_gives_the_builtin_or_a_refusal(body):
    try:
        assert recognise(("X", body)) == BUILTIN
    except CodeRefused as exc:
        assert str(exc).startswith("the C# class 'X' is not run: ")


@settings(max_examples=300, deadline=None, database=None)
@given(st.data())
def test_edits_of_an_accepted_body_never_crash(data):
    body = DATA_CONTRACT
    at = data.draw(st.integers(0, len(body)))
    cut = data.draw(st.integers(0, 20))
    insert = data.draw(st.text(alphabet=" \n/*\"'@{}();.<>[]$0aZ_", max_size=20))
    edited = body[:at] + insert + body[at + cut :]
    try:
        result = recognise(("Parse", edited))
    except CodeRefused as exc:
        assert "is not run" in str(exc)
    else:
        assert result == BUILTIN


_FORM_TOKENS = [t.text for t in tokens(DATA_CONTRACT)]
_OTHER_TOKENS = sorted({*_FORM_TOKENS, "1", "+", "*", '"x"', "ToUpper", "Trim", "name", "int"})


@settings(max_examples=300, deadline=None, database=None)
@given(st.data())
def test_any_one_token_changed_added_or_removed_is_refused(data):
    """Exactly the form: a body one token away from it, whatever the token, is refused (the
    leading using lines may name any namespace, so they are left alone)."""
    body = list(_FORM_TOKENS)
    at = data.draw(st.integers(body.index("public"), len(body) - 1))
    how = data.draw(st.sampled_from(["replace", "insert", "delete"]))
    if how == "delete":
        del body[at]
    else:
        other = data.draw(st.sampled_from(_OTHER_TOKENS))
        if how == "replace":
            if other == body[at]:
                return
            body[at] = other
        else:
            body.insert(at, other)
    assert recognise(("Parse", " ".join(_FORM_TOKENS))) == BUILTIN
    with pytest.raises(CodeRefused):
        recognise(("Parse", " ".join(body)))


@pytest.mark.parametrize(
    "unit", ["/*", "*/", '"', "'", '@"', "//", "(", "a.", "using a.", "0.0", "\\", "é"]
)
def test_big_bodies_are_decided_promptly(unit):
    body = (unit * (MAX_BODY // len(unit)))[:MAX_BODY]
    started = time.process_time()
    with contextlib.suppress(CodeRefused):
        recognise(("X", body))
    # reading is linear: a 64 KiB body takes milliseconds; a slip into quadratic work would
    # take minutes
    assert time.process_time() - started < 5


# -- in a program ------------------------------------------------------------------------------
def code_program(tmp_path, body: str, name: str = "Parse") -> tuple[str, int]:
    b = ProgramBuilder()
    main_panel = b.panel("Main")
    b.robot(main_panel)
    raw = main_panel.add(52, "Robot/IoT Controller 0", "-1")
    code = main_panel.add(44, name, body, "System.dll")
    show = main_panel.add(28, "")
    main_panel.chain(raw, code, show)
    return b.write(tmp_path / "code.viple"), code


def test_the_builtin_prints_the_first_sensor_s_value(tmp_path):
    path, _ = code_program(tmp_path, DATA_CONTRACT)
    c = ProgramController(compile_program(load_program(path)), parse_key_script(""))
    c.start(0.0)
    c.tick(0.05, {"port 4": 164.97}, frozenset())
    assert [p.text for p in c.printed] == ["164.97"]


def test_check_refuses_the_doubled_copy_with_the_activity_kind_and_class(tmp_path, capsys):
    body = DATA_CONTRACT.replace(RETURN_LINE, MUTATIONS["doubled"])
    path, code = code_program(tmp_path, body)
    assert main(["viple", "check", path]) == 1
    out = capsys.readouterr().out
    assert "ok (" not in out
    assert f"activity {code} (kind 44, Code Activity): the C# class 'Parse' is not run" in out
    assert "'int' where the closest form has 'report'" in out
    with pytest.raises(ProgramError):
        compile_program(load_program(path))
    # a run refuses it the same way, before anything moves
    assert main(["viple", "run", path, "--maze", WEB_MAZE, "--json"]) == 2
    assert "(kind 44, Code Activity)" in capsys.readouterr().err


def test_check_passes_the_documented_form(tmp_path, capsys):
    path, _ = code_program(tmp_path, DATA_CONTRACT)
    assert main(["viple", "check", path]) == 0
    assert ": ok (VIPLE 4.0.0.1" in capsys.readouterr().out
