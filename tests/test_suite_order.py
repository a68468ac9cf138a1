"""The default run's order (tests/conftest.py): the listed heavy modules exist and come first,
heaviest first, each module's tests in their own order."""

from __future__ import annotations

from types import SimpleNamespace

from tests.conftest import HEAVY_MODULES, REPO, heaviest_first


def test_every_listed_heavy_module_exists_once():
    assert len(set(HEAVY_MODULES)) == len(HEAVY_MODULES)
    assert [m for m in HEAVY_MODULES if not (REPO / m).is_file()] == []


def test_heavy_modules_come_first_and_each_module_keeps_its_order():
    light, heavy, heavier = "tests/test_a.py", HEAVY_MODULES[1], HEAVY_MODULES[0]
    ids = [f"{light}::t1", f"{heavy}::t1", f"{light}::t2", f"{heavier}::t1", f"{heavy}::t2",
           f"{heavier}::t2"]
    items = [SimpleNamespace(nodeid=nodeid) for nodeid in ids]
    heaviest_first(items)
    assert [item.nodeid for item in items] == [
        f"{heavier}::t1", f"{heavier}::t2", f"{heavy}::t1", f"{heavy}::t2", f"{light}::t1",
        f"{light}::t2"]
