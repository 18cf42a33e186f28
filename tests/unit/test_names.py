"""Students' names: what the names dialog and --student/--partner accept."""

import pytest

from workbench.labs.names import NameProblem, check_pair


def test_names_are_trimmed_and_the_partner_is_optional():
    assert check_pair("  Ana Lopez ", "") == ("Ana Lopez", "")
    assert check_pair("ana", " ben ") == ("ana", "ben")


@pytest.mark.parametrize(
    ("student", "partner", "message"),
    [
        ("", "", "the student's name is empty"),
        ("   ", "ben", "the student's name is empty"),
        ("x" * 41, "", "longer than 40 characters"),
        ("ana\x1b[31m", "", "control characters"),
        ("ana", "ANA", "the partner is the student"),
        ("ana", "b\tb", "partner's name has control characters"),
    ],
)
def test_bad_names_are_refused_with_the_reason(student, partner, message):
    with pytest.raises(NameProblem, match=message.replace("(", r"\(")):
        check_pair(student, partner)
