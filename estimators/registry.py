"""Finding estimator classes by name: the built-ins, the ``landnav.estimators`` entry-point group
of installed third-party packages, and ``module:Class`` strings.

A third-party package registers an estimator in its ``pyproject.toml``::

    [project.entry-points."landnav.estimators"]
    my_filter = "my_package.filters:MyFilter"

Public functions
----------------
get_estimator, list_estimators, is_plugin_path, name_problems, entry_problems, plugin_file.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from estimators.base import Estimator, check_estimator_class, config_problems
from simulator.errors import InputError

if TYPE_CHECKING:
    from importlib import metadata

ENTRY_POINT_GROUP = "landnav.estimators"

# name -> "module:Class"; imported on demand so listing names imports nothing
BUILTINS = {
    "gnss_only": "estimators.builtin.baselines:GnssOnly",
    "dead_reckoning": "estimators.builtin.baselines:DeadReckoning",
    "gnss_wls": "estimators.builtin.gnss_wls:GnssWls",
    "fgo_lc": "estimators.builtin.fgo:FgoLooselyCoupled",
    "fgo_tc": "estimators.builtin.fgo:FgoTightlyCoupled",
    "rtk_ins_ekf": "estimators.builtin.rtk_ins:RtkInsEkf",
    "dr2d_drm1_ekf": "estimators.builtin.cho2006:Drm1Ekf",
    "dr2d_drm2_ekf": "estimators.builtin.cho2006:Drm2Ekf",
    "dr2d_drm2_spkf": "estimators.builtin.cho2006:Drm2Spkf",
    "dr2d_odo_ekf": "estimators.builtin.park2019_dr:Dr2dOdoEkf",
    "dr3d_ekf": "estimators.builtin.park2019_dr:Dr3dEkf",
    "tc_ukf": "estimators.builtin.chan:TcUkf",
    "tc_ekf": "estimators.builtin.chan:TcEkf",
    "riss3d_tc_ekf": "estimators.builtin.karamat2015:RissTcEkf",
    "ins_odo_ekf": "estimators.builtin.park2019_ins:ParkInsOdometer",
    "ins_lkf": "estimators.builtin.tan2008:TanLinearisedKF",
}


def _entry_points() -> dict[str, metadata.EntryPoint]:
    # imported here: importlib.metadata costs 10 ms, and a scenario naming built-ins only (every
    # ``landnav generate``) never needs it
    from importlib import metadata

    return {ep.name: ep for ep in metadata.entry_points(group=ENTRY_POINT_GROUP)}


def list_estimators() -> list[str]:
    """Names of the built-in and entry-point estimators (built-ins first, then sorted)."""
    plugins = sorted(set(_entry_points()) - set(BUILTINS))
    return [*BUILTINS, *plugins]


def _search_path() -> list[str]:
    """``sys.path``, with the current directory first when it is not there: a module:Class of
    the user's own is found from the current directory, as ``python -m`` finds it (a console
    script's sys.path starts with its bin directory instead)."""
    if os.getcwd() not in sys.path and "" not in sys.path:
        return [os.getcwd(), *sys.path]
    return sys.path


def _import_target(target: str, what: str) -> type:
    module_name, _, attr = target.partition(":")
    if not module_name or not attr:
        raise InputError(f"{what}: expected module:Class, got {target!r}")
    sys.path[:] = _search_path()
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:  # a plug-in's own failure, reported as its message
        raise InputError(f"{what}: cannot import module {module_name!r}: "
                         f"{type(exc).__name__}: {exc}") from None
    try:
        return getattr(module, attr)
    except AttributeError:
        raise InputError(f"{what}: module {module_name!r} has no {attr!r}") from None


def get_estimator(name: str) -> type[Estimator]:
    """The estimator class of a registered name or a ``module:Class`` string.

    Raises
    ------
    InputError
        For an unknown name (listing the known ones), a plug-in that fails to import (its own
        error message), or a class that does not satisfy the ``Estimator`` contract.
    """
    where = f"estimator {name!r}"
    if name in BUILTINS:
        cls = _import_target(BUILTINS[name], where)
    elif ":" in name:
        cls = _import_target(name, where)
    else:
        entry = _entry_points().get(name)
        if entry is None:
            raise InputError(f"unknown estimator {name!r}; known: "
                             f"{', '.join(list_estimators())} (or give module:Class)")
        try:
            cls = entry.load()
        except Exception as exc:  # a plug-in's own failure, reported as its message
            raise InputError(f"{where} (entry point {entry.value}) fails to import: "
                             f"{type(exc).__name__}: {exc}") from None
    problems = check_estimator_class(cls, where)
    if problems:
        raise InputError(problems[0] if len(problems) == 1 else "; ".join(problems))
    return cls


def is_plugin_path(entry: Mapping[str, Any] | str) -> bool:
    """Whether an entry names its class as ``module:Class`` (the user's own code), not a
    built-in or an installed entry point."""
    name = entry if isinstance(entry, str) else entry["name"]
    return name not in BUILTINS and ":" in name


def name_problems(entry: Mapping[str, Any] | str) -> list[tuple[str, str]]:
    """Problems of a scenario estimator entry's name, read from the name table alone (nothing
    is imported): a built-in, an installed entry point, or a ``module:Class`` path."""
    name = entry if isinstance(entry, str) else entry["name"]
    if name in BUILTINS:
        return []
    if ":" in name:
        module_name, _, attr = name.partition(":")
        if module_name and attr:
            return []
        return [("name", f"estimator {name!r}: expected module:Class, got {name!r}")]
    if name in _entry_points():
        return []
    return [("name", f"unknown estimator {name!r}; known: {', '.join(list_estimators())} "
                     "(or give module:Class)")]


def entry_problems(entry: Mapping[str, Any] | str) -> list[tuple[str, str]]:
    """Problems of a resolved scenario estimator entry, as (key, message) pairs: the name must
    resolve to an estimator class and the config must fit its defaults."""
    name = entry if isinstance(entry, str) else entry["name"]
    try:
        cls = get_estimator(name)
    except InputError as exc:
        return [("name", p.message) for p in exc.problems]
    config = None if isinstance(entry, str) else entry.get("config")
    return [("config", message) for message in config_problems(cls, config)]


def plugin_file(name: str) -> str | None:
    """The source file of the module an estimator name refers to (a built-in, an entry point,
    or ``module:Class``), looked for along the import path as an import would, without running
    any of its code (nor its packages' ``__init__``); None when there is no such ``.py`` file
    (not found, a compiled module, a zip archive)."""
    if name in BUILTINS:
        module = BUILTINS[name].partition(":")[0]
    elif ":" in name:
        module = name.partition(":")[0]
    else:
        entry = _entry_points().get(name)
        if entry is None:
            return None
        module = entry.module
    *packages, last = module.split(".")
    folders = [Path(p or os.curdir) for p in _search_path()]
    for part in packages:  # a package, or the folders of a namespace package
        folders = [f / part for f in folders if (f / part).is_dir()]
    for folder in folders:
        for candidate in (folder / f"{last}.py", folder / last / "__init__.py"):
            if candidate.is_file():
                return str(candidate.resolve())
    return None
