"""Who a request for sign-off may name as partner.

A student's app names the partner as the student typed it; nothing there shows that the
person named worked on the exercise, or agrees. So the partner of a sign-off is a student of
the class (one the course's store knows: they have opened a lab) other than the student, and
the instructor confirms the pair when signing (the console asks); without that the
sign-off is for the student alone. The gradebook, in turn, never lets a record that only
names someone replace a row of their own (:func:`workbench.labs.signoff.gradebook.gradebook_rows`).
"""

from __future__ import annotations

from collections.abc import Collection


class PairNotConfirmed(ValueError):
    """A sign-off of a request that names a partner, before the instructor said whether the
    partner worked on it and agrees."""


def partner_problem(student: str, partner: str, class_list: Collection[str]) -> str:
    """Why ``partner`` cannot be ``student``'s partner on a sign-off, or ``""`` when they can
    (or no partner is named); ``class_list`` is the students the store knows."""
    if not partner:
        return ""
    if partner.casefold() == student.casefold():
        return f"{student} names themself as their partner"
    if partner not in class_list:
        return (
            f"{partner} is not a student of this class (nobody of that name has opened a lab "
            "here): sign for the student alone, or ask the partner to log in first"
        )
    return ""
