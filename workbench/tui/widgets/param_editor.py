"""One tunable parameter of an algorithm: its value (checked as it is typed), its range and
default, and what it means.

A starter FSM of the labs leaves some parameters for the students: their description starts
with ``FILL IN:``. The editor marks those and shows the rest of the description (the lab's hint)
under the value, so the student sees what to decide without opening the file.
"""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Input, Label, Static

from workbench.fsm.machine import Parameter

from .field import Field

#: how a starter FSM marks a parameter the students decide (the start of its description)
FILL_IN = "FILL IN:"


def _g(value: float) -> str:
    return f"{value:g}"


def fill_in_hint(parameter: Parameter) -> str | None:
    """The lab's hint for a parameter the students fill in (None: not one of those)."""
    text = " ".join(parameter.description.split())
    if not text.upper().startswith(FILL_IN):
        return None
    return text[len(FILL_IN) :].strip()


class ParamEditor(Vertical):
    """Posts :class:`ParamEditor.Edited` with ``NAME=VALUE`` whenever the value changes."""

    DEFAULT_CSS = """
    ParamEditor {
        height: auto;
    }
    ParamEditor > Horizontal {
        height: auto;
    }
    ParamEditor .param-name {
        width: 15;
    }
    ParamEditor Input {
        width: 8;
        margin-right: 1;
        background: $panel;
    }
    ParamEditor .param-range {
        width: 1fr;
        height: auto;
        color: $text-muted;
    }
    ParamEditor .param-fill-in {
        height: auto;
        padding-left: 2;
        color: $text-warning;
    }
    ParamEditor.-fill-in .param-name {
        color: $text-warning;
        text-style: bold;
    }
    ParamEditor .param-error {
        height: auto;
        color: $text-error;
        display: none;
    }
    ParamEditor.-invalid .param-error {
        display: block;
    }
    ParamEditor.-invalid Input {
        background: $error 30%;
    }
    """

    class Edited(Message):
        def __init__(self, editor: ParamEditor, item: str) -> None:
            super().__init__()
            self.editor = editor
            self.item = item

    def __init__(self, parameter: Parameter, value: float, default: float) -> None:
        super().__init__()
        self.parameter = parameter
        self.default = default
        self._input = Field(_g(value), compact=True, classes="param-value")
        self._error = Static("", classes="param-error", markup=False)
        #: the lab's hint when the students fill this parameter in
        self.hint = fill_in_hint(parameter)
        self.set_class(self.hint is not None, "-fill-in")
        if parameter.description:
            self.tooltip = " ".join(parameter.description.split())

    def compose(self) -> ComposeResult:
        p = self.parameter
        bounds = []
        if p.minimum is not None and p.maximum is not None:
            bounds.append(f"{_g(p.minimum)} to {_g(p.maximum)}")
        elif p.minimum is not None:
            bounds.append(f"from {_g(p.minimum)}")
        elif p.maximum is not None:
            bounds.append(f"up to {_g(p.maximum)}")
        bounds.append(f"default {_g(self.default)}")
        with Horizontal():
            yield Label(p.name, classes="param-name", markup=False)
            yield self._input
            # the whole range, wrapped under itself when the dialog is narrow
            yield Static(", ".join(bounds), classes="param-range", markup=False)
        if self.hint is not None:
            yield Static(f"{FILL_IN} {self.hint}", classes="param-fill-in", markup=False)
        yield self._error

    @property
    def text(self) -> str:
        return self._input.value.strip()

    def set_value(self, value: float) -> None:
        self._input.value = _g(value)

    def set_error(self, error: str | None) -> None:
        self._error.update(error or "")
        self.set_class(bool(error), "-invalid")

    @property
    def invalid(self) -> bool:
        return self.has_class("-invalid")

    def on_input_changed(self, event: Input.Changed) -> None:
        event.stop()
        self.post_message(self.Edited(self, f"{self.parameter.name}={event.value.strip()}"))
