"""Textual's private parts: used only in ``workbench/tui/serving`` and
``workbench/tui/textual_private.py``, and still there, with the shape relied on, in the
Textual installed.

Textual may change its private modules and attributes in any release. Every use of them is in
one package so an upgrade is checked in one place: this file fails, naming the part, when the
pinned Textual no longer has what the serving code reaches for (then the serving module that
names the part needs a look, see ``docs/architecture.md``)."""

from __future__ import annotations

import ast
import asyncio
import functools
import importlib
import inspect
import io
import os
import pkgutil
import re
import sys
from pathlib import Path

import pytest
import textual
from textual.app import App
from textual.binding import BindingsMap
from textual.cache import LRUCache
from textual.content import Content
from textual.css.stylesheet import Stylesheet
from textual.dom import DOMNode
from textual.drivers.web_driver import WebDriver
from textual.screen import Screen
from textual.widget import Widget
from textual.widgets import Checkbox, Input

import workbench
import workbench.tui

ROOT = Path(workbench.__file__).parent
SERVING = ROOT / "tui" / "serving"
#: the private parts the rest of the TUI needs, behind plain names: the one module outside
#: tui/serving that may reach into Textual
PRIVATE = ROOT / "tui" / "textual_private.py"
TEXTUAL = Path(textual.__file__).parent
PRIVATE_MODULE = "workbench.tui.textual_private"


def private_module(name: str) -> bool:
    parts = name.split(".")
    return parts[0] == "textual" and any(part.startswith("_") for part in parts[1:])


def outside_serving() -> list[Path]:
    return [p for p in sorted(ROOT.rglob("*.py")) if SERVING not in p.parents and p != PRIVATE]


def textual_private_names() -> set[str]:
    """Every ``_name`` (not ``__name__``) Textual's own code defines or sets on ``self``."""
    names: set[str] = set()
    for path in TEXTUAL.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        names.update(re.findall(r"\bself\.(_[a-z]\w*)", text))
        names.update(re.findall(r"\bdef (_[a-z]\w*)", text))
    return names


# -- only tui/serving ----------------------------------------------------------------------------


def test_no_module_outside_tui_serving_imports_a_private_textual_module():
    found = []
    for path in outside_serving():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module and private_module(node.module):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.module}")
            elif isinstance(node, ast.Import):
                found += [f"{path.relative_to(ROOT)}:{node.lineno} {alias.name}"
                          for alias in node.names if private_module(alias.name)]  # fmt: skip
    assert not found, "Textual's private modules belong in workbench/tui/serving: " + str(found)


def tui_classes_outside_serving() -> list[type]:
    found = []
    for info in pkgutil.walk_packages(workbench.tui.__path__, "workbench.tui."):
        if info.name.startswith("workbench.tui.serving") or info.name == PRIVATE_MODULE:
            continue
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if isinstance(value, type) and value.__module__ == module.__name__:
                found.append(value)
    return found


@functools.cache
def private_names_set_by(base: type) -> frozenset[str]:
    """The ``self._x`` a Textual class's own source sets or reads (once per class: finding a
    class's source parses its whole module, and every widget shares Widget and DOMNode)."""
    try:
        return frozenset(re.findall(r"\bself\.(_[a-z]\w*)", inspect.getsource(base)))
    except (OSError, TypeError):
        return frozenset()


def test_no_class_outside_tui_serving_uses_or_replaces_a_private_part_of_its_textual_bases():
    """``self._x`` or ``def _x`` in a class built on Textual's, where a Textual base has ``_x``
    (overriding one by accident is as bad: Textual then calls the workbench's)."""
    found = []
    for cls in tui_classes_outside_serving():
        bases = [b for b in cls.__mro__[1:] if b.__module__.split(".")[0] == "textual"]
        if not bases:
            continue
        theirs = {name for base in bases for name in vars(base)}
        for base in bases:
            theirs |= private_names_set_by(base)
        source = inspect.getsource(cls)
        ours = set(re.findall(r"\bself\.(_[a-z]\w*)|\bdef (_[a-z]\w*)", source))
        used = {name for pair in ours for name in pair if name}
        found += [f"{cls.__module__}.{cls.__qualname__}.{name}" for name in used & theirs]
    assert not found, "reach Textual's private parts through workbench/tui/serving: " + str(found)


