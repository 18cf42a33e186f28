"""Students' names as the labs keep them: who does the labs and with whom."""

from __future__ import annotations

MAX_STUDENT_NAME = 40


class NameProblem(ValueError):
    """A student's or partner's name cannot be used; the message says why."""


def check_student(name: str, what: str = "student") -> str:
    """A name with outer spaces removed: 1-40 printable characters."""
    name = name.strip()
    if not name:
        raise NameProblem(f"the {what}'s name is empty: type a name")
    if len(name) > MAX_STUDENT_NAME:
        raise NameProblem(f"the {what}'s name is longer than {MAX_STUDENT_NAME} characters")
    if not name.isprintable():
        raise NameProblem(f"the {what}'s name has control characters")
    return name


def check_pair(student: str, partner: str = "") -> tuple[str, str]:
    """The student and the (optional, possibly empty) partner, checked."""
    student = check_student(student)
    partner = check_student(partner, "partner") if partner.strip() else ""
    if partner and partner.casefold() == student.casefold():
        raise NameProblem("the partner is the student: leave the partner empty when alone")
    return student, partner
