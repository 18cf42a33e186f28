"""The labs screen's keys: the exercise list has them, an answer only when the student moves to
it, a multiple-choice answer is picked (keys or mouse), and keys typed together act in order."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, OptionList, Static

from tests.waiting import until
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.widgets.choices import Choice, Choices

from .labs_support import lab_app, open_exercise, text
from .support import burst, run

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
RULES = "maze-algorithms/erobotic-rules"
QUESTION = "why-no-states"


def rules_question():
    lab = next(lab for lab in load_labs() if lab.id == "maze-algorithms")
    return next(q for q in lab.exercise("erobotic-rules").questions if q.id == QUESTION)


def right_choice() -> int:
    """The index of the right answer among the question's choices."""
    question = rules_question()
    return next(i for i, c in enumerate(question.choices) if question.check(c)[0])


def reason_of(screen: LabsScreen, question: str) -> str:
    box = screen.query_one(f"#q-{question}").parent
    assert box is not None
    return str(box.query_one(".question-reason", Static).render())


def test_reopening_the_labs_focuses_the_list_and_its_keys_leave_the_answers_alone(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        listing = screen.query_one("#labs-list", OptionList)
        assert screen.focused is listing
        field = screen.query_one("#q-tcp-port", Input)
        field.focus()
        await pilot.press("1", "3", "5", "0", "enter")  # typed and tried
        assert field.value == "1350"
        await pilot.press("escape")  # back to the maze from the answer field
        await pilot.press("l")
        await pilot.pause()
        assert app.screen is screen and screen.focused is listing
        await pilot.press("a")  # the set-up, not an "a" in the answer
        await pilot.pause()
        assert "set up: unity" in text(screen, "#labs-message")
        await pilot.press("i")
        await pilot.pause()
        assert isinstance(app.screen, SignoffModal)
        await pilot.press("escape")
        await pilot.pause()
        assert app.screen is screen and screen.focused is listing
        await pilot.press("i", "escape", "a")
        await pilot.pause()
        assert field.value == "1350"
        assert reason_of(screen, "tcp-port") == "[X] correct (1 try)"
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["answers"] == {"tcp-port": "1350"}

    run(app, body)


def test_an_answer_field_keeps_its_text_when_it_takes_the_focus(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        field = screen.query_one("#q-tcp-port", Input)
        field.value = "135"
        await pilot.press("tab")  # from the list on, the way a student moves to it
        while screen.focused is not field:
            await pilot.press("tab")
        await pilot.press("0")
        assert field.value == "1350"  # added to, not replaced

    run(app, body)


def test_each_exercise_opens_at_the_top_with_its_objectives_in_view(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        scroll = screen.query_one("#labs-scroll")
        scroll.scroll_end(animate=False)
        await pilot.pause()
        assert scroll.scroll_y > 0
        listing = screen.query_one("#labs-list", OptionList)
        listing.highlighted = listing.get_option_index("maze-algorithms/which-is-best")
        await pilot.pause()
        assert scroll.scroll_y == 0
        # the new exercise's text is laid out once it has been read (on a busy machine, some
        # frames later): then its objectives are in view at the top
        objectives = screen.query_one("#labs-objectives")
        await until(
            lambda: objectives.region.y >= scroll.region.y and objectives.region.height > 0,
            "the objectives in view",
        )
        assert scroll.scroll_y == 0

    run(app, body)


def test_every_choice_is_shown_whole_at_80x24(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        choices = screen.query_one(f"#q-{QUESTION}", Choices)
        choices.scroll_visible(animate=False)
        await pilot.pause()
        shown = " ".join(" ".join(str(choice.render()).split()) for choice in choices.query(Choice))
        for choice in rules_question().choices:
            assert choice in shown
        for choice in choices.query(Choice):
            assert choice.region.right <= 80 and choice.size.height >= 1

    run(app, body)


def test_a_choice_is_picked_with_the_keys_and_saved_as_its_text(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        assert reason_of(screen, QUESTION) == "not answered yet"
        choices = screen.query_one(f"#q-{QUESTION}", Choices)
        choices.focus()
        await pilot.pause()
        await pilot.press(*["down"] * right_choice(), "enter")
        await pilot.pause()
        right = rules_question().choices[right_choice()]
        assert choices.answer == right
        assert reason_of(screen, QUESTION) == "[X] correct (1 try)"
        saved = app.store.progress.of("ana")[("maze-algorithms", "erobotic-rules")]
        assert saved["answers"][QUESTION] == right
        wrong = (right_choice() + 1) % len(rules_question().choices)
        await pilot.press(*["up"] * right_choice(), *["down"] * wrong, "space")
        await pilot.pause()
        assert choices.answer == rules_question().choices[wrong]
        assert reason_of(screen, QUESTION) == "[ ] not the expected answer (2 tries)"

    run(app, body)


def test_a_choice_is_picked_with_the_mouse(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        choices = screen.query_one(f"#q-{QUESTION}", Choices)
        choices.scroll_visible(animate=False)
        await pilot.pause()
        target = list(choices.query(Choice))[right_choice()]
        await pilot.click(target)
        await pilot.pause()
        assert choices.answer == rules_question().choices[right_choice()]
        assert reason_of(screen, QUESTION) == "[X] correct (1 try)"

    run(app, body)


def test_a_saved_answer_comes_back_picked(tmp_path):
    data = tmp_path / "data"
    right = rules_question().choices[right_choice()]
    with Store.open(data) as store:
        store.progress.save(
            "ana",
            "maze-algorithms",
            "erobotic-rules",
            {"lab": "maze-algorithms", "exercise": "erobotic-rules", "objectives": [],
             "answers": {QUESTION: right.upper()}, "passed": False},
        )  # fmt: skip
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        choices = screen.query_one(f"#q-{QUESTION}", Choices)
        picked = [c.value for c in choices.query(Choice)]
        assert picked == [i == right_choice() for i in range(len(picked))]
        assert reason_of(screen, QUESTION) == "[X] correct"

    run(app, body)


def test_keys_typed_together_on_the_labs_screen_act_in_order(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, RULES)
        choices = screen.query_one(f"#q-{QUESTION}", Choices)
        choices.focus()
        await pilot.pause()
        # the pick lands in the set it was typed at, though shift+tab moved on before it acted
        await burst(pilot, *[("down", None)] * right_choice(), ("enter", "\r"), ("shift+tab", None))
        assert choices.answer == rules_question().choices[right_choice()]
        assert screen.focused is not choices
        screen.query_one("#labs-list", OptionList).focus()
        await pilot.pause()
        # down to the next exercise, then i: its sign-off opens
        await burst(pilot, ("down", None), ("i", "i"))
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        assert (modal.progress.lab, modal.progress.exercise) == (
            "maze-algorithms",
            "which-is-best",
        )

    run(app, body)