def test_no_module_outside_tui_serving_reads_a_private_textual_attribute_of_another_object():
    """``screen._clear_tooltip()``, ``node._bindings``: a private name of Textual's read from
    anything but ``self`` (the workbench's own private names are left alone)."""
    textual_names = textual_private_names()
    found = []
    for path in outside_serving():
        if "tui" not in path.relative_to(ROOT).parts:
            continue  # the core never imports Textual (the import-linter contract)
        tree = ast.parse(path.read_text(encoding="utf-8"))
        own = {
            n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))
        }
        own |= {
            n.attr
            for n in ast.walk(tree)
            if isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store)
        }
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
                and node.attr in textual_names
                and node.attr not in own
            ):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} .{node.attr}")
    assert not found, "reach Textual's private parts through workbench/tui/serving: " + str(found)


# -- what tui/serving relies on ------------------------------------------------------------------

#: private modules and the names taken from them: what each must be
MODULE_NAMES = {
    "textual._ansi_sequences": {"SYNC_START": str, "SYNC_END": str},
    "textual._time": {"get_time": "callable"},
    "textual._xterm_parser": {"XTermParser": type},
    "textual._compositor": {"ChopsUpdate": type, "Compositor": type, "CompositorUpdate": type},
    "textual._context": {"active_app": "contextvar"},
    "textual.widgets._footer": {"FooterKey": type},
    "textual.widgets._toggle_button": {"ToggleButton": type},
    "textual.drivers.web_driver": {"_ExitInput": type},
}

#: private methods called or replaced, with their parameters (names, in order)
METHODS = {
    ("textual._compositor", "Compositor", "_regions_to_spans"): ["cls", "regions"],
    ("textual._compositor", "Compositor", "_render_chops"): ["self", "crop", "is_rendered_line"],
    ("textual._compositor", "Compositor", "_get_renders"): ["self", "crop"],
    ("textual._compositor", "Compositor", "render_partial_update"): ["self"],
    ("textual._compositor", "ChopsUpdate", "__init__"): ["self", "chops", "spans", "chop_ends"],
    ("textual._compositor", "CompositorUpdate", "render_segments"): ["self", "console"],
    ("textual._compositor", "Compositor", "render_update"): [
        "self",
        "full",
        "screen_stack",
        "simplify",
    ],
    ("textual.app", "App", "_display"): ["self", "screen", "renderable"],
    ("textual.drivers.web_driver", "WebDriver", "_enable_mouse_support"): ["self"],
    ("textual.drivers.web_driver", "WebDriver", "_enable_bracketed_paste"): ["self"],
    ("textual._xterm_parser", "XTermParser", "__init__"): ["self", "debug"],
    ("textual._xterm_parser", "XTermParser", "feed"): ["self", "data"],
    ("textual._xterm_parser", "XTermParser", "tick"): ["self"],
    ("textual.drivers.web_driver", "WebDriver", "_on_meta"): ["self", "packet_type", "payload"],
    ("textual.drivers.web_driver", "WebDriver", "write"): ["self", "data"],
    ("textual.app", "App", "_handle_exception"): ["self", "error"],
    ("textual.screen", "Screen", "_clear_tooltip"): ["self"],
    ("textual.screen", "Screen", "_on_idle"): ["self", "event"],
    ("textual.screen", "Screen", "_on_timer_update"): ["self"],
    ("textual.screen", "Screen", "_refresh_layout"): ["self", "size", "scroll"],
    ("textual.screen", "Screen", "_compositor_refresh"): ["self"],
    ("textual.screen", "Screen", "refresh_bindings"): ["self"],
    ("textual.widgets._input", "Input", "_on_key"): ["self", "event"],
    ("textual.widget", "Widget", "_scroll_update"): ["self", "virtual_size"],
    ("textual.app", "App", "_start_widget"): ["self", "parent", "widget"],
}


@pytest.mark.parametrize("module_name", sorted(MODULE_NAMES))
def test_each_private_module_used_has_the_names_taken_from_it(module_name):
    module = importlib.import_module(module_name)
    for name, kind in MODULE_NAMES[module_name].items():
        value = getattr(module, name, None)
        assert value is not None, f"{module_name}.{name} is gone"
        if kind == "callable":
            assert callable(value), f"{module_name}.{name}"
        elif kind == "contextvar":
            assert callable(getattr(value, "get", None)), f"{module_name}.{name}"
        else:
            assert isinstance(value, kind), f"{module_name}.{name}"


