"""The package structure: every module imports on its own, and no module imports a layer above
its own (the layer order lives here, in ``LAYERS``).

The layers, lowest first, follow the data path: the core (Earth model, units, column names,
errors, the schema vocabulary, random processes) -> trajectory and environment -> GNSS -> sensors
-> faults -> scenario (assembles every part's schema and checks the whole) -> dataset ->
estimators (the plug-in API, the filter toolbox and the built-ins, which use the core only) ->
replay (the causal harness) -> scoring -> pipeline (the library entry points) -> campaigns ->
commands and the CLI. A module may import modules of its own layer and of the layers below.
The one exception: ``estimators.registry`` (estimator names to classes) may be imported from any
layer, so that a scenario's estimator names are checked where the scenario is.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("simulator", "estimators")

# lowest first; a module belongs to the layer of its longest matching prefix
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("core", ("simulator", "simulator.earth", "simulator.units", "simulator.columns",
              "simulator.errors", "simulator.schema", "simulator.tables", "simulator.timebase",
              "simulator.progress", "simulator.stochastic", "simulator.outputs",
              "simulator.geoid", "simulator.compilation", "simulator.threads",
              "simulator.display_units", "simulator.html_report", "simulator.datasheet")),
    ("trajectory", ("simulator.trajectory", "simulator.vehicle", "simulator.environment")),
    ("drive", ("simulator.drive",)),
    ("gnss", ("simulator.gnss",)),
    ("sensors", ("simulator.sensors",)),
    ("faults", ("simulator.faults",)),
    ("scenario", ("simulator.scenario",)),
    ("dataset", ("simulator.dataset", "simulator.recordings")),
    ("estimators", ("estimators",)),
    ("replay", ("simulator.replay", "simulator.isolated")),
    ("scoring", ("simulator.scoring",)),
    ("pipeline", ("simulator.pipeline", "simulator.comparison")),
    ("campaign", ("simulator.campaign",)),
    ("reproduce", ("simulator.reproduce",)),
    ("commands", ("simulator.commands", "simulator.cli")),
]
ANYWHERE = {"estimators.registry"}  # the estimator name registry
# estimators depend on the core only (and on each other): never on how datasets are made
ESTIMATOR_MAY_IMPORT = ("estimators",) + LAYERS[0][1]


def _modules() -> dict[str, Path]:
    found = {}
    for package in PACKAGES:
        for path in sorted((REPO / package).rglob("*.py")):
            parts = path.relative_to(REPO).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def _matches(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


def layer_of(module: str) -> int:
    """Index in ``LAYERS`` of the layer owning ``module`` (its longest matching prefix)."""
    best, length = None, -1
    for index, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            if _matches(module, prefix) and len(prefix) > length:
                best, length = index, len(prefix)
    if best is None:
        raise LookupError(f"{module} belongs to no layer: add it to LAYERS in {__file__}")
    return best


def imports_of(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every import of our packages in a file, wherever it stands (in
    functions and ``TYPE_CHECKING`` blocks too); ``from package import module`` counts as an
    import of the module."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                name = f"{node.module}.{alias.name}"
                found.append((node.lineno, name if name in MODULES else node.module))
    return [(line, name) for line, name in found if name.split(".")[0] in PACKAGES]


MODULES = _modules()


def test_every_module_has_a_layer():
    for module in MODULES:
        layer_of(module)


def test_no_module_imports_a_layer_above_its_own():
    upward = []
    for module, path in MODULES.items():
        own = layer_of(module)
        for line, target in imports_of(path):
            if target in ANYWHERE:
                continue
            if layer_of(target) > own:
                upward.append(f"{path.relative_to(REPO)}:{line}: {module} ({LAYERS[own][0]}) "
                              f"imports {target} ({LAYERS[layer_of(target)][0]})")
            if _matches(module, "estimators") and not any(
                    _matches(target, prefix) for prefix in ESTIMATOR_MAY_IMPORT):
                upward.append(f"{path.relative_to(REPO)}:{line}: estimator module {module} "
                              f"imports {target} (estimators use the core only)")
    assert not upward, "\n".join(upward)


def test_the_layer_check_sees_an_upward_import(tmp_path):
    """The checker itself: a sensor importing the dataset layer, inside a function, is found."""
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from simulator.dataset.io import open_dataset\n")
    (line, target), = imports_of(bad)
    assert line == 2 and layer_of(target) > layer_of("simulator.sensors.imu")
    assert layer_of("simulator.sensors") < layer_of("simulator.faults") < layer_of("simulator.cli")


def imports_failing_alone(modules: list[str], path: Path = REPO) -> dict[str, str]:
    """module -> error of each of ``modules`` that fails to import on its own, each in a process
    of its own forked from a fresh interpreter (``tests.fresh_imports``) that finds modules on
    ``path``. Byte-code caches are written and read as on an ordinary installation (a sandbox's
    PYTHONDONTWRITEBYTECODE would make every interpreter recompile every module)."""
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
           "PYTHONPATH": os.pathsep.join([str(path), str(REPO)])}
    code = ("import json, sys; from tests.fresh_imports import failures; "
            "print(json.dumps(failures(sys.argv[1:])))")
    done = subprocess.run([sys.executable, "-c", code, *modules], capture_output=True,
                          text=True, cwd=REPO, env=env)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])  # after anything a module printed


def test_every_module_imports_on_its_own():
    """Every module of landnav imported first in its own process, one per core at a time: an
    import cycle, or a module that works only after another has been imported, fails here."""
    failed = imports_failing_alone(list(MODULES))
    assert not failed, "\n".join(f"{module}: {error}" for module, error in failed.items())


def test_the_import_check_sees_a_module_that_needs_another_first(tmp_path):
    """The checker itself: a module that reads a sibling its package has not imported fails
    alone (it works once the sibling is imported), a cycle fails, a plain module passes."""
    package = tmp_path / "needy"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "sibling.py").write_text("VALUE = 1\n")
    (package / "reader.py").write_text("import needy\n\nVALUE = needy.sibling.VALUE\n")
    (package / "first.py").write_text("from needy.second import B\n\nA = 1\n")
    (package / "second.py").write_text("from needy.first import A\n\nB = 2\n")
    failed = imports_failing_alone(["needy.sibling", "needy.reader", "needy.first"], tmp_path)
    assert sorted(failed) == ["needy.first", "needy.reader"]
    assert "has no attribute 'sibling'" in failed["needy.reader"]
    assert "partially initialized" in failed["needy.first"]
