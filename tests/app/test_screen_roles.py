"""Every screen that takes a role from ``tui/host.py`` defines the method the app calls on it."""

from __future__ import annotations

import importlib
import pkgutil

import workbench.tui
from workbench.tui.host import FollowsUnicode, ShowsSnapshot


def all_subclasses(cls: type) -> set[type]:
    found = set()
    for sub in cls.__subclasses__():
        found |= {sub, *all_subclasses(sub)}
    return found


def test_each_role_s_screens_define_its_method():
    for module in pkgutil.walk_packages(workbench.tui.__path__, "workbench.tui."):
        importlib.import_module(module.name)
    roles = {ShowsSnapshot: "show_snapshot", FollowsUnicode: "set_unicode"}
    for role, method in roles.items():
        screens = all_subclasses(role)
        assert screens, role
        for screen in screens:
            assert callable(getattr(screen, method, None)), (screen, method)