@pytest.mark.parametrize(("place", "parameters"), sorted(METHODS.items()))
def test_each_private_method_used_takes_the_parameters_relied_on(place, parameters):
    module_name, class_name, method = place
    cls = getattr(importlib.import_module(module_name), class_name)
    found = inspect.getattr_static(cls, method, None)
    assert found is not None, f"{class_name}.{method} is gone"
    function = found.__func__ if isinstance(found, (staticmethod, classmethod)) else found
    names = list(inspect.signature(function).parameters)  # (a class method's first is cls)
    assert names == parameters, f"{class_name}.{method}{inspect.signature(function)}"


def test_the_private_properties_replaced_are_still_properties():
    from textual.widgets._toggle_button import ToggleButton

    assert isinstance(inspect.getattr_static(Screen, "_binding_chain"), property)
    button = inspect.getattr_static(ToggleButton, "_button")
    assert isinstance(button, property)
    assert inspect.signature(button.fget).return_annotation in (Content, "Content")
    assert issubclass(Checkbox, ToggleButton) and issubclass(Input, Widget)


def test_a_new_screen_has_the_drawing_state_prompt_frames_reads():
    screen = Screen()
    for name in (
        "_dirty_widgets",
        "_repaint_required",
        "_layout_required",
        "_scroll_required",
        "_recompose_required",
    ):
        assert hasattr(screen, name), name
    from textual._compositor import Compositor

    assert isinstance(screen._compositor, Compositor)
    assert isinstance(screen._compositor._dirty_regions, set)
    assert isinstance(screen._bindings, BindingsMap)
    assert isinstance(BindingsMap().key_to_bindings, dict)


def test_a_new_app_has_the_state_the_serving_code_reads():
    app = App()
    assert app._size is None
    assert app._driver is None
    assert isinstance(app._keymap, dict)
    assert app._batch_count == 0
    assert app._screen_stack == []
    assert isinstance(DOMNode()._bindings, BindingsMap)
    assert DOMNode()._parent is None  # (the cached binding chain reads a node's parent there)


def test_a_widget_keeps_its_virtual_size_and_redraw_flag_where_the_single_layout_looks():
    from textual.reactive import Reactive

    descriptor = inspect.getattr_static(Widget, "virtual_size")
    assert isinstance(descriptor, Reactive)
    assert descriptor._layout is True  # what a layout's sizes would ask for, left out
    assert Widget()._repaint_required is False


def test_a_widget_keeps_its_vertical_scroll_bar_where_a_bar_of_its_own_goes():
    # (textual_private.own_vertical_scrollbar: Textual's vertical_scrollbar property makes one
    # there the first time it is asked for)
    widget = Widget()
    assert widget._vertical_scrollbar is None
    assert isinstance(inspect.getattr_static(Widget, "vertical_scrollbar"), property)


def test_a_footer_says_when_it_has_read_its_bindings_where_the_key_bar_looks():
    from textual.widgets import Footer

    assert Footer()._bindings_ready is False


def test_a_stylesheet_keeps_its_parse_cache_and_variables_where_the_warm_up_looks():
    stylesheet = Stylesheet(variables={"primary": "#004578"})
    assert isinstance(stylesheet._parse_cache, LRUCache)
    cache = stylesheet._parse_cache
    assert isinstance(cache.maxsize, int) and list(cache.keys()) == []
    assert stylesheet._variables == {"primary": "#004578"}


def test_the_key_parser_keeps_its_time_limit_where_the_served_driver_reads_it():
    from textual._xterm_parser import XTermParser

    parser = XTermParser()
    assert parser._timeout_time is None  # no escape sequence under way
    list(parser.feed("\x1b"))
    assert isinstance(parser._timeout_time, float)  # a lone escape waits for the rest


def test_the_web_driver_keeps_its_input_thread_reader_and_app_where_the_served_driver_does(
    monkeypatch,
):
    read_end, write_end = os.pipe()  # its reader watches standard input: a pipe here
    monkeypatch.setattr(sys, "__stdin__", io.TextIOWrapper(io.FileIO(read_end)))

    async def look() -> None:
        app = App()
        driver = WebDriver(app)
        try:
            assert driver._app is app
            assert driver._debug is False
            assert hasattr(driver, "_key_thread")
            assert hasattr(driver._input_reader, "_selector")
        finally:
            driver._input_reader._selector.close()

    try:
        asyncio.run(look())
    finally:
        sys.__stdin__.close()
        os.close(write_end)
